//! The test images of a run: renders, image metrics, FLIP error maps and the additive models'
//! split figures.
//!
//! For every test (view, light) pair the rendering L = f E cos(theta_l) is formed at the lit
//! foreground pixels (shadowed and back-facing pixels render 0, like the ground truth: the
//! renderer has no interreflections) and scored against the observed image on the object mask
//! (the view's foreground pixels): PSNR and DSSIM on sRGB clamped to [0, 1], HDR-FLIP on linear
//! values, and LPIPS (when its weights are present) on the sRGB images with the background set
//! to black in both (LPIPS has no mask argument; blacking the background out is the masked
//! equivalent). Written into the run directory when images are on:
//!
//! ```text
//! renders/view007_light003.{exr,png}        the model's rendering (linear EXR, sRGB PNG)
//! renders/view007_light003_diffuse.png      additive models: the diffuse part's rendering
//! renders/view007_light003_specular.png     additive models: the specular part's rendering
//! flip/view007_light003.png                 HDR-FLIP error map, magma, grey outside the mask
//! albedo/view007.png                        additive models: the diffuse albedo pi f_d (sRGB),
//!                                           averaged over the view's lit test samples
//! ```

use super::predict::Prediction;
use crate::data::TrainingData;
use crate::run_dir::write_atomic;
use crate::{Error, Result};
use dataset_merl::scene::Split;
use dataset_merl::scene::images::{write_exr_rgb, write_png_srgb};
use dataset_merl::{SampleSet, SceneDataset};
use indicatif::{ProgressBar, ProgressStyle};
use metrics::Image;
use metrics::lpips::Lpips;
use std::collections::HashMap;
use std::path::Path;

/// Mean image metrics over the test images.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ImageScores {
    /// Mean PSNR (dB).
    pub psnr: f64,
    /// Mean DSSIM.
    pub dssim: f64,
    /// Mean HDR-FLIP.
    pub flip: f64,
    /// Mean LPIPS, when the weights were present.
    pub lpips: Option<f64>,
    /// Test images scored.
    pub images: usize,
}

/// Writes an 8-bit RGB PNG atomically.
pub fn write_png_rgb8(path: &Path, width: usize, height: usize, rgb: &[[u8; 3]]) -> Result<()> {
    use image::ImageEncoder;
    let mut bytes = Vec::new();
    let flat: Vec<u8> = rgb.iter().flatten().copied().collect();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(&flat, width as u32, height as u32, image::ExtendedColorType::Rgb8)
        .map_err(|e| Error::format(path, format!("PNG encoding: {e}")))?;
    write_atomic(path, &bytes)
}

fn flat(v: &[[f32; 3]]) -> Vec<f32> {
    v.iter().flat_map(|c| c.iter().copied()).collect()
}

fn mul(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] * b[0], a[1] * b[1], a[2] * b[2]]
}

