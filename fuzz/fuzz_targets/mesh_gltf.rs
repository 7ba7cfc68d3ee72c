//! Text glTF meshes (JSON, buffers as data URIs or files beside it) through `load_mesh`.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    // The gltf crate (1.4.1) panics in its own validation on some references outside their
    // arrays; the loader catches that with `catch_unwind` and returns an error. libfuzzer-sys's
    // panic hook would abort on the caught panic too, so it is replaced by a silent one: a panic
    // the loader does not catch still aborts (libfuzzer-sys's own `catch_unwind`), a crash.
    static SILENT: std::sync::Once = std::sync::Once::new();
    SILENT.call_once(|| std::panic::set_hook(Box::new(|_| {})));
    let dir = std::path::PathBuf::from(format!("/dev/shm/nbrdf-fuzz-gltf-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&dir);
    let path = dir.join("mesh.gltf");
    if std::fs::write(&path, data).is_ok() {
        let _ = mesh_encoding::load_mesh(&path, &mesh_encoding::LoadOptions::default());
    }
});
