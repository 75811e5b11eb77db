#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| fovea_fuzz::headset(data));
