//! The BVH tracer against the f64 brute-force reference on small shared meshes: camera rays from
//! several views plus random rays. Required: the same hit/miss and the same triangle for at least
//! 99.99 % of rays, and barycentrics within 1e-5 where the triangle agrees; shadow (any-hit)
//! queries agree likewise.

mod common;

use common::Rng;
use mesh_encoding::glam::Vec3;
use raycast_precompute::{BruteForce, Camera, Tracer};

#[derive(Default, Debug)]
struct Tally {
    rays: usize,
    hits: usize,
    same: usize,
    max_bary_diff: f32,
    shadow_rays: usize,
    shadow_same: usize,
}

fn compare(tracer: &Tracer, reference: &BruteForce, origin: Vec3, dir: Vec3, tally: &mut Tally) {
    let a = tracer.closest_hit(origin, dir, f32::INFINITY);
    let b = reference.closest_hit(origin, dir, f32::INFINITY);
    tally.rays += 1;
    match (a, b) {
        (None, None) => tally.same += 1,
        (Some(a), Some(b)) => {
            tally.hits += 1;
            if a.triangle == b.triangle {
                tally.same += 1;
                for k in 0..2 {
                    let d = (a.barycentrics[k] - b.barycentrics[k]).abs();
                    tally.max_bary_diff = tally.max_bary_diff.max(d);
                }
                assert!((a.t - b.t).abs() <= 1e-5 * b.t.max(1.0), "t {} vs {}", a.t, b.t);
            }
        }
        _ => {}
    }
}

#[test]
fn bvh_agrees_with_brute_force_on_small_meshes() {
    let mut tally = Tally::default();
    let mut rng = Rng::new(7);
    for (name, res) in [("suzanne.obj", 96), ("woody.obj", 64), ("cow.obj", 48), ("spot.obj", 48)] {
        let Some(mesh) = common::shared_mesh(name) else { return };
        let tracer = Tracer::new(&mesh);
        let reference = BruteForce::new(&mesh);
        for _ in 0..3 {
            let eye = 2.5 * rng.direction();
            let up = if eye.normalize().z.abs() > 0.9 { Vec3::X } else { Vec3::Z };
            let cam = Camera::look_at(eye, Vec3::ZERO, up, 40.0, res, res).unwrap();
            for px in 0..cam.pixel_count() {
                let (o, d) = cam.pixel_ray(px);
                compare(&tracer, &reference, o, d, &mut tally);
            }
        }
        for _ in 0..1000 {
            let origin = 3.0 * rng.direction();
            let dir = (0.6 * rng.direction() - origin).normalize();
            compare(&tracer, &reference, origin, dir, &mut tally);
        }
        // Shadow rays: from points just off the surface, in random directions.
        for _ in 0..1000 {
            let t = (rng.0.next_u64() % mesh.triangle_count() as u64) as usize;
            let [v0, v1, v2] = mesh.corners(t);
            let n = (v1 - v0).cross(v2 - v0).normalize();
            let origin = (v0 + v1 + v2) / 3.0 + 1e-4 * n;
            let mut dir = rng.direction();
            if dir.dot(n) < 0.0 {
                dir = -dir;
            }
            tally.shadow_rays += 1;
            let same = tracer.occluded(origin, dir, f32::INFINITY)
                == reference.occluded(origin, dir, f32::INFINITY);
            tally.shadow_same += usize::from(same);
        }
    }
    println!("{tally:?}");
    assert!(tally.hits > tally.rays / 5, "too few hits to mean anything: {tally:?}");
    assert!(tally.same as f64 >= 0.9999 * tally.rays as f64, "{tally:?}");
    assert!(tally.max_bary_diff < 1e-5, "{tally:?}");
    assert!(tally.shadow_same as f64 >= 0.9999 * tally.shadow_rays as f64, "{tally:?}");
}
