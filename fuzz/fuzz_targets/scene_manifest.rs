//! Scene manifests (JSON with its own checksum).
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let path = std::path::PathBuf::from(format!("/dev/shm/nbrdf-fuzz-{}.json", std::process::id()));
    if std::fs::write(&path, data).is_ok() {
        let _ = scene::Manifest::read(&path);
    }
});
