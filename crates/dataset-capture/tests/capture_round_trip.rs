//! A capture made from a semi-synthetic scene rendered with point lights imports to the same
//! samples (every record to 1e-6, identical masks), and bad captures are refused with an error
//! naming the file and the fault, writing nothing.

// Channel loops index several arrays at once.
#![allow(clippy::needless_range_loop)]

use dataset_capture::{export_capture, import_capture};
use dataset_merl::generate_scene;
use scene::manifest::Split;
use scene::{MaterialSpec, SceneConfig, SceneDataset, SceneSettings};
use std::path::{Path, PathBuf};
use test_support::TempDir;

/// A small semi-synthetic scene lit by point lights 2.5 mesh radii from the origin.
fn point_lit_scene(dir: &Path) -> PathBuf {
    let config = SceneConfig {
        mesh: test_support::mesh::write_sphere_over_plane(dir, 16, 32),
        material: MaterialSpec::Lambert { albedo: [0.5, 0.3, 0.8] },
        seed: 11,
        settings: SceneSettings {
            width: 48,
            height: 40,
            views: 6,
            train_views: 3,
            lights_per_view: 5,
            train_lights: 3,
            up_axis: scene::UpAxis::Z,
            point_light_distance: Some(2.5),
            ..SceneSettings::default()
        },
        merl_dir: None,
    };
    let out = dir.join("scene");
    generate_scene(&config, &out, false).unwrap();
    out
}

fn assert_close3(a: &[[f32; 3]], b: &[[f32; 3]], what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: counts");
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        for c in 0..3 {
            assert!(
                (x[c] - y[c]).abs() <= 1e-6 * (1.0 + y[c].abs()),
                "{what}[{i}]: {x:?} vs {y:?}"
            );
        }
    }
}

#[test]
fn a_point_lit_scene_survives_export_and_import() {
    let dir = TempDir::new("capture-round-trip");
    let original = point_lit_scene(&dir.0);
    let capture = dir.0.join("capture");
    export_capture(&original, &capture).unwrap();
    let imported = dir.0.join("imported");
    let report = import_capture(&capture, &imported, false, &stdx::Limits::DEFAULT).unwrap();
    let a = SceneDataset::open(&original).unwrap();
    let b = SceneDataset::open(&imported).unwrap();
    assert!(a.manifest.views[0].lights[0].position.is_some(), "the scene has point lights");
    // Every view's mask against the silhouette: the exported masks are the scene's own.
    for (vi, v) in report.views.iter().enumerate() {
        assert_eq!(v.iou, Some(1.0), "view {vi}: {v:?}");
        let ma = std::fs::read(original.join(format!("masks/v{vi:02}.png"))).unwrap();
        let mb = std::fs::read(imported.join(format!("masks/v{vi:02}.png"))).unwrap();
        assert_eq!(ma, mb, "view {vi}: masks differ");
    }
    for split in [Split::Train, Split::Test] {
        let (sa, sb) = (a.samples(split).unwrap(), b.samples(split).unwrap());
        // (The first orbit views look up at the plane's underside: few lit training samples.)
        assert!(sa.len() > 300, "{split:?}: {} samples", sa.len());
        assert_eq!(sa.view, sb.view, "{split:?}: views");
        // A capture holds only the pairs a scene uses, so a test view's lights are renumbered
        // from 0: compare each sample's light by its rank among the split's lights of its view.
        let rank = |d: &SceneDataset, view: u16, light: u16| {
            let lights = &d.manifest.views[view as usize].lights[..light as usize];
            lights.iter().filter(|l| l.split == split).count()
        };
        for i in 0..sa.len() {
            assert_eq!(
                rank(&a, sa.view[i], sa.light[i]),
                rank(&b, sb.view[i], sb.light[i]),
                "light of {i}"
            );
        }
        assert_eq!(sa.pixel, sb.pixel, "{split:?}: pixels");
        assert_eq!(sa.saturated, sb.saturated, "{split:?}: saturation");
        assert_close3(&sa.position, &sb.position, "position");
        assert_close3(&sa.normal, &sb.normal, "normal");
        assert_close3(&sa.l, &sb.l, "l");
        assert_close3(&sa.v, &sb.v, "v");
        assert_close3(&sa.irradiance, &sb.irradiance, "irradiance");
        assert_close3(&sa.observed, &sb.observed, "observed");
        // Point lights: the irradiance falls off with distance, so it varies over the samples.
        let (lo, hi) = sa
            .irradiance
            .iter()
            .fold((f32::MAX, 0.0_f32), |(lo, hi), e| (lo.min(e[0]), hi.max(e[0])));
        assert!(hi > 1.2 * lo, "{split:?}: irradiance {lo}..{hi} does not fall off");
    }
}

/// Imports `capture` into a fresh `out` and returns the error text, checking nothing was written.
fn refused(capture: &Path, what: &str) -> String {
    refused_within(capture, what, &stdx::Limits::DEFAULT)
}

