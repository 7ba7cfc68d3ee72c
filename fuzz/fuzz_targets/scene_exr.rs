//! EXR images through the scene reader (a file in /dev/shm).
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let path = std::path::PathBuf::from(format!("/dev/shm/nbrdf-fuzz-{}.exr", std::process::id()));
    if std::fs::write(&path, data).is_ok() {
        let _ = scene::images::read_exr_rgb(&path, &stdx::Limits::DEFAULT);
    }
});
