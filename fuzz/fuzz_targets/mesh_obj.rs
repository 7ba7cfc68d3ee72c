//! OBJ meshes through `load_mesh` (the bytes go through a file in /dev/shm, as a user's would).
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let path = std::path::PathBuf::from(format!("/dev/shm/nbrdf-fuzz-{}.obj", std::process::id()));
    if std::fs::write(&path, data).is_ok() {
        let _ = mesh_encoding::load_mesh(&path, &mesh_encoding::LoadOptions::default());
    }
});
