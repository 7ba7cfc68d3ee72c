//! Ray-casting throughput on stanford-bunny and ogre (normalised): one 512 x 512 view with 42
//! lights, primary plus shadow rays per second (criterion reports elements/s = rays/s), and the
//! BVH build. Needs the shared data folder (`NEURAL_BRDF_DATA` or `<workspace>/../shared/data`).

use std::path::PathBuf;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use mesh_encoding::{LoadOptions, TriMesh, load_mesh};
use raycast_precompute::rig::orbit_views;
use raycast_precompute::{PrecomputeSettings, Tracer, precompute_with_tracer};

fn mesh(name: &str) -> Option<TriMesh> {
    let data = std::env::var_os("NEURAL_BRDF_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"));
    let options = LoadOptions { normalize_unit_sphere: true, ..Default::default() };
    match load_mesh(data.join("meshes").join(name), &options) {
        Ok(m) => Some(m.mesh),
        Err(e) => {
            eprintln!("SKIP {name}: {e}");
            None
        }
    }
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("raycast");
    group.sample_size(10);
    for name in ["stanford-bunny.obj", "ogre.obj"] {
        let Some(mesh) = mesh(name) else { continue };
        let tracer = Tracer::new(&mesh);
        let views = orbit_views(1, 42, (512, 512), 2.6, 45.0, 11).unwrap();
        let settings = PrecomputeSettings::default();
        let stats = precompute_with_tracer(&tracer, &views, &settings).unwrap().stats;
        group.throughput(Throughput::Elements(stats.primary_rays + stats.shadow_rays));
        group.bench_function(format!("{name}/primary+shadow 512x512x42"), |b| {
            b.iter(|| precompute_with_tracer(&tracer, &views, &settings).unwrap())
        });
        group.throughput(Throughput::Elements(mesh.triangle_count() as u64));
        group.bench_function(format!("{name}/bvh build"), |b| b.iter(|| Tracer::new(&mesh)));
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
