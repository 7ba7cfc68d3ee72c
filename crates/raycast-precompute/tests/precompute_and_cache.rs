//! The precompute's data layout and masks, and the cache paths: miss, hit, corrupted and
//! truncated files (recomputed, never trusted), content keys independent of file names.

mod common;

use mesh_encoding::glam::Vec3;
use mesh_encoding::{NormalWeighting, TriMesh};
use raycast_precompute::{
    CacheOutcome, Camera, PrecomputeSettings, ShadowBias, View, cache_key, cache_path, precompute,
    precompute_cached,
};

fn sphere_mesh() -> TriMesh {
    let (p, t) = common::uv_sphere(Vec3::ZERO, 1.0, 24, 48);
    TriMesh::new(p, t).unwrap()
}

fn views() -> Vec<View> {
    let mut rng = common::Rng::new(3);
    (0..3)
        .map(|_| {
            let eye = 3.0 * rng.direction();
            let up = if eye.normalize().z.abs() > 0.9 { Vec3::X } else { Vec3::Z };
            let camera = Camera::look_at(eye, Vec3::ZERO, up, 45.0, 40, 30).unwrap();
            let lights = (0..70).map(|_| rng.direction().into()).collect();
            View { camera, lights, mask: None }
        })
        .collect()
}

#[test]
fn layout_is_consistent_and_masks_restrict_tracing() {
    let mesh = sphere_mesh();
    let views = views();
    let settings = PrecomputeSettings::default();
    let full = precompute(&mesh, &views, &settings).unwrap();
    for (v, view) in full.views.iter().zip(&views) {
        assert!(!v.is_empty() && v.len() < 40 * 30);
        assert!(v.pixels.windows(2).all(|w| w[0] < w[1]));
        let eye = view.camera.center();
        for k in 0..v.len() {
            let x = v.positions[k];
            assert!((x.length() - 1.0).abs() < 0.01);
            assert!(v.normals[k].is_normalized() && v.view_dirs[k].is_normalized());
            assert!((v.view_dirs[k] - (eye - x).normalize()).length() < 1e-4);
            assert!(v.normals[k].dot(v.view_dirs[k]) > -0.05, "visible side of a sphere");
            assert!(
                view.camera.project(x).unwrap().distance(mesh_encoding::glam::Vec2::new(
                    (v.pixels[k] % 40) as f32 + 0.5,
                    (v.pixels[k] / 40) as f32 + 0.5
                )) < 1e-2
            );
        }
        assert_eq!(v.visibility.light_count(), 70);
    }
    // Masked: only every third pixel.
    let mut masked_views = views.clone();
    for v in &mut masked_views {
        v.mask = Some((0..40 * 30).map(|i| i % 3 == 0).collect());
    }
    let masked = precompute(&mesh, &masked_views, &settings).unwrap();
    assert_eq!(masked.stats.primary_rays, 3 * 400);
    for (m, f) in masked.views.iter().zip(&full.views) {
        for (k, &px) in m.pixels.iter().enumerate() {
            let j = f.pixels.binary_search(&px).unwrap();
            assert_eq!(m.triangles[k], f.triangles[j]);
            for l in 0..70 {
                assert_eq!(m.visibility.get(k, l), f.visibility.get(j, l));
            }
        }
        assert_eq!(m.len(), f.pixels.iter().filter(|&&p| p % 3 == 0).count());
    }
    // Bad inputs are errors naming the view.
    let mut bad = views.clone();
    bad[1].lights[4] = Vec3::ZERO.into();
    let e = precompute(&mesh, &bad, &settings).unwrap_err().to_string();
    assert!(e.contains("view 1") && e.contains("light 4"), "{e}");
    let mut bad = views;
    bad[2].mask = Some(vec![true; 5]);
    assert!(precompute(&mesh, &bad, &settings).unwrap_err().to_string().contains("view 2"));
}

