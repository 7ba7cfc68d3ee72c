//! LPIPS weight files (`.lpipsw`).
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let path = std::path::PathBuf::from(format!("/dev/shm/nbrdf-fuzz-{}.lpipsw", std::process::id()));
    if std::fs::write(&path, data).is_ok() {
        let _ = metrics::lpips::weights::read(&path);
    }
});
