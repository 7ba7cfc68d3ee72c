//! `eval`: renders the test images of a finished run and computes its metrics (spec 7).
//!
//! For every test (view, light) pair the model is evaluated at the lit foreground pixels and
//! the rendering L = f E cos(theta_l) is written as linear EXR and sRGB PNG into
//! `<run>/renders/`; shadowed and back-facing pixels render 0, like the ground truth (the
//! renderer has no interreflections). PSNR and DSSIM (sRGB clamped to [0, 1]) and HDR-FLIP
//! (linear) are computed on the object mask (the view's foreground pixels) and averaged over
//! the test images; the cube-root RMSE runs over the lit test samples with theta_l, theta_v
//! <= 80 degrees, not saturated and with a valid ground truth. The results are added to
//! `<run>/metrics.json` under `test`.

use crate::config::RunConfig;
use crate::data::{TrainingData, spatial_features};
use crate::run_dir::{CONFIG_FILE, METRICS_FILE, RunMetrics};
use crate::train::{cache_dir_for, load_weights};
use crate::{Error, Result};
use brdf_neural::{BrdfModel, ModelConfig, Samples};
use burn::tensor::Device;
use dataset_merl::SceneDataset;
use dataset_merl::scene::Split;
use dataset_merl::scene::images::{write_exr_rgb, write_png_srgb};
use indicatif::ProgressBar;
use metrics::Image;
use metrics::rmse::{CubeRootRmse, RmseConfig};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Rows per forward pass.
const CHUNK: usize = 1 << 15;

/// Test metrics of a run (spec 7), raw values (not table-scaled).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TestMetrics {
    /// Mean PSNR over the test images (dB, sRGB clamped, object mask).
    pub psnr: f64,
    /// Mean DSSIM over the test images.
    pub dssim: f64,
    /// Mean HDR-FLIP over the test images.
    pub flip: f64,
    /// Cube-root RMSE of the BRDF on the test samples.
    pub rmse_cbrt: f64,
    /// Samples that entered the RMSE.
    pub rmse_samples: usize,
    /// Test images evaluated.
    pub images: usize,
}

/// Evaluates `model` on every record of `data`: f `[n]` RGB.
pub fn predict(
    model: &BrdfModel,
    config: &ModelConfig,
    data: &TrainingData,
    device: &Device,
) -> Result<Vec<[f32; 3]>> {
    let mut out = Vec::with_capacity(data.len());
    let k = data.spatial_dim;
    for start in (0..data.len()).step_by(CHUNK) {
        let end = (start + CHUNK).min(data.len());
        let samples = Samples {
            spatial: &data.spatial[start * k..end * k],
            l: &data.l[start..end],
            v: &data.v[start..end],
        };
        let batch = config.batch(&samples, None, device)?;
        let f: Vec<f32> = model
            .forward(&batch)
            .f
            .into_data()
            .try_to_vec::<f32>()
            .map_err(|e| Error::config("model", format!("output not f32: {e:?}")))?;
        out.extend(f.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
    }
    Ok(out)
}

/// Evaluates the finished run in `run`; `scene` overrides the config's scene directory.
pub fn eval(
    run: &Path,
    scene: Option<&Path>,
    cache: Option<&Path>,
    progress: bool,
) -> Result<TestMetrics> {
    let mut config = RunConfig::read(&run.join(CONFIG_FILE))?;
    if let Some(s) = scene {
        config.scene = Some(s.to_path_buf());
    }
    let scene_dir = config
        .scene
        .clone()
        .ok_or_else(|| Error::config("scene", "no scene directory (pass --scene)"))?;
    let device = brdf_neural::device::cpu();
    let model = load_weights(&config, run, &device)?;
    let dataset = SceneDataset::open(&scene_dir)?;
    let samples = dataset.samples(Split::Test)?;
    let cache = cache_dir_for(&config, run, cache);
    let (spatial, dim) = spatial_features(&dataset, &samples, &config.features, &cache)?;
    let data = TrainingData::new(&samples, &spatial, dim);
    let f = predict(&model, &config.model, &data, &device)?;

    let mut rmse = CubeRootRmse::new(RmseConfig::default());
    for (r, &i) in data.source.iter().enumerate() {
        rmse.push(f[r], samples.gt_brdf[i], data.l[r][2], data.v[r][2], samples.saturated[i]);
    }
    let metrics_out = render_and_score(&dataset, &samples, &data, &f, run, progress)?;
    let test = TestMetrics { rmse_cbrt: rmse.value()?, rmse_samples: rmse.kept, ..metrics_out };
    let path = run.join(METRICS_FILE);
    let mut all = RunMetrics::read(&path)?;
    all.test = Some(test.clone());
    all.write(&path)?;
    Ok(test)
}

/// Renders every test pair, writes EXR + PNG and returns the mean image metrics.
fn render_and_score(
    dataset: &SceneDataset,
    samples: &dataset_merl::SampleSet,
    data: &TrainingData,
    f: &[[f32; 3]],
    run: &Path,
    progress: bool,
) -> Result<TestMetrics> {
    let s = &dataset.manifest.config.settings;
    let (w, h) = (s.width as usize, s.height as usize);
    let pairs = dataset.pairs(Split::Test);
    let renders = run.join("renders");
    std::fs::create_dir_all(&renders).map_err(|e| Error::io(&renders, e))?;
    // Records of each pair.
    let mut by_pair: std::collections::HashMap<(usize, usize), Vec<usize>> = Default::default();
    for (r, &i) in data.source.iter().enumerate() {
        by_pair.entry((samples.view[i] as usize, samples.light[i] as usize)).or_default().push(r);
    }
    let bar = if progress { ProgressBar::new(pairs.len() as u64) } else { ProgressBar::hidden() };
    let mut m = TestMetrics::default();
    for &(vi, li) in &pairs {
        let mut img = vec![[0.0_f32; 3]; w * h];
        for &r in by_pair.get(&(vi, li)).map(Vec::as_slice).unwrap_or_default() {
            let p = samples.pixel[data.source[r]] as usize;
            let wt = data.weight[r];
            img[p] = [f[r][0] * wt[0], f[r][1] * wt[1], f[r][2] * wt[2]];
        }
        let mut mask = vec![false; w * h];
        for &p in &dataset.geometry.views[vi].pixels {
            mask[p as usize] = true;
        }
        let gt = dataset.observed_image(vi, li)?;
        let stem = format!("view{vi:03}_light{li:03}");
        write_exr_rgb(&renders.join(format!("{stem}.exr")), w, h, &img)?;
        write_png_srgb(&renders.join(format!("{stem}.png")), w as u32, h as u32, &img)?;
        let flat = |v: &[[f32; 3]]| v.iter().flat_map(|c| c.iter().copied()).collect::<Vec<_>>();
        let test = Image::new(w, h, flat(&img))?;
        let reference = Image::new(w, h, flat(&gt))?;
        m.psnr += metrics::psnr_linear(&test, &reference, Some(&mask))?;
        m.dssim += metrics::dssim_linear(&test, &reference, Some(&mask))?;
        m.flip += metrics::hdr_flip(&test, &reference, Some(&mask))?;
        m.images += 1;
        bar.inc(1);
    }
    bar.finish_and_clear();
    let n = m.images.max(1) as f64;
    m.psnr /= n;
    m.dssim /= n;
    m.flip /= n;
    Ok(m)
}
