//! The data manifests of `cargo xtask fetch-data` (`data-manifests/*.toml`). xtask is a binary,
//! so its manifest reader is compiled into this target from its source file.
#![no_main]

#[path = "../../xtask/src/fetch/manifest.rs"]
#[allow(dead_code)]
mod manifest;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let path = std::path::PathBuf::from(format!("/dev/shm/nbrdf-fuzz-{}.toml", std::process::id()));
    if std::fs::write(&path, data).is_ok() {
        let _ = manifest::load(&path);
    }
});