#[test]
fn cache_miss_hit_corruption_and_keys() {
    let tmp = common::TempDir::new("cache");
    let dir = tmp.0.clone();
    let mesh = sphere_mesh();
    let views = views();
    let settings = PrecomputeSettings::default();

    let (first, outcome) = precompute_cached(&mesh, &views, &settings, &dir).unwrap();
    assert_eq!(outcome, CacheOutcome::Miss);
    let (second, outcome) = precompute_cached(&mesh, &views, &settings, &dir).unwrap();
    assert_eq!(outcome, CacheOutcome::Hit);
    assert_eq!(first, second);
    assert_eq!(first, precompute(&mesh, &views, &settings).unwrap());

    let path = cache_path(&dir, cache_key(&mesh, &views, &settings));
    let good = std::fs::read(&path).unwrap();
    let damage: Vec<(&str, Vec<u8>)> = vec![
        ("checksum", {
            let mut b = good.clone();
            let mid = b.len() / 2;
            b[mid] ^= 0x10;
            b
        }),
        ("truncated", good[..good.len() - 100].to_vec()),
        ("magic", {
            let mut b = good.clone();
            b[0] = b'X';
            b
        }),
        ("version", {
            let mut b = good.clone();
            b[8] = b[8].wrapping_add(1);
            b
        }),
        ("magic or size", good[..20].to_vec()),
        ("magic or size", Vec::new()),
    ];
    for (expected, bytes) in damage {
        std::fs::write(&path, &bytes).unwrap();
        let (scene, outcome) = precompute_cached(&mesh, &views, &settings, &dir).unwrap();
        match outcome {
            CacheOutcome::Rebuilt { reason } => assert!(reason.contains(expected), "{reason}"),
            other => panic!("damaged ({expected}) file was {other:?}"),
        }
        assert_eq!(scene, first);
        // The file was replaced by a good one.
        assert_eq!(std::fs::read(&path).unwrap(), good);
    }
    // No temporary files are left behind.
    let names: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(names.len(), 1, "{names:?}");

    // Keys follow content: a clone has the same key, any change a different one.
    let key = cache_key(&mesh, &views, &settings);
    assert_eq!(key, cache_key(&mesh.clone(), &views.clone(), &settings));
    let mut moved = mesh.clone();
    moved.positions[0].x += 1e-6;
    assert_ne!(key, cache_key(&moved, &views, &settings));
    let mut relit = views.clone();
    if let raycast_precompute::Light::Directional(d) = &mut relit[0].lights[0] {
        d.y += 1e-6;
    }
    assert_ne!(key, cache_key(&mesh, &relit, &settings));
    let area = PrecomputeSettings { normal_weighting: NormalWeighting::Area, ..settings };
    assert_ne!(key, cache_key(&mesh, &views, &area));
    let abs = PrecomputeSettings { shadow_bias: ShadowBias::Absolute(1e-4), ..settings };
    assert_ne!(key, cache_key(&mesh, &views, &abs));
}

#[test]
fn shared_mesh_from_two_file_names_shares_one_cache_entry() {
    let Some(data) = common::data_dir() else { return };
    let tmp = common::TempDir::new("names");
    let dir = tmp.0.clone();
    let copy = dir.join("renamed-spot.obj");
    std::fs::copy(data.join("meshes/spot.obj"), &copy).unwrap();
    let options = mesh_encoding::LoadOptions::default();
    let a = mesh_encoding::load_mesh(data.join("meshes/spot.obj"), &options).unwrap().mesh;
    let b = mesh_encoding::load_mesh(&copy, &options).unwrap().mesh;
    let cam = Camera::look_at(Vec3::new(0.0, -3.0, 0.5), Vec3::ZERO, Vec3::Z, 40.0, 8, 8).unwrap();
    let views = vec![View { camera: cam, lights: vec![Vec3::Z.into()], mask: None }];
    let cache = dir.join("cache");
    let s = PrecomputeSettings::default();
    assert_eq!(precompute_cached(&a, &views, &s, &cache).unwrap().1, CacheOutcome::Miss);
    assert_eq!(precompute_cached(&b, &views, &s, &cache).unwrap().1, CacheOutcome::Hit);
}
