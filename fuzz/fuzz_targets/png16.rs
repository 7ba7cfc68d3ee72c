//! 16-bit (and 8-bit) PNG images of a DiLiGenT capture through `read_png16`.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let path = std::path::PathBuf::from(format!("/dev/shm/nbrdf-fuzz-{}.png", std::process::id()));
    if std::fs::write(&path, data).is_ok() {
        let _ = dataset_diligent::pms_dir::read_png16(&path, &stdx::Limits::DEFAULT);
    }
});
