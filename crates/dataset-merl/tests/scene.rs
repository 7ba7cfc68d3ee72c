//! The semi-synthetic scene generator and dataset API: a Lambertian sphere above a plane renders
//! rho/pi E cos within noise, shadowed pixels are zero, generation is deterministic, resumable
//! and atomic, and the loader rejects tampered scenes.

// Channel loops index several arrays at once.
#![allow(clippy::needless_range_loop)]

mod common;

use common::TempDir;
use dataset_merl::generate_scene;
use scene::SceneDataset;
use scene::Split;
use scene::{MaterialSpec, SceneConfig, SceneSettings};
use std::path::PathBuf;

fn small_settings() -> SceneSettings {
    SceneSettings {
        width: 64,
        height: 64,
        views: 4,
        train_views: 2,
        lights_per_view: 6,
        train_lights: 4,
        ..SceneSettings::default()
    }
}

fn lambert_config(mesh: PathBuf) -> SceneConfig {
    SceneConfig {
        mesh,
        material: MaterialSpec::Lambert { albedo: [0.5, 0.3, 0.8] },
        seed: 7,
        settings: small_settings(),
        merl_dir: None,
    }
}

#[test]
fn lambertian_renders_rho_over_pi_e_cos_and_shadows_are_zero() {
    let dir = TempDir::new("lambert");
    let cfg = lambert_config(test_support::mesh::write_sphere_over_plane(&dir.0, 24, 48));
    let out = dir.0.join("scene");
    let report = generate_scene(&cfg, &out, false).unwrap();
    assert!(!report.skipped && report.label == "analytic (Lambert)");
    assert!(
        report.stats.lit_samples > 1000 && report.stats.shadowed_samples > 50,
        "{:?}",
        report.stats
    );
    let ds = SceneDataset::open(&out).unwrap();
    assert_eq!(ds.manifest.label, report.label, "the manifest carries the provenance label");
    let sigma = cfg.settings.noise_sigma as f64;
    let e = cfg.settings.light_intensity;
    let mut checked = 0;
    let mut sum_sq = 0.0;
    for split in [Split::Train, Split::Test] {
        let s = ds.samples(split).unwrap();
        assert!(!s.is_empty());
        for i in 0..s.len() {
            let (n, l) = (s.normal[i], s.l[i]);
            let cos = (n[0] * l[0] + n[1] * l[1] + n[2] * l[2]) as f64;
            assert!(cos > 0.0);
            for c in 0..3 {
                let rho = [0.5, 0.3, 0.8][c];
                let expect = rho / std::f64::consts::PI * e[c] as f64 * cos;
                let r = s.observed[i][c] as f64 - expect;
                assert!(
                    r.abs() < 6.0 * sigma + 1e-5,
                    "sample {i} channel {c}: {} vs {expect}",
                    s.observed[i][c]
                );
                sum_sq += r * r;
                checked += 1;
            }
            assert!(s.gt_valid[i] && !s.saturated[i]);
            assert!((s.gt_brdf[i][0] as f64 - 0.5 / std::f64::consts::PI).abs() < 1e-7);
        }
    }
    // The residual is the sensor noise: its standard deviation is sigma.
    let sd = (sum_sq / checked as f64).sqrt();
    assert!((sd / sigma - 1.0).abs() < 0.05, "residual sd {sd} vs sigma {sigma}");
    // Shadowed pixels are zero up to noise.
    let flags = ds.flags_image(0, 0).unwrap();
    let img = ds.observed_image(0, 0).unwrap();
    let mut shadowed = 0;
    for v in 0..ds.manifest.views.len() {
        for li in 0..ds.manifest.views[v].lights.len() {
            let flags = ds.flags_image(v, li).unwrap();
            let img = ds.observed_image(v, li).unwrap();
            for (f, p) in flags.iter().zip(&img) {
                if f & scene::flag::SHADOWED != 0 {
                    shadowed += 1;
                    assert!(p.iter().all(|x| (*x as f64).abs() < 6.0 * sigma), "{p:?}");
                }
            }
        }
    }
    assert!(shadowed > 50);
    // Background pixels are exactly zero.
    assert!(flags.iter().zip(&img).all(|(f, p)| *f != 0 || *p == [0.0; 3]));
}