/// [`refused`] within `limits`.
fn refused_within(capture: &Path, what: &str, limits: &stdx::Limits) -> String {
    let out = capture.with_file_name(format!("out-{}", what.replace(' ', "-")));
    let e = match import_capture(capture, &out, false, limits) {
        Ok(_) => panic!("{what}: the import succeeded"),
        Err(e) => e.to_string(),
    };
    assert!(!out.exists(), "{what}: {} was written", out.display());
    let parent = out.parent().unwrap();
    let leftovers: Vec<_> = std::fs::read_dir(parent)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains(".partial-"))
        .collect();
    assert!(leftovers.is_empty(), "{what}: temporary files left: {leftovers:?}");
    e
}

/// A fresh copy of the exported capture, for one corruption.
fn copy_of(capture: &Path, tag: &str) -> PathBuf {
    let to = capture.with_file_name(format!("capture-{tag}"));
    std::fs::create_dir_all(to.join("images")).unwrap();
    std::fs::create_dir_all(to.join("masks")).unwrap();
    for sub in ["", "images", "masks"] {
        for e in std::fs::read_dir(capture.join(sub)).unwrap() {
            let e = e.unwrap();
            if e.file_type().unwrap().is_file() {
                std::fs::copy(e.path(), to.join(sub).join(e.file_name())).unwrap();
            }
        }
    }
    to
}

fn edit_json(path: &Path, f: impl FnOnce(&mut serde_json::Value)) {
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    f(&mut v);
    std::fs::write(path, serde_json::to_string_pretty(&v).unwrap()).unwrap();
}

#[test]
fn bad_captures_are_refused_naming_the_file_and_the_fault() {
    let dir = TempDir::new("capture-bad");
    let original = point_lit_scene(&dir.0);
    let capture = dir.0.join("capture");
    export_capture(&original, &capture).unwrap();

    // Images larger than the caller's limits, refused from the cameras' size before any image
    // is decoded.
    let (w, h) = {
        let m = SceneDataset::open(&original).unwrap().manifest;
        (m.config.settings.width, m.config.settings.height)
    };
    let tight = stdx::Limits { max_image_pixels: u64::from(w * h) - 1, ..Default::default() };
    let e = refused_within(&capture, "beyond the limits", &tight);
    assert!(e.contains("transforms.json") && e.contains(&format!("{w} x {h} pixels")), "{e}");

    // A missing image.
    let c = copy_of(&capture, "missing");
    std::fs::remove_file(c.join("images/v01_l00.exr")).unwrap();
    let e = refused(&c, "missing image");
    assert!(e.contains("v01_l00.exr") && e.contains("missing"), "{e}");

    // A camera count that does not match the lights.
    let c = copy_of(&capture, "count");
    edit_json(&c.join("transforms.json"), |v| {
        v["frames"].as_array_mut().unwrap().pop();
    });
    let e = refused(&c, "count mismatch");
    assert!(e.contains("lights.json") && e.contains("camera images"), "{e}");

    // A mesh that is not aligned with the cameras (shifted by a third of its size).
    let c = copy_of(&capture, "misaligned");
    let mut mesh = scene::mesh_file::load(&c.join("mesh.ply")).unwrap();
    for p in &mut mesh.positions {
        p.x += 0.6;
    }
    std::fs::write(c.join("mesh.ply"), scene::mesh_file::ply_bytes(&mesh)).unwrap();
    let e = refused(&c, "misaligned mesh");
    assert!(e.contains("IoU") && e.contains("not aligned") && e.contains(".exr"), "{e}");

    // NaN pixels.
    let c = copy_of(&capture, "nan");
    let p = c.join("images/v00_l00.exr");
    let (w, h, mut px) = scene::images::read_exr_rgb(&p, &stdx::Limits::DEFAULT).unwrap();
    px[w * 3 + 5][1] = f32::NAN;
    scene::images::write_exr_rgb(&p, w, h, &px).unwrap();
    let e = refused(&c, "nan pixels");
    assert!(e.contains("v00_l00.exr") && e.contains("non-finite") && e.contains("(5, 3)"), "{e}");

    // A pose that cannot be inverted.
    let c = copy_of(&capture, "singular");
    edit_json(&c.join("transforms.json"), |v| {
        v["frames"][2]["transform_matrix"][2] = serde_json::json!([0.0, 0.0, 0.0, 1.0]);
    });
    let e = refused(&c, "singular pose");
    assert!(
        e.contains("transforms.json") && e.contains("frame 2") && e.contains("not invertible"),
        "{e}"
    );

    // An unknown key in capture.toml.
    let c = copy_of(&capture, "key");
    let toml = std::fs::read_to_string(c.join("capture.toml")).unwrap();
    std::fs::write(c.join("capture.toml"), format!("exposure = 2\n{toml}")).unwrap();
    let e = refused(&c, "bad key");
    assert!(e.contains("capture.toml") && e.contains("exposure"), "{e}");
}
