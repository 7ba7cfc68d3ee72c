//! The optimised shadow-ray path (8 x 8-tile packets per light) against the simple one: the
//! whole precompute of real meshes must be bit-identical, and single packets must give exactly
//! the per-ray `occluded` answers, also for incoherent origins, partial packets and directions
//! with zero and -0.0 components.

mod common;

use common::Rng;
use mesh_encoding::glam::Vec3;
use raycast_precompute::rig::orbit_views;
use raycast_precompute::{
    PACKET_SIZE, PrecomputeSettings, Tracer, Traversal, precompute_with_traversal,
};

#[test]
fn packets_match_one_by_one_on_real_meshes() {
    for (name, size) in [("stanford-bunny.obj", 160), ("spot.obj", 128)] {
        let Some(mesh) = common::shared_mesh(name) else { return };
        let tracer = Tracer::new(&mesh);
        let views = orbit_views(3, 42, (size, size), 2.6, 45.0, 5).unwrap();
        let settings = PrecomputeSettings::default();
        let simple =
            precompute_with_traversal(&tracer, &views, &settings, Traversal::OneByOne).unwrap();
        let packets =
            precompute_with_traversal(&tracer, &views, &settings, Traversal::Packets).unwrap();
        // Enough of every state for the comparison to mean something.
        let (lit, shadowed, back) = simple
            .views
            .iter()
            .map(|v| v.visibility.counts())
            .fold((0, 0, 0), |a, c| (a.0 + c.0, a.1 + c.1, a.2 + c.2));
        println!("{name}: lit {lit}, shadowed {shadowed}, back-facing {back}");
        assert!(lit > 10_000 && shadowed > 1_000 && back > 1_000, "{name}");
        assert_eq!(simple.stats, packets.stats, "{name}");
        for (a, b) in simple.views.iter().zip(&packets.views) {
            assert_eq!(a.visibility, b.visibility, "{name}");
        }
        assert_eq!(simple, packets, "{name}");
    }
}

#[test]
fn single_packets_match_per_ray_queries() {
    let Some(mesh) = common::shared_mesh("suzanne.obj") else { return };
    let tracer = Tracer::new(&mesh);
    let mut rng = Rng::new(11);
    let mut dirs: Vec<Vec3> = (0..40).map(|_| rng.direction()).collect();
    dirs.extend([Vec3::Z, -Vec3::Z, Vec3::X, -Vec3::Y, Vec3::new(-0.0, 0.6, -0.8)]);
    let (mut occluded, mut total) = (0usize, 0usize);
    for dir in dirs {
        for n in [1, 5, 37, PACKET_SIZE] {
            // Origins on and just off the surface (coherent or not), and some outside the mesh.
            let origins: Vec<Vec3> = (0..n)
                .map(|_| {
                    if rng.uniform() < 0.2 {
                        return 1.5 * rng.direction();
                    }
                    let t = (rng.0.next_u64() % mesh.triangle_count() as u64) as usize;
                    let [v0, v1, v2] = mesh.corners(t);
                    let (a, b) = (rng.uniform(), rng.uniform());
                    let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
                    let n = (v1 - v0).cross(v2 - v0).normalize_or_zero();
                    v0 + a * (v1 - v0) + b * (v2 - v0) + 1e-4 * n
                })
                .collect();
            let mask = tracer.occluded_packet(dir, &origins);
            assert_eq!(mask, tracer.occluded_packet_portable(dir, &origins), "SSE vs AVX-512");
            for (i, o) in origins.iter().enumerate() {
                let alone = tracer.occluded(*o, dir, f32::INFINITY);
                assert_eq!(mask & (1 << i) != 0, alone, "ray {i} of {n}, dir {dir}, origin {o}");
                occluded += usize::from(alone);
                total += 1;
            }
            if n < PACKET_SIZE {
                assert_eq!(mask >> n, 0, "bits beyond the packet");
            }
        }
    }
    assert!(occluded > total / 10 && occluded < total * 9 / 10, "{occluded} of {total}");
    assert_eq!(tracer.occluded_packet(Vec3::Z, &[]), 0);
}

#[test]
fn batched_closest_hits_match_closest_hit() {
    let Some(mesh) = common::shared_mesh("spot.obj") else { return };
    let tracer = Tracer::new(&mesh);
    let mut rng = Rng::new(23);
    // Camera rays of a tile-like bundle, plus random rays of every octant (some with -0.0).
    let mut origins = Vec::new();
    let mut dirs = Vec::new();
    let eye = Vec3::new(0.3, -2.4, 0.9);
    for i in 0..150 {
        let target = Vec3::new(0.01 * (i % 12) as f32 - 0.06, 0.0, 0.01 * (i / 12) as f32 - 0.06);
        origins.push(eye);
        dirs.push((target - eye).normalize());
    }
    for _ in 0..300 {
        let o = 1.8 * rng.direction();
        origins.push(o);
        dirs.push((0.5 * rng.direction() - o).normalize());
    }
    origins.extend([Vec3::new(0.1, 0.05, 3.0), Vec3::new(0.02, 3.0, 0.1)]);
    dirs.extend([Vec3::new(-0.0, 0.0, -1.0), Vec3::new(0.0, -1.0, -0.0)]);
    let mut batched = vec![None; dirs.len()];
    tracer.closest_hits(&origins, &dirs, &mut batched);
    let mut hits = 0;
    for (i, got) in batched.iter().enumerate() {
        let alone = tracer.closest_hit(origins[i], dirs[i], f32::INFINITY);
        assert_eq!(*got, alone, "ray {i}");
        hits += usize::from(alone.is_some());
    }
    assert!(hits > 150 && hits < dirs.len() - 20, "{hits}");
}