#[test]
fn generation_is_deterministic_resumable_and_seeded() {
    let dir = TempDir::new("determinism");
    let cfg = lambert_config(test_support::mesh::write_sphere_over_plane(&dir.0, 24, 48));
    let (a, b) = (dir.0.join("a"), dir.0.join("b"));
    generate_scene(&cfg, &a, false).unwrap();
    generate_scene(&cfg, &b, false).unwrap();
    let ma = SceneDataset::open(&a).unwrap().manifest;
    let mb = SceneDataset::open(&b).unwrap().manifest;
    assert_eq!(ma.files, mb.files);
    assert!(generate_scene(&cfg, &a, false).unwrap().skipped);
    let other = SceneConfig { seed: 8, ..cfg.clone() };
    let r = generate_scene(&other, &a, false).unwrap();
    assert!(!r.skipped);
    let mc = SceneDataset::open(&a).unwrap().manifest;
    assert_ne!(mc.files, mb.files);
    // No temporary directory left behind.
    let leftovers: Vec<_> = std::fs::read_dir(&dir.0)
        .unwrap()
        .filter_map(|e| {
            let n = e.unwrap().file_name().into_string().unwrap();
            n.contains("partial").then_some(n)
        })
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

#[test]
fn loader_rejects_tampered_scenes() {
    let dir = TempDir::new("tamper");
    let cfg = lambert_config(test_support::mesh::write_sphere_over_plane(&dir.0, 24, 48));
    let out = dir.0.join("scene");
    generate_scene(&cfg, &out, false).unwrap();
    let manifest_path = out.join("manifest.json");
    let original = std::fs::read_to_string(&manifest_path).unwrap();
    // An edited value in the manifest.
    let edited = original.replacen("\"seed\": 7", "\"seed\": 9", 1);
    assert_ne!(edited, original);
    std::fs::write(&manifest_path, &edited).unwrap();
    let msg = SceneDataset::open(&out).err().expect("tampered manifest accepted").to_string();
    assert!(msg.contains("manifest.json") && msg.contains("checksum"), "{msg}");
    std::fs::write(&manifest_path, &original).unwrap();
    // A changed data file.
    let img = out.join("images/v01_l02.exr");
    let mut bytes = std::fs::read(&img).unwrap();
    let n = bytes.len();
    bytes[n - 5] ^= 0xFF;
    std::fs::write(&img, &bytes).unwrap();
    let msg = SceneDataset::open(&out).err().expect("changed image accepted").to_string();
    assert!(msg.contains("v01_l02.exr") && msg.contains("hash"), "{msg}");
    // A missing data file.
    std::fs::remove_file(&img).unwrap();
    let msg = SceneDataset::open(&out).err().expect("missing image accepted").to_string();
    assert!(msg.contains("v01_l02.exr"), "{msg}");
}

#[test]
fn bad_inputs_are_clear_errors_and_leave_nothing_behind() {
    let dir = TempDir::new("bad");
    let out = dir.0.join("scene");
    let missing = lambert_config(dir.0.join("nope.obj"));
    let msg = generate_scene(&missing, &out, false).unwrap_err().to_string();
    assert!(msg.contains("nope.obj"), "{msg}");
    let bad_mesh = dir.0.join("bad.obj");
    std::fs::write(&bad_mesh, "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n").unwrap();
    let msg = generate_scene(&lambert_config(bad_mesh), &out, false).unwrap_err().to_string();
    assert!(msg.contains("bad.obj"), "{msg}");
    let unknown = SceneConfig {
        material: MaterialSpec::Merl { name: "unobtainium".into() },
        ..lambert_config(test_support::mesh::write_sphere_over_plane(&dir.0, 24, 48))
    };
    let msg = generate_scene(&unknown, &out, false).unwrap_err().to_string();
    assert!(msg.contains("unobtainium"), "{msg}");
    let captured = SceneConfig {
        material: MaterialSpec::Captured { benchmark: "DiLiGenT".into(), object: "ball".into() },
        ..lambert_config(test_support::mesh::write_sphere_over_plane(&dir.0, 24, 48))
    };
    let msg = generate_scene(&captured, &out, false).unwrap_err().to_string();
    assert!(msg.contains("imported") && msg.contains("ball"), "{msg}");
    let msg = SceneConfig::from_json(r#"{"mesh": "m.obj", "material": {"kind": "lambert", "albedo": [0.5, 0.5, 0.5]}, "seed": 1, "settings": {"widht": 3}}"#)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("widht"), "{msg}");
    let msg = SceneConfig::from_json(r#"{"mesh": "m.obj", "material": {"kind": "lambert", "albedo": [0.5, 0.5, 0.5]}, "seed": 1, "settings": {"train_views": 30}}"#)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("train_views"), "{msg}");
    assert!(!out.exists());
    // Only the two mesh files the test wrote: no scene, no partial directory.
    assert_eq!(std::fs::read_dir(&dir.0).unwrap().count(), 2);
}

#[test]
fn merl_scene_stores_the_table_lookup_as_ground_truth() {
    let dir = TempDir::new("merl");
    let cfg = SceneConfig {
        material: MaterialSpec::Merl { name: "maroon-plastic".into() },
        ..lambert_config(test_support::mesh::write_sphere_over_plane(&dir.0, 24, 48))
    };
    let out = dir.0.join("scene");
    let r = generate_scene(&cfg, &out, false).unwrap();
    assert_eq!(r.label, "MERL-derived (NBRDF)");
    let ds = SceneDataset::open(&out).unwrap();
    let table = dataset_merl::load_material("maroon-plastic", None).unwrap().table;
    let s = ds.samples(Split::Test).unwrap();
    assert!(s.len() > 100);
    for i in (0..s.len()).step_by(7) {
        let f = angles::Frame::from_normal(s.normal[i].map(f64::from));
        let (l, v) = (f.to_local(s.l[i].map(f64::from)), f.to_local(s.v[i].map(f64::from)));
        let expect = table.eval_dirs(l, v, dataset_merl::Lookup::NearestLower).unwrap();
        for c in 0..3 {
            assert!(
                (s.gt_brdf[i][c] as f64 - expect[c]).abs() <= 1e-6 * expect[c].max(1e-3),
                "{i}"
            );
        }
    }
}
