//! Text glTF meshes (JSON, buffers as data URIs or files beside it) through `load_mesh`.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let dir = std::path::PathBuf::from(format!("/dev/shm/nbrdf-fuzz-gltf-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&dir);
    let path = dir.join("mesh.gltf");
    if std::fs::write(&path, data).is_ok() {
        let _ = mesh_encoding::load_mesh(&path, &mesh_encoding::LoadOptions::default());
    }
});
