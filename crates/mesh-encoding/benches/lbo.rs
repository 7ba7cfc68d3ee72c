//! Criterion benchmark of the Laplace-Beltrami eigen-solve: 65 pairs of `spot` (the shared
//! mesh, 2.9k vertices) with the default settings (sequential shift-invert block Lanczos plus
//! the inertia check), and the assembly of `L` and `M`. The large-mesh figures (513 pairs of the
//! bunny, ogre, nefertiti) take seconds per solve and are measured with the `lbo_bench` example
//! instead (see `PERFORMANCE.md`).
//!
//! ```text
//! cargo bench -p mesh-encoding --bench lbo
//! ```

use std::path::PathBuf;

use criterion::{Criterion, criterion_group, criterion_main};
use mesh_encoding::lbo::{EigenSettings, LboMatrices, smallest_eigenpairs};
use mesh_encoding::load_mesh;

fn spot_path() -> PathBuf {
    std::env::var_os("NEURAL_BRDF_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"))
        .join("meshes/spot.obj")
}

fn bench_lbo(c: &mut Criterion) {
    let path = spot_path();
    let Ok(loaded) = load_mesh(&path, &Default::default()) else {
        eprintln!("lbo bench: {} not found, skipped", path.display());
        return;
    };
    let matrices = LboMatrices::from_mesh(&loaded.mesh).expect("assembly");
    let settings = EigenSettings::default();
    let mut group = c.benchmark_group("lbo");
    group.sample_size(10);
    group.bench_function("assemble spot", |b| {
        b.iter(|| LboMatrices::from_mesh(&loaded.mesh).expect("assembly"))
    });
    group.bench_function("eigenpairs spot k=65", |b| {
        b.iter(|| smallest_eigenpairs(&matrices, 65, &settings).expect("solve"))
    });
    group.finish();
}

criterion_group!(benches, bench_lbo);
criterion_main!(benches);
