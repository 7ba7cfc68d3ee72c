//! The noise ceiling and the paper's protocol on the smoke profile's scene (the shipped Spot
//! mesh, blue-acrylic, 32 px, 4 views x 12 lights): a "model" that returns the exact
//! ground-truth BRDF scores the ceiling (the noise-free renders against the observations) to
//! 1e-6 dB on every metric, and +inf dB against the noise-free renders in both protocols; a
//! model off by a few percent scores below the ceiling, and its whole-frame PSNR exceeds its
//! masked one by exactly 10 log10(frame pixels / object pixels).

use experiments::data::{RecordSet, SpatialFeatures};
use experiments::eval::Prediction;
use experiments::eval::images::{RenderOptions, render_and_score};
use scene::SceneDataset;
use scene::{MaterialSpec, SceneConfig, SceneSettings, Split};

use test_support::TempDir;

/// The Spot mesh the binaries embed (`embedded:spot`).
fn spot_mesh() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data-manifests/embedded/spot/spot.obj")
}

fn smoke_scene(dir: &std::path::Path) -> SceneDataset {
    let config = SceneConfig {
        mesh: spot_mesh(),
        material: MaterialSpec::Merl { name: "blue-acrylic".into() },
        seed: 1,
        settings: SceneSettings::with_counts(32, 4, 12),
        merl_dir: None,
    };
    let out = dir.join("scene");
    dataset_merl::generate_scene(&config, &out, false).unwrap();
    SceneDataset::open(&out).unwrap()
}

#[test]
fn the_ground_truth_scores_the_noise_ceiling_exactly() {
    let dir = TempDir::new("ceiling");
    let scene = smoke_scene(&dir.0);
    assert!(scene.has_clean_renders());
    let samples = scene.samples(Split::Test).unwrap();
    let none = SpatialFeatures { point: vec![0; samples.len()], ..Default::default() };
    let data = RecordSet::new(&samples, &none);
    assert!(!data.is_empty());
    let gt: Vec<[f32; 3]> = data.source.iter().map(|&i| samples.gt_brdf[i]).collect();
    let opts = RenderOptions {
        run: &dir.0,
        write: false,
        lpips: None,
        progress: false,
        skip_ceiling: false,
    };
    let score = |f: Vec<[f32; 3]>| {
        let pred = Prediction { f, ..Default::default() };
        render_and_score(&scene, &samples, &data, &pred, &opts).unwrap()
    };
    let perfect = score(gt.clone());
    let ceiling = perfect.ceiling.clone().expect("a semi-synthetic scene has a ceiling");
    assert!(perfect.images > 0);
    assert!((perfect.model.psnr - ceiling.psnr).abs() < 1e-6, "{perfect:?}");
    assert!((perfect.model.dssim - ceiling.dssim).abs() < 1e-12, "{perfect:?}");
    assert!((perfect.model.flip - ceiling.flip).abs() < 1e-12, "{perfect:?}");
    let clean = perfect.clean.clone().unwrap();
    assert_eq!(clean.psnr, f64::INFINITY, "{perfect:?}");
    assert_eq!((clean.dssim, clean.flip), (0.0, 0.0), "{perfect:?}");
    // The noise (sigma 1e-3) is what bounds the ceiling: finite, and high.
    assert!(ceiling.psnr.is_finite() && ceiling.psnr > 35.0, "{ceiling:?}");
    // A model 3 % too bright is below the ceiling against the observations and finite
    // against the noise-free renders.
    let off = score(gt.iter().map(|f| f.map(|x| 1.03 * x)).collect());
    assert!(off.model.psnr < ceiling.psnr - 0.1, "{off:?} vs {ceiling:?}");
    assert!(off.clean.unwrap().psnr.is_finite());
    assert_eq!(off.ceiling.unwrap(), ceiling, "the ceiling does not depend on the model");
}

#[test]
fn the_papers_protocol_scores_the_whole_frame_against_the_noise_free_renders() {
    let dir = TempDir::new("paper-protocol");
    let scene = smoke_scene(&dir.0);
    let samples = scene.samples(Split::Test).unwrap();
    let none = SpatialFeatures { point: vec![0; samples.len()], ..Default::default() };
    let data = RecordSet::new(&samples, &none);
    let gt: Vec<[f32; 3]> = data.source.iter().map(|&i| samples.gt_brdf[i]).collect();
    let opts = RenderOptions {
        run: &dir.0,
        write: false,
        lpips: None,
        progress: false,
        skip_ceiling: true,
    };
    let score = |f: Vec<[f32; 3]>| {
        let pred = Prediction { f, ..Default::default() };
        render_and_score(&scene, &samples, &data, &pred, &opts).unwrap()
    };
    // The exact ground truth: +inf dB, no structural or perceptual error.
    let perfect = score(gt.clone()).paper.expect("every evaluation has the paper's protocol");
    assert_eq!(perfect.psnr, f64::INFINITY, "{perfect:?}");
    assert_eq!((perfect.dssim, perfect.flip), (0.0, 0.0), "{perfect:?}");
    // A model 5 % too dark, image by image: against the same (noise-free) reference, the
    // whole frame's PSNR minus the mask's is 10 log10(frame / mask), the background matching
    // exactly. The run's mean over images is the mean of those per-image identities.
    let dark: Vec<[f32; 3]> = gt.iter().map(|f| f.map(|x| 0.95 * x)).collect();
    let off = score(dark.clone());
    let (whole, masked) = (off.paper.clone().unwrap(), off.clean.clone().unwrap());
    let size = scene.manifest.config.settings.width as usize;
    let pairs = scene.pairs(Split::Test);
    let expected: f64 = pairs
        .iter()
        .map(|&(v, _)| {
            let mask = scene.geometry.views[v].pixels.len() as f64;
            10.0 * ((size * size) as f64 / mask).log10()
        })
        .sum::<f64>()
        / pairs.len() as f64;
    assert!(whole.psnr.is_finite() && masked.psnr.is_finite());
    assert!(
        (whole.psnr - masked.psnr - expected).abs() < 1e-9,
        "whole {} - masked {} = {}, expected {expected}",
        whole.psnr,
        masked.psnr,
        whole.psnr - masked.psnr
    );
    assert!(expected > 3.0, "the object covers less than half the frame: {expected}");
    // The reading against the observations (background set to 0): the same identity with our
    // masked score against the observations.
    let observed = off.paper_observed.clone().unwrap();
    assert!(
        (observed.psnr - off.model.psnr - expected).abs() < 1e-9,
        "whole {} - masked {} against the observations, expected {expected}",
        observed.psnr,
        off.model.psnr
    );
    // The background adds no error: the whole frame's FLIP and DSSIM are below the mask's.
    assert!(whole.flip < masked.flip && whole.dssim < masked.dssim, "{whole:?} {masked:?}");
    assert_eq!(off.frame_pixels, pairs.len() * size * size);
}

#[test]
fn scenes_of_the_old_format_ask_to_be_regenerated() {
    let dir = TempDir::new("old-scene");
    let scene = smoke_scene(&dir.0);
    // Rewrite the manifest as version 1 (checksum recomputed: a valid old manifest).
    let mut m = scene.manifest.clone();
    m.version = 1;
    let path = scene.dir.join(scene::MANIFEST_FILE);
    std::fs::write(&path, m.to_json()).unwrap();
    let err = SceneDataset::open(&scene.dir).err().expect("version 1 is refused").to_string();
    assert!(err.contains("version 1") && err.contains("regenerate"), "{err}");
    assert!(err.contains("manifest.json"), "{err}");
}
