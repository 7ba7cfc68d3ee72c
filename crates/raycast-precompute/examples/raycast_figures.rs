//! Prints the ray-casting figures of the geometry note: BVH build time, primary plus shadow rays
//! per second for stanford-bunny and ogre (512 x 512, 42 lights, 4 orbit views), and the speed
//! ratio against the brute-force reference (both on all rayon threads, brute force on a sample
//! of the same camera rays). The packet path (the default) and the one-ray-at-a-time reference
//! path are timed alternately in the same run (A/B under the same load) and must agree bit for
//! bit.
//!
//! `cargo run --release -p raycast-precompute --example raycast_figures`

use std::path::PathBuf;
use std::time::Instant;

use mesh_encoding::{LoadOptions, load_mesh};
use raycast_precompute::rig::orbit_views;
use raycast_precompute::{
    BruteForce, PrecomputeSettings, Tracer, Traversal, precompute_with_tracer,
    precompute_with_traversal,
};
use rayon::prelude::*;

fn main() {
    let data = std::env::var_os("NEURAL_BRDF_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"));
    println!("threads: {}", rayon::current_num_threads());
    for name in ["stanford-bunny.obj", "ogre.obj"] {
        let options = LoadOptions { normalize_unit_sphere: true, ..Default::default() };
        let mesh = match load_mesh(data.join("meshes").join(name), &options) {
            Ok(m) => m.mesh,
            Err(e) => {
                eprintln!("skip: {e}");
                continue;
            }
        };
        let builds: Vec<f64> =
            (0..5).map(|_| Tracer::new(&mesh).build_time().as_secs_f64()).collect();
        let tracer = Tracer::new(&mesh);
        let views = orbit_views(4, 42, (512, 512), 2.6, 45.0, 11).unwrap();
        let settings = PrecomputeSettings::default();
        let _warm = precompute_with_tracer(&tracer, &views[..1], &settings).unwrap();
        // A/B: the one-by-one reference (A) and the packets (B), alternated, best of 5 each.
        let mut best = f64::INFINITY;
        let mut best_simple = f64::INFINITY;
        let mut stats = Default::default();
        for _ in 0..3 {
            let start = Instant::now();
            let simple =
                precompute_with_traversal(&tracer, &views, &settings, Traversal::OneByOne).unwrap();
            best_simple = best_simple.min(start.elapsed().as_secs_f64());
            let start = Instant::now();
            let scene = precompute_with_tracer(&tracer, &views, &settings).unwrap();
            best = best.min(start.elapsed().as_secs_f64());
            assert_eq!(scene, simple, "packet and one-by-one paths disagree");
            stats = scene.stats;
        }
        let rays = (stats.primary_rays + stats.shadow_rays) as f64;

        // Brute force on every 97th camera ray of the first view, same threads.
        let cam = &views[0].camera;
        let sample: Vec<usize> = (0..cam.pixel_count()).step_by(97).collect();
        let reference = BruteForce::new(&mesh);
        let start = Instant::now();
        let hits: usize = sample
            .par_iter()
            .map(|&p| {
                let (o, d) = cam.pixel_ray(p);
                usize::from(reference.closest_hit(o, d, f32::INFINITY).is_some())
            })
            .sum();
        let brute_rate = sample.len() as f64 / start.elapsed().as_secs_f64();
        let start = Instant::now();
        let bvh_hits: usize = sample
            .par_iter()
            .map(|&p| {
                let (o, d) = cam.pixel_ray(p);
                usize::from(tracer.closest_hit(o, d, f32::INFINITY).is_some())
            })
            .sum();
        let bvh_sample_rate = sample.len() as f64 / start.elapsed().as_secs_f64();

        println!(
            "{name}: one-by-one {:.2} M rays/s, packets {:.2} M rays/s: {:.2}x (same process, \
             alternated, best of 5, results bit-identical)",
            rays / best_simple / 1e6,
            rays / best / 1e6,
            best_simple / best
        );
        println!(
            "{name}: {} triangles; BVH build {:.3}-{:.3} s; {} primary + {} shadow rays \
             ({} back-facing skipped) in {:.3} s = {:.2} M rays/s; brute force {:.0} rays/s on \
             {} camera rays ({hits} hits, BVH {bvh_hits}); BVH/brute-force ratio {:.0}x \
             (closest-hit on the same sample: {:.0}x)",
            mesh.triangle_count(),
            builds.iter().cloned().fold(f64::INFINITY, f64::min),
            builds.iter().cloned().fold(0.0, f64::max),
            stats.primary_rays,
            stats.shadow_rays,
            stats.skipped_back_facing,
            best,
            rays / best / 1e6,
            brute_rate,
            sample.len(),
            rays / best / brute_rate,
            bvh_sample_rate / brute_rate,
        );
    }
}
