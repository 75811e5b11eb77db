//! Test helpers shared by the unit tests of every crate and by the integration tests
//! (`tests/support` re-exports them), so each rule is written once: the reference data under
//! `../shared` ([`data`]), Pearson's χ² goodness-of-fit test for sampling code ([`chi2`]) and
//! picture comparisons that keep their evidence ([`pictures`], feature `pictures`), and what a
//! folder holds ([`file_names`]).

pub mod chi2;
pub mod data;
#[cfg(feature = "pictures")]
pub mod pictures;

/// The names of the entries in `dir`, sorted (what a write left behind).
pub fn file_names(dir: &std::path::Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("reading {}: {e}", dir.display()))
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}
