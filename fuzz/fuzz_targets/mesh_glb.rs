//! GLB meshes through `load_mesh` (the bytes go through a file in /dev/shm, as a user's would).
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    // The gltf crate (1.4.1) panics in its own validation on some references outside their
    // arrays; the loader catches that with `catch_unwind` and returns an error. libfuzzer-sys's
    // panic hook would abort on the caught panic too, so it is replaced by a silent one: a panic
    // the loader does not catch still aborts (libfuzzer-sys's own `catch_unwind`), a crash.
    static SILENT: std::sync::Once = std::sync::Once::new();
    SILENT.call_once(|| std::panic::set_hook(Box::new(|_| {})));
    let path = std::path::PathBuf::from(format!("/dev/shm/nbrdf-fuzz-{}.glb", std::process::id()));
    if std::fs::write(&path, data).is_ok() {
        let _ = mesh_encoding::load_mesh(&path, &mesh_encoding::LoadOptions::default());
    }
});
