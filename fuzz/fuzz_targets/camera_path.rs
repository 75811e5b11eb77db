#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| fovea_fuzz::camera_path(data));
