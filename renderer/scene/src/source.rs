//! Reading the files a scene refers to, safely: a URI resolves only to a file inside the scene
//! file's folder (no `..`, absolute paths, schemes such as `file://`, or symbolic links leading
//! out), only regular files are opened (a FIFO would block, a device such as `/dev/zero` never
//! ends), and every read is bounded by the size the document declares and by the byte budget.
//! Errors are plain reasons; the caller adds the file, the item and the URI. No message carries
//! bytes of a file that was read or refused.

use crate::limits::ByteBudget;
use base64::Engine as _;
use std::fs::File;
use std::io::Read;
use std::path::{Component, Path, PathBuf};

/// What a URI names.
#[derive(Debug, PartialEq)]
pub(crate) enum Uri<'a> {
    /// `data:[<media type>];base64,<payload>`.
    Data {
        media_type: &'a str,
        payload: &'a str,
    },
    /// A relative path, percent-decoded, checked to stay below the scene's folder.
    Relative(PathBuf),
}

/// Parses a glTF URI; refuses everything that could name a file outside the scene's folder.
pub(crate) fn parse_uri(uri: &str) -> Result<Uri<'_>, String> {
    if uri.len() >= 5 && uri[..5].eq_ignore_ascii_case("data:") {
        let rest = &uri[5..];
        let Some((header, payload)) = rest.split_once(',') else {
            return Err("data: URI without a ',' before its payload".into());
        };
        let Some(media_type) = header.strip_suffix(";base64") else {
            return Err("data: URI is not base64-encoded (glTF data URIs are ';base64,')".into());
        };
        return Ok(Uri::Data {
            media_type,
            payload,
        });
    }
    if let Some(scheme) = uri_scheme(uri) {
        return Err(format!(
            "the '{scheme}:' scheme is not allowed: only relative paths inside the scene's folder and data: URIs are read"
        ));
    }
    // A query or fragment is not part of the file name (a literal '#' or '?' is written %23 / %3F).
    let path_part = uri.split(['?', '#']).next().unwrap_or("");
    let decoded = percent_decode(path_part)?;
    check_relative(&decoded)?;
    Ok(Uri::Relative(PathBuf::from(decoded)))
}

/// RFC 3986 scheme (`ALPHA *( ALPHA / DIGIT / "+" / "-" / "." ) ":"`) before any '/', '?' or '#'.
/// A Windows drive letter (`C:`) counts as one too, which is what we want: it is absolute.
fn uri_scheme(uri: &str) -> Option<&str> {
    let end = uri.find([':', '/', '?', '#'])?;
    let candidate = &uri[..end];
    let is_scheme = uri[end..].starts_with(':')
        && candidate.starts_with(|c: char| c.is_ascii_alphabetic())
        && candidate
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.'));
    is_scheme.then_some(candidate)
}

fn percent_decode(s: &str) -> Result<String, String> {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok());
            let value = hex
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or("malformed %-escape in the URI")?;
            out.push(value);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| "the URI's %-escapes do not decode to UTF-8".to_string())
}

fn check_relative(path: &str) -> Result<(), String> {
    if path.is_empty() {
        return Err("empty URI".into());
    }
    if path.contains('\0') {
        return Err("the URI contains a NUL character".into());
    }
    if path.starts_with(['/', '\\']) {
        return Err(
            "absolute paths are not allowed: URIs resolve inside the scene's folder".into(),
        );
    }
    // Backslashes count as separators too, so `..\x` cannot slip through on any platform.
    if path.split(['/', '\\']).any(|part| part == "..") {
        return Err("'..' is not allowed: URIs resolve inside the scene's folder".into());
    }
    Ok(())
}

