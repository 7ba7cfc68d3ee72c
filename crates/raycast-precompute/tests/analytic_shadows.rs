//! Shadows on an analytic scene: a tessellated sphere above a ground plane, lit by a directional
//! light. A plane point x is in shadow exactly when the line x + s l (s > 0) passes within the
//! sphere's radius of its centre; sphere points are lit exactly when n.l > 0 (convex, nothing
//! above them). Points within a small margin of either boundary (tessellation) are not judged.

mod common;

use mesh_encoding::TriMesh;
use mesh_encoding::glam::Vec3;
use raycast_precompute::{Camera, LightState, PrecomputeSettings, View, precompute};

const CENTER: Vec3 = Vec3::new(0.0, 0.0, 1.0);
const RADIUS: f32 = 0.5;

fn scene() -> TriMesh {
    let (mut p, mut t) = common::uv_sphere(CENTER, RADIUS, 48, 96);
    let base = p.len() as u32;
    let s = 4.0;
    p.extend([
        Vec3::new(-s, -s, 0.0),
        Vec3::new(s, -s, 0.0),
        Vec3::new(s, s, 0.0),
        Vec3::new(-s, s, 0.0),
    ]);
    t.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
    TriMesh::new(p, t).unwrap()
}

#[test]
fn sphere_casts_the_analytic_shadow_on_the_plane() {
    let mesh = scene();
    let l = Vec3::new(0.5, 0.2, 1.0).normalize();
    let below = Vec3::new(0.1, 0.0, -1.0).normalize();
    let camera = Camera::look_at(
        Vec3::new(0.3, -4.0, 3.5),
        Vec3::new(0.3, 0.0, 0.3),
        Vec3::Z,
        45.0,
        160,
        160,
    )
    .unwrap();
    let view = View { camera, lights: vec![l.into(), below.into()], mask: None };
    let scene = precompute(&mesh, &[view], &PrecomputeSettings::default()).unwrap();
    let v = &scene.views[0];
    let plane_first = mesh.triangle_count() as u32 - 2;
    let (mut plane_lit, mut plane_shadow, mut sphere_lit, mut sphere_dark) = (0, 0, 0, 0);
    for k in 0..v.len() {
        let x = v.positions[k];
        let state = v.visibility.get(k, 0);
        if v.triangles[k] >= plane_first {
            assert!(x.z.abs() < 1e-5);
            assert!((v.normals[k] - Vec3::Z).length() < 1e-5);
            // Below-plane light: back-facing, never traced.
            assert_eq!(v.visibility.get(k, 1), LightState::BackFacing);
            let w = CENTER - x;
            let dist = (w - w.dot(l) * l).length();
            if (dist - RADIUS).abs() < 0.02 {
                continue;
            }
            let expected = if dist < RADIUS && w.dot(l) > 0.0 {
                plane_shadow += 1;
                LightState::Shadowed
            } else {
                plane_lit += 1;
                LightState::Lit
            };
            assert_eq!(state, expected, "plane point {x}, distance to axis {dist}");
        } else {
            let n_exact = (x - CENTER).normalize();
            assert!(
                (x - CENTER).length() <= RADIUS + 1e-5 && (x - CENTER).length() > 0.99 * RADIUS
            );
            assert!(v.normals[k].dot(n_exact) > 0.999, "normal {} vs {}", v.normals[k], n_exact);
            let c = v.normals[k].dot(l);
            if c.abs() < 0.05 {
                continue;
            }
            if c > 0.0 {
                sphere_lit += 1;
                assert_eq!(state, LightState::Lit, "sphere point {x}");
            } else {
                sphere_dark += 1;
                assert_eq!(state, LightState::BackFacing, "sphere point {x}");
            }
        }
    }
    println!(
        "plane lit {plane_lit} shadowed {plane_shadow}; sphere lit {sphere_lit} back {sphere_dark}"
    );
    assert!(plane_lit > 1000 && plane_shadow > 300 && sphere_lit > 300 && sphere_dark > 100);
    // Every back-facing pair was skipped, every other pair traced.
    let (lit, shadowed, back) = v.visibility.counts();
    assert_eq!(scene.stats.shadow_rays as usize, lit + shadowed);
    assert_eq!(scene.stats.skipped_back_facing as usize, back);
    assert_eq!(scene.stats.primary_rays, 160 * 160);
}

/// A bias of zero lets the shadow ray start on its own triangle: some pixels then shadow
/// themselves (acne) on the plane, which the default bias prevents.
#[test]
fn default_bias_prevents_acne_and_is_relative_to_scene_size() {
    let mesh = scene();
    let l = Vec3::new(-0.3, 0.1, 1.0).normalize();
    let camera =
        Camera::look_at(Vec3::new(0.0, -3.0, 6.0), Vec3::new(2.5, 2.5, 0.0), Vec3::Z, 30.0, 96, 96)
            .unwrap();
    let view = View { camera, lights: vec![l.into()], mask: None };
    let scene =
        precompute(&mesh, std::slice::from_ref(&view), &PrecomputeSettings::default()).unwrap();
    assert!((scene.shadow_bias - 1e-4 * mesh.diagonal()).abs() < 1e-9);
    let v = &scene.views[0];
    // Pixels on the plane far from the sphere's shadow are all lit.
    let far = (0..v.len()).filter(|&k| v.positions[k].x > 2.0 && v.positions[k].y > 2.0);
    let mut n = 0;
    for k in far {
        n += 1;
        assert_eq!(v.visibility.get(k, 0), LightState::Lit, "acne at {}", v.positions[k]);
    }
    assert!(n > 1000, "{n}");
}
