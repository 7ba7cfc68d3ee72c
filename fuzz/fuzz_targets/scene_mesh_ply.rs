//! The mesh PLY a scene directory carries (`scene::mesh_file`).
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let path = std::path::PathBuf::from(format!("/dev/shm/nbrdf-fuzz-{}.ply", std::process::id()));
    if std::fs::write(&path, data).is_ok() {
        let _ = scene::mesh_file::load(&path);
    }
});
