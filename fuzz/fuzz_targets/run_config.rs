//! Run configurations (`config.toml` of a run directory).
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let origin = std::path::Path::new("fuzz.toml");
        if let Err(e) = run_format::RunConfig::from_toml(text, origin) {
            assert!(e.to_string().contains("fuzz.toml"), "the error names the file: {e}");
        }
    }
});