/// Resolves a relative URI path below `folder`, following symbolic links and refusing any that
/// lead out of it. Returns the canonical path.
pub(crate) fn resolve_inside(folder: &Path, relative: &Path) -> Result<PathBuf, String> {
    let root = folder.canonicalize().map_err(|e| {
        format!(
            "cannot resolve the scene's folder {}: {e}",
            folder.display()
        )
    })?;
    if !relative
        .components()
        .all(|c| matches!(c, Component::Normal(_) | Component::CurDir))
    {
        return Err("the URI is not a plain relative path".into());
    }
    let target = root
        .join(relative)
        .canonicalize()
        .map_err(|e| format!("cannot open it: {e}"))?;
    if !target.starts_with(&root) {
        return Err(format!(
            "it resolves outside the scene's folder {} (through a symbolic link)",
            root.display()
        ));
    }
    Ok(target)
}

/// Why a file could not be read. Kept apart from plain strings so the scene file's own failures
/// stay `std::io::Error`s and budget overruns stay budget errors.
#[derive(Debug)]
pub(crate) enum ReadError {
    Open(std::io::Error),
    NotRegular(&'static str),
    Short { size: u64, declared: u64 },
    Read(std::io::Error),
    Shrank { read: u64, want: u64 },
    Budget(String),
}

impl std::fmt::Display for ReadError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ReadError::Open(e) => write!(f, "cannot open it: {e}"),
            ReadError::NotRegular(kind) => write!(f, "it is {kind}, not a regular file"),
            ReadError::Short { size, declared } => write!(
                f,
                "the file has {size} bytes but byteLength declares {declared}"
            ),
            ReadError::Read(e) => write!(f, "reading it failed: {e}"),
            ReadError::Shrank { read, want } => write!(
                f,
                "the file shrank while being read ({read} of {want} bytes)"
            ),
            ReadError::Budget(detail) => f.write_str(detail),
        }
    }
}

/// Opens `path` for reading only if it is a regular file; returns it with its size. Opening is
/// non-blocking so a FIFO is refused instead of waiting for a writer.
pub(crate) fn open_regular(path: &Path) -> Result<(File, u64), ReadError> {
    let file = open_nonblocking(path).map_err(ReadError::Open)?;
    let meta = file.metadata().map_err(ReadError::Open)?;
    if !meta.is_file() {
        return Err(ReadError::NotRegular(describe_kind(&meta.file_type())));
    }
    Ok((file, meta.len()))
}

#[cfg(unix)]
fn open_nonblocking(path: &Path) -> std::io::Result<File> {
    use std::os::unix::fs::OpenOptionsExt;
    std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK | libc::O_CLOEXEC)
        .open(path)
}

#[cfg(not(unix))]
fn open_nonblocking(path: &Path) -> std::io::Result<File> {
    // No FIFOs to block on here; the regular-file check after opening still applies.
    File::open(path)
}

fn describe_kind(kind: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if kind.is_char_device() || kind.is_block_device() {
            return "a device";
        }
        if kind.is_socket() {
            return "a socket";
        }
    }
    if kind.is_dir() {
        "a folder"
    } else {
        "not a file"
    }
}

/// Reads a regular file: exactly `declared` bytes when the document declares a length (a file
/// shorter than that is an error, the rest of a longer one is not read), else the whole file.
/// The bytes are taken from `budget` before anything is allocated.
pub(crate) fn read_bounded(
    path: &Path,
    declared: Option<u64>,
    budget: &mut ByteBudget,
    what: &str,
) -> Result<Vec<u8>, ReadError> {
    let (file, size) = open_regular(path)?;
    let want = match declared {
        Some(d) if size < d => return Err(ReadError::Short { size, declared: d }),
        Some(d) => d,
        None => size,
    };
    budget.take(want, what).map_err(ReadError::Budget)?;
    // `want` fits: the budget is far below usize::MAX on 64-bit targets.
    let mut data = Vec::with_capacity(usize::try_from(want).unwrap_or(0));
    file.take(want)
        .read_to_end(&mut data)
        .map_err(ReadError::Read)?;
    if (data.len() as u64) < want {
        return Err(ReadError::Shrank {
            read: data.len() as u64,
            want,
        });
    }
    Ok(data)
}