/// Renders every test pair, writes the images (when `write`) and returns the mean metrics.
/// `lpips`: the loaded network, or `None` (weights missing).
#[allow(clippy::too_many_arguments)]
pub fn render_and_score(
    dataset: &SceneDataset,
    samples: &SampleSet,
    data: &TrainingData,
    pred: &Prediction,
    run: &Path,
    write: bool,
    lpips: Option<&Lpips>,
    progress: bool,
) -> Result<ImageScores> {
    let s = &dataset.manifest.config.settings;
    let (w, h) = (s.width as usize, s.height as usize);
    let pairs = dataset.pairs(Split::Test);
    let (renders, flips, albedo_dir) = (run.join("renders"), run.join("flip"), run.join("albedo"));
    if write {
        for d in [&renders, &flips, &albedo_dir] {
            std::fs::create_dir_all(d).map_err(|e| Error::io(d, e))?;
        }
    }
    let mut by_pair: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
    for (r, &i) in data.source.iter().enumerate() {
        by_pair.entry((samples.view[i] as usize, samples.light[i] as usize)).or_default().push(r);
    }
    let bar = if progress { ProgressBar::new(pairs.len() as u64) } else { ProgressBar::hidden() };
    bar.set_style(
        ProgressStyle::with_template("eval {bar:40} {pos}/{len} test images, eta {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let mut m = ImageScores::default();
    let mut lpips_sum = 0.0;
    // Per view: sum of pi f_d and the count, for the albedo maps.
    let mut albedo: HashMap<usize, (Vec<[f32; 3]>, Vec<u32>)> = HashMap::new();
    for &(vi, li) in &pairs {
        let records = by_pair.get(&(vi, li)).map(Vec::as_slice).unwrap_or_default();
        let render = |part: &[[f32; 3]]| {
            let mut img = vec![[0.0_f32; 3]; w * h];
            for &r in records {
                img[samples.pixel[data.source[r]] as usize] = mul(part[r], data.weight[r]);
            }
            img
        };
        let img = render(&pred.f);
        let mut mask = vec![false; w * h];
        for &p in &dataset.geometry.views[vi].pixels {
            mask[p as usize] = true;
        }
        let gt = dataset.observed_image(vi, li)?;
        let test = Image::new(w, h, flat(&img))?;
        let reference = Image::new(w, h, flat(&gt))?;
        m.psnr += metrics::psnr_linear(&test, &reference, Some(&mask))?;
        m.dssim += metrics::dssim_linear(&test, &reference, Some(&mask))?;
        let flip = metrics::hdr_flip_with(&test, &reference, Some(&mask), &Default::default())?;
        m.flip += flip.mean;
        if let Some(net) = lpips {
            let masked = |im: &Image| {
                let srgb = metrics::srgb::to_srgb_clamped(im);
                let d: Vec<f32> = srgb
                    .data()
                    .chunks_exact(3)
                    .zip(&mask)
                    .flat_map(|(c, &inside)| if inside { [c[0], c[1], c[2]] } else { [0.0; 3] })
                    .collect();
                Image::new(w, h, d)
            };
            lpips_sum += net.distance(&masked(&test)?, &masked(&reference)?)?;
        }
        m.images += 1;
        if write {
            let stem = format!("view{vi:03}_light{li:03}");
            write_exr_rgb(&renders.join(format!("{stem}.exr")), w, h, &img)?;
            write_png_srgb(&renders.join(format!("{stem}.png")), w as u32, h as u32, &img)?;
            let map = metrics::colormap::error_map_rgb8(&flip.map, Some(&mask));
            write_png_rgb8(&flips.join(format!("{stem}.png")), w, h, &map)?;
            for (name, part) in [("diffuse", &pred.diffuse), ("specular", &pred.specular)] {
                if let Some(part) = part {
                    let path = renders.join(format!("{stem}_{name}.png"));
                    write_png_srgb(&path, w as u32, h as u32, &render(part))?;
                }
            }
            if let Some(fd) = &pred.diffuse_raw {
                let (sum, count) =
                    albedo.entry(vi).or_insert_with(|| (vec![[0.0; 3]; w * h], vec![0; w * h]));
                for &r in records {
                    let p = samples.pixel[data.source[r]] as usize;
                    for c in 0..3 {
                        sum[p][c] += std::f32::consts::PI * fd[r][c];
                    }
                    count[p] += 1;
                }
            }
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    let mut views: Vec<_> = albedo.into_iter().collect();
    views.sort_by_key(|(vi, _)| *vi);
    for (vi, (sum, count)) in views {
        let mean: Vec<[f32; 3]> = sum
            .iter()
            .zip(&count)
            .map(|(s, &n)| if n > 0 { s.map(|x| x / n as f32) } else { [0.0; 3] })
            .collect();
        write_png_srgb(&albedo_dir.join(format!("view{vi:03}.png")), w as u32, h as u32, &mean)?;
    }
    let n = m.images.max(1) as f64;
    m.psnr /= n;
    m.dssim /= n;
    m.flip /= n;
    m.lpips = lpips.map(|_| lpips_sum / n);
    Ok(m)
}
