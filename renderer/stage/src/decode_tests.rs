use super::*;
use fovea_test_kit::pictures::exr_declaring;
use std::path::PathBuf;

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fovea-decode-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A valid 8000 × 8000 PNG of 7.8 KB (1-bit grey, all black): decoded to RGBA it is 256 MB, and
/// `fovea eval` kept ≈ 7.8 GB for it. Refused from its header.
#[test]
fn an_8000_squared_png_is_refused_from_its_header() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/black_8000x8000.png");
    let err = format!(
        "{:#}",
        read_rgba8(&path, MAX_IMAGE_PIXELS, None).unwrap_err()
    );
    assert!(
        err.contains("black_8000x8000.png")
            && err.contains("8000×8000")
            && err.contains("16777216-pixel limit"),
        "{err}"
    );
}

/// An EXR declaring 100000² pixels aborted `fovea eval` and `replay` on allocation (exit 134).
#[test]
fn an_exr_declaring_100000_squared_pixels_is_an_error_not_an_abort() {
    let bytes = exr_declaring(100_000, 100_000);
    let err = format!(
        "{:#}",
        decode_exr(&bytes, "huge.exr", MAX_IMAGE_PIXELS, None).unwrap_err()
    );
    assert!(
        err.contains("huge.exr") && err.contains("100000×100000"),
        "{err}"
    );
    let path = temp_dir("exr-huge").join("huge.exr");
    std::fs::write(&path, &bytes).unwrap();
    let err = format!("{:#}", read_exr(&path, MAX_IMAGE_PIXELS, None).unwrap_err());
    assert!(
        err.contains("huge.exr") && err.contains("pixel limit"),
        "{err}"
    );
}

#[test]
fn declared_sizes_are_checked_against_the_expected_one() {
    let err = format!(
        "{:#}",
        decode_exr(&exr_declaring(4, 4), "ref.exr", 1 << 20, Some((8, 8))).unwrap_err()
    );
    assert!(
        err.contains("ref.exr: the image is 4×4, expected 8×8"),
        "{err}"
    );
    let (w, h, px) = decode_exr(&exr_declaring(4, 4), "ref.exr", 1 << 20, Some((4, 4))).unwrap();
    assert_eq!((w, h, px.len()), (4, 4, 16));
}

#[test]
fn fifos_devices_and_large_files_are_refused_without_reading() {
    let err = format!(
        "{:#}",
        read_bounded(Path::new("/dev/zero"), 1 << 20, "image").unwrap_err()
    );
    assert!(err.contains("a device"), "{err}");
    let dir = temp_dir("fifo");
    let fifo = dir.join("frame.png");
    let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    // SAFETY: a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    let err = format!("{:#}", read_bounded(&fifo, 1 << 20, "image").unwrap_err());
    assert!(err.contains("FIFO") && err.contains("frame.png"), "{err}");
    let big = dir.join("big.png");
    std::fs::write(&big, vec![0u8; 2048]).unwrap();
    let err = format!("{:#}", read_bounded(&big, 1024, "image").unwrap_err());
    assert!(
        err.contains("2048 bytes") && err.contains("1024-byte limit"),
        "{err}"
    );
}