/// Decodes a base64 data-URI payload (padding optional), charging its decoded size to `budget`.
pub(crate) fn decode_data_uri(
    payload: &str,
    budget: &mut ByteBudget,
    what: &str,
) -> Result<Vec<u8>, String> {
    let decoded_len = payload.len() as u64 / 4 * 3 + 3;
    budget.take(decoded_len, what)?;
    let engine = base64::engine::GeneralPurpose::new(
        &base64::alphabet::STANDARD,
        base64::engine::GeneralPurposeConfig::new()
            .with_decode_padding_mode(base64::engine::DecodePaddingMode::Indifferent),
    );
    engine
        .decode(payload.trim())
        .map_err(|e| format!("invalid base64 payload: {e}"))
}

/// A URI as error messages show it: data URIs abbreviated (their payload is file content),
/// control characters escaped, long ones cut.
pub(crate) fn display_uri(uri: &str) -> String {
    if let Ok(Uri::Data {
        media_type,
        payload,
    }) = parse_uri(uri)
    {
        return format!("data:{media_type};base64,… ({} characters)", payload.len());
    }
    let escaped: String = uri.escape_debug().collect();
    match escaped.char_indices().nth(200) {
        Some((cut, _)) => format!("{}…", &escaped[..cut]),
        None => escaped,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uris_that_could_leave_the_folder_are_refused() {
        for (uri, needle) in [
            ("../secret.bin", "'..'"),
            ("a/../../b.bin", "'..'"),
            ("a\\..\\b.bin", "'..'"),
            ("%2e%2e/b.bin", "'..'"),
            ("/etc/passwd", "absolute"),
            ("%2Fetc/passwd", "absolute"),
            ("file:///etc/passwd", "'file:' scheme"),
            ("FILE:x.bin", "'FILE:' scheme"),
            ("http://example.com/a.bin", "'http:' scheme"),
            ("C:/x.bin", "'C:' scheme"),
            ("a%00b", "NUL"),
            ("a%zzb", "%-escape"),
            ("", "empty"),
        ] {
            let err = parse_uri(uri).expect_err(uri);
            assert!(err.contains(needle), "{uri}: {err}");
        }
    }

    #[test]
    fn relative_and_data_uris_parse() {
        assert_eq!(
            parse_uri("tex/a%20b.png"),
            Ok(Uri::Relative(PathBuf::from("tex/a b.png")))
        );
        assert_eq!(
            parse_uri("a.bin#frag"),
            Ok(Uri::Relative(PathBuf::from("a.bin")))
        );
        assert_eq!(parse_uri("dir:x/a.bin"), Err("the 'dir:' scheme is not allowed: only relative paths inside the scene's folder and data: URIs are read".into()));
        assert_eq!(
            parse_uri("./x:y.bin"),
            Ok(Uri::Relative(PathBuf::from("./x:y.bin"))),
            "a colon after a '/' is part of a name"
        );
        assert_eq!(
            parse_uri("data:image/png;base64,AAAA"),
            Ok(Uri::Data {
                media_type: "image/png",
                payload: "AAAA"
            })
        );
        assert!(parse_uri("data:text/plain,hello")
            .unwrap_err()
            .contains("base64"));
        let mut budget = ByteBudget::new(100);
        assert_eq!(
            decode_data_uri("AAEC", &mut budget, "b").unwrap(),
            vec![0, 1, 2]
        );
        assert_eq!(
            decode_data_uri("AAE", &mut budget, "b").unwrap(),
            vec![0, 1],
            "padding is optional"
        );
        assert!(decode_data_uri("A!!A", &mut budget, "b").is_err());
    }

    #[test]
    fn displayed_uris_never_carry_data_payloads() {
        assert_eq!(
            display_uri("data:application/octet-stream;base64,c2VjcmV0"),
            "data:application/octet-stream;base64,… (8 characters)"
        );
        assert_eq!(display_uri("a\nb.png"), "a\\nb.png");
        assert_eq!(display_uri(&"x".repeat(500)).chars().count(), 201);
    }
}
