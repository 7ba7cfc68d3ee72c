//! The 8-bit per-pair flag PNGs of a scene (`flags/vVV_lLL.png`).
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let path = std::path::PathBuf::from(format!("/dev/shm/nbrdf-fuzz-{}.png", std::process::id()));
    if std::fs::write(&path, data).is_ok() {
        let _ = scene::images::read_png_gray(&path, &stdx::Limits::DEFAULT);
    }
});
