//! The reference data under `../shared/data` beside the repository (real scenes, the bunny, the
//! Visual-Polar test vectors). A test that needs a file asks [`shared_data`]: when the file is
//! missing, the test fails naming the path if `FOVEA_REQUIRE_DATA` is set (as `scripts/test` and
//! so CI do), and otherwise prints `skipped: <reason>` to stderr and returns early — never a
//! silent pass.

use std::path::{Path, PathBuf};

/// The environment variable that turns missing reference data into a failure.
pub const REQUIRE_DATA: &str = "FOVEA_REQUIRE_DATA";

/// The repository's root folder.
pub fn repo_root() -> PathBuf {
    let kit = Path::new(env!("CARGO_MANIFEST_DIR"));
    let kit = kit.canonicalize().unwrap_or_else(|_| kit.to_path_buf());
    kit.join("../..")
        .canonicalize()
        .unwrap_or_else(|_| kit.join("../.."))
}

/// `../shared/data` beside the repository.
pub fn shared_data_dir() -> PathBuf {
    let root = repo_root();
    match root.parent() {
        Some(parent) => parent.join("shared/data"),
        None => root.join("../shared/data"),
    }
}

/// Whether missing reference data fails the test (`FOVEA_REQUIRE_DATA` set, not empty or `0`).
pub fn data_required() -> bool {
    std::env::var_os(REQUIRE_DATA).is_some_and(|v| !v.is_empty() && v != "0")
}

/// `../shared/data/<relative>` when it exists. When it does not: panics naming the path if
/// [`data_required`], else prints `skipped: <path> is not in this checkout` to stderr and returns
/// `None` (the test then returns without asserting anything).
pub fn shared_data(relative: &str) -> Option<PathBuf> {
    let path = shared_data_dir().join(relative);
    if path.exists() {
        return Some(path);
    }
    missing(&path, data_required())
}

/// What happens to a test whose data at `path` is missing (see [`shared_data`]).
fn missing(path: &Path, required: bool) -> Option<PathBuf> {
    let reason = format!("{} is not in this checkout", path.display());
    if required {
        panic!("{REQUIRE_DATA} is set and this test needs its data: {reason}");
    }
    eprintln!("skipped: {reason} (set {REQUIRE_DATA}=1 to make that a failure)");
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn present_data_is_found_beside_the_repository() {
        // The README of the reference data is the one file every checkout of ../shared has.
        if let Some(p) = shared_data("README.md") {
            assert!(p.is_file() && p.ends_with("shared/data/README.md"), "{p:?}");
        }
    }

    #[test]
    fn missing_data_is_skipped_with_a_reason_when_not_required() {
        let path = shared_data_dir().join("no-such-file");
        assert_eq!(missing(&path, false), None);
    }

    #[test]
    #[should_panic(expected = "no-such-file is not in this checkout")]
    fn missing_data_fails_naming_the_path_when_required() {
        missing(&shared_data_dir().join("no-such-file"), true);
    }
}
