//! Sweep profiles (`crates/sweep/profiles/*.toml` and users' own).
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        if let Err(e) = sweep::SweepProfile::parse(text, "fuzz-profile.toml") {
            assert!(e.to_string().contains("fuzz-profile.toml"), "the error names the file: {e}");
        }
    }
});
