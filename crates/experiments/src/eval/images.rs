//! The test images of a run: renders, image metrics against the observed and the noise-free
//! images, the noise ceiling, FLIP error maps and the additive models' split figures.
//!
//! For every test (view, light) pair the rendering L = f E cos(theta_l) is formed at the lit
//! foreground pixels (shadowed and back-facing pixels render 0, like the ground truth: the
//! renderer has no interreflections) by the scene's own [`shade`], clipped at the scene's
//! saturation level for semi-synthetic scenes (the sensor clips every observation there), and
//! scored on the object mask (the view's foreground pixels): PSNR and DSSIM on sRGB clamped to
//! [0, 1], HDR-FLIP on linear values, and LPIPS (when its weights are present) on the sRGB
//! images with the background set to black in both (LPIPS has no mask argument; blacking the
//! background out is the masked equivalent).
//!
//! Semi-synthetic scenes also hold the noise-free render of every test pair. The model is then
//! scored against it too ([`ImageScores::clean`]), and the noise-free render itself is scored
//! against the observation: the noise ceiling, the best any model can score
//! ([`ImageScores::ceiling`]). A model that returns the ground-truth BRDF renders the
//! noise-free image exactly, so it scores the ceiling against the observations and infinite
//! PSNR against the noise-free images. HDR-FLIP takes its exposure range from the observed
//! image in all three comparisons of a test image (a noise-free image can be all black in the
//! mask, where FLIP's range is undefined).
//!
//! **Two protocols.** Everything above is ours: the object mask, against the observations,
//! beside the noise ceiling. The paper's Table 1 scores differently, and every run is scored
//! that way too ([`ImageScores::paper`], [`whole_frame`]): the whole frame, background
//! included, against the noise-free render (a capture has none: its observation with the
//! background set to 0). The background is exactly 0 in the render and that reference, so the
//! whole frame's PSNR exceeds the masked one by 10 log10(frame pixels / object pixels) when
//! the scores are against the same reference, and an exact model scores +inf dB. The paper
//! does not say which reference it used, so a generated scene is also scored over the whole
//! frame against its observation with the background set to 0
//! ([`ImageScores::paper_observed`]): the reading that keeps the sensor noise.
//!
//! Written into the run directory when images are on:
//!
//! ```text
//! renders/view007_light003.{exr,png}        the model's rendering (linear EXR, sRGB PNG)
//! renders/view007_light003_diffuse.png      additive models: the diffuse part's rendering
//! renders/view007_light003_specular.png     additive models: the specular part's rendering
//! flip/view007_light003.png                 HDR-FLIP error map, magma, grey outside the mask
//! albedo/view007.png                        additive models: the diffuse albedo pi f_d (sRGB),
//!                                           averaged over the view's lit test samples
//! ```

use crate::data::RecordSet;
use crate::{Error, Result};
use brdf_neural::fitted::Prediction;
use indicatif::ProgressBar;
use metrics::Image;
use metrics::flip::FlipWindow;
use metrics::lpips::Lpips;
use rayon::prelude::*;
use run_format::ImageMetrics;
use scene::Split;
use scene::images::{exr_rgb_bytes, png_srgb_bytes};
use scene::shading::shade;
use scene::{SampleSet, SceneDataset};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The mean metrics of a run's test images.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ImageScores {
    /// The model against the observed (noisy) test images.
    pub model: ImageMetrics,
    /// The paper's protocol: the model against the noise-free test images (captured scenes:
    /// the observations with the background set to 0) over the whole frame
    /// ([`whole_frame`]).
    pub paper: Option<ImageMetrics>,
    /// The paper's whole frame against the observations instead, their background set to 0
    /// (semi-synthetic scenes: the other reading of the paper's protocol, which keeps the
    /// sensor noise in the reference; a capture's `paper` already is this).
    pub paper_observed: Option<ImageMetrics>,
    /// The model against the noise-free test images (semi-synthetic scenes).
    pub clean: Option<ImageMetrics>,
    /// The noise ceiling: the noise-free images against the observed ones (semi-synthetic
    /// scenes).
    pub ceiling: Option<ImageMetrics>,
    /// Test images scored.
    pub images: usize,
    /// Pixels scored over all test images (the masks' sizes summed).
    pub pixels: usize,
    /// Pixels of the whole frames of all test images (the paper's protocol).
    pub frame_pixels: usize,
}

/// Writes a linear RGB image as an EXR file atomically.
fn write_exr_rgb(path: &Path, width: usize, height: usize, rgb: &[[f32; 3]]) -> Result<()> {
    Ok(stdx::fs::write_atomic(path, &exr_rgb_bytes(path, width, height, rgb)?)?)
}

/// Writes a linear RGB image as an 8-bit sRGB PNG atomically.
pub fn write_png_srgb_atomic(path: &Path, width: u32, height: u32, rgb: &[[f32; 3]]) -> Result<()> {
    Ok(stdx::fs::write_atomic(path, &png_srgb_bytes(path, width, height, rgb)?)?)
}

/// Writes an 8-bit RGB PNG atomically.
pub fn write_png_rgb8(path: &Path, width: usize, height: usize, rgb: &[[u8; 3]]) -> Result<()> {
    use image::ImageEncoder;
    let mut bytes = Vec::new();
    let flat: Vec<u8> = rgb.iter().flatten().copied().collect();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(&flat, width as u32, height as u32, image::ExtendedColorType::Rgb8)
        .map_err(|e| Error::format(path, format!("PNG encoding: {e}")))?;
    Ok(stdx::fs::write_atomic(path, &bytes)?)
}

fn to_image(w: usize, h: usize, v: &[[f32; 3]]) -> Result<Image> {
    Ok(Image::new(w, h, v.iter().flat_map(|c| c.iter().copied()).collect())?)
}

/// A test image in the two spaces the metrics take: linear (HDR-FLIP) and sRGB clamped to
/// [0, 1] (PSNR, DSSIM, LPIPS), converted once however many comparisons it is in.
pub struct Shown {
    /// Linear values.
    pub linear: Image,
    /// [`metrics::srgb::to_srgb_clamped`] of them.
    pub srgb: Image,
}

impl Shown {
    fn new(linear: Image) -> Shown {
        Shown { srgb: metrics::srgb::to_srgb_clamped(&linear), linear }
    }
}

/// Scores `test` against `reference` on `mask`; `flip` is HDR-FLIP of the same pair on the
/// same mask (computed by the caller from prepared images, [`metrics::FlipImage`]).
pub fn score(
    test: &Shown,
    reference: &Shown,
    mask: &[bool],
    lpips: Option<&Lpips>,
    flip: &metrics::FlipResult,
) -> Result<ImageMetrics> {
    let lpips = match lpips {
        Some(net) => {
            let masked = |im: &Image| {
                let d: Vec<f32> = im
                    .data()
                    .chunks_exact(3)
                    .zip(mask)
                    .flat_map(|(c, &inside)| if inside { [c[0], c[1], c[2]] } else { [0.0; 3] })
                    .collect();
                Image::new(im.width(), im.height(), d)
            };
            Some(net.distance(&masked(&test.srgb)?, &masked(&reference.srgb)?)?)
        }
        None => None,
    };
    Ok(ImageMetrics {
        psnr: metrics::psnr(&test.srgb, &reference.srgb, Some(mask))?,
        dssim: metrics::dssim(&test.srgb, &reference.srgb, Some(mask))?,
        flip: flip.mean,
        lpips,
    })
}

/// The paper's protocol on one test image: `test` against `reference` over the whole frame,
/// background included (PSNR and DSSIM on sRGB clamped to [0, 1], data range 1; HDR-FLIP the
/// mean of `flip`'s map over every pixel). `flip` is HDR-FLIP of the same pair, computed with
/// the exposure range of the reference's object pixels: a whole frame whose background (most
/// of it) is black has a zero median luminance and so no exposure range of its own. `lpips`
/// is the pair's LPIPS, which LPIPS already computes on the whole frame (the background is 0 in
/// both images here, as in the masked protocol's input).
pub fn whole_frame(
    test: &Shown,
    reference: &Shown,
    flip: &metrics::flip::FlipResult,
    lpips: Option<f64>,
) -> Result<ImageMetrics> {
    let map = &flip.map;
    Ok(ImageMetrics {
        psnr: metrics::psnr(&test.srgb, &reference.srgb, None)?,
        dssim: metrics::dssim(&test.srgb, &reference.srgb, None)?,
        flip: map.iter().map(|&v| v as f64).sum::<f64>() / map.len().max(1) as f64,
        lpips,
    })
}

/// The observation of a captured scene as the paper's protocol's reference: the pixels outside
/// the object mask set to 0, as they are in every render (captures have no noise-free image).
fn background_removed(observed: &Image, mask: &[bool]) -> Result<Image> {
    let d: Vec<f32> = observed
        .data()
        .chunks_exact(3)
        .zip(mask)
        .flat_map(|(c, &inside)| if inside { [c[0], c[1], c[2]] } else { [0.0; 3] })
        .collect();
    Ok(Image::new(observed.width(), observed.height(), d)?)
}

/// What [`render_and_score`] needs besides the scene and the prediction.
pub struct RenderOptions<'a> {
    /// The run directory (images are written below it).
    pub run: &'a Path,
    /// Write the images.
    pub write: bool,
    /// The LPIPS network, or `None` (weights missing).
    pub lpips: Option<&'a Lpips>,
    /// Show a progress bar.
    pub progress: bool,
    /// Skip the noise ceiling (already known for this scene): [`ImageScores::ceiling`] is then
    /// `None`.
    pub skip_ceiling: bool,
}

/// Renders every test pair, writes the images (when `opts.write`) and returns the mean metrics.
pub fn render_and_score(
    dataset: &SceneDataset,
    samples: &SampleSet,
    data: &RecordSet,
    pred: &Prediction,
    opts: &RenderOptions<'_>,
) -> Result<ImageScores> {
    let t = TestImages::new(dataset, samples, data);
    let (w, h) = (t.width, t.height);
    let out = OutputDirs::new(opts.run, opts.write)?;
    let bar = progress_bar(t.pairs.len(), opts.progress);
    // One test image per task: rendering, the (up to three) scores and the image files are
    // independent across pairs, and FLIP dominates the cost.
    let one_pair = |&pair: &(usize, usize)| -> Result<PairScores> {
        let scores = score_pair(&t, (dataset, pred), opts, out.as_ref(), pair)?;
        bar.inc(1);
        Ok(scores)
    };
    let per_pair: Vec<PairScores> = if opts.lpips.is_some() {
        // The LPIPS network runs its own threads; one image at a time.
        t.pairs.iter().map(one_pair).collect::<Result<_>>()?
    } else {
        t.pairs.par_iter().map(one_pair).collect::<Result<_>>()?
    };
    bar.finish_and_clear();
    let sums = PairSums::of(&per_pair);
    if let (Some(out), Some(fd)) = (&out, &pred.diffuse_raw) {
        let mut albedo = AlbedoMaps::default();
        for &(vi, li) in &t.pairs {
            let records = t.records(vi, li);
            albedo.add(vi, w * h, records.iter().map(|&r| (samples.pixel[data.source[r]], fd[r])));
        }
        albedo.write(&out.albedo, (w, h))?;
    }
    let n = t.pairs.len();
    let pixels = t.pairs.iter().map(|&(vi, _)| dataset.geometry.views[vi].pixels.len()).sum();
    let PairSums { model, clean, ceiling, paper, paper_observed } = sums;
    Ok(ImageScores {
        model: model.divided(n),
        paper: paper.map(|p| p.divided(n)),
        paper_observed: paper_observed.map(|p| p.divided(n)),
        frame_pixels: n * w * h,
        clean: clean.map(|c| c.divided(n)),
        ceiling: ceiling.map(|c| c.divided(n)),
        images: n,
        pixels,
    })
}

/// Renders test pair `(vi, li)`, scores it in every protocol and writes its files (when `out`).
fn score_pair(
    t: &TestImages,
    (dataset, pred): (&SceneDataset, &Prediction),
    opts: &RenderOptions<'_>,
    out: Option<&OutputDirs>,
    (vi, li): (usize, usize),
) -> Result<PairScores> {
    let (w, h) = (t.width, t.height);
    let records = t.records(vi, li);
    let render = |part: &[[f32; 3]]| t.render(records, part);
    let img = render(&pred.f);
    let mask = t.mask(vi);
    let test = Shown::new(to_image(w, h, &img)?);
    let observed = Shown::new(to_image(w, h, &dataset.observed_image(vi, li)?)?);
    // The observation with its background set to 0, scored over the whole frame: the
    // paper's protocol for a capture, its other reading for a generated scene.
    let reference = Shown::new(background_removed(&observed.linear, &mask)?);
    let noise_free =
        dataset.clean_image(vi, li)?.map(|c| to_image(w, h, &c).map(Shown::new)).transpose()?;
    let whole_frame_references = [Some(&reference.linear), noise_free.as_ref().map(|n| &n.linear)];
    let flip = FlipPair::new(&test.linear, &observed.linear, &mask, whole_frame_references)?;
    let (flip_test, flip_observed) = (flip.prepare(&test.linear)?, flip.prepare(&observed.linear)?);
    let model_flip = flip.compare(&flip_test, &flip_observed, Some(&mask))?;
    let model = score(&test, &observed, &mask, opts.lpips, &model_flip)?;
    let mut scores =
        PairScores { model, clean: None, ceiling: None, paper: None, paper_observed: None };
    // The masked LPIPS blacks out both backgrounds: it is the whole frame's here.
    let f = flip.compare(&flip_test, &flip.prepare(&reference.linear)?, None)?;
    let against_observed = whole_frame(&test, &reference, &f, scores.model.lpips)?;
    if let Some(noise_free) = &noise_free {
        let flip_clean = flip.prepare(&noise_free.linear)?;
        let clean_flip = flip.compare(&flip_test, &flip_clean, Some(&mask))?;
        let clean = score(&test, noise_free, &mask, opts.lpips, &clean_flip)?;
        // Both images are 0 outside the mask: the masked LPIPS is the whole frame's.
        scores.paper = Some(whole_frame(&test, noise_free, &clean_flip, clean.lpips)?);
        scores.paper_observed = Some(against_observed);
        scores.clean = Some(clean);
        if !opts.skip_ceiling {
            let f = flip.compare(&flip_clean, &flip_observed, Some(&mask))?;
            scores.ceiling = Some(score(noise_free, &observed, &mask, opts.lpips, &f)?);
        }
    } else {
        scores.paper = Some(against_observed);
    }
    if let Some(out) = out {
        let stem = format!("view{vi:03}_light{li:03}");
        out.write_pair(&stem, (w, h), &img, &model_flip.map, &mask)?;
        for (name, part) in [("diffuse", &pred.diffuse), ("specular", &pred.specular)] {
            if let Some(part) = part {
                let path = out.renders.join(format!("{stem}_{name}.png"));
                write_png_srgb_atomic(&path, w as u32, h as u32, &render(part))?;
            }
        }
    }
    Ok(scores)
}

/// The per-pair scores summed (each protocol where every pair has it).
struct PairSums {
    model: ImageMetrics,
    clean: Option<ImageMetrics>,
    ceiling: Option<ImageMetrics>,
    paper: Option<ImageMetrics>,
    paper_observed: Option<ImageMetrics>,
}

impl PairSums {
    fn of(per_pair: &[PairScores]) -> PairSums {
        let (mut model, mut clean, mut ceiling) = (ImageMetrics::default(), None, None);
        let (mut paper, mut paper_observed): (Option<ImageMetrics>, Option<ImageMetrics>) =
            (None, None);
        for s in per_pair {
            model.add(&s.model);
            if let Some(p) = &s.paper {
                paper.get_or_insert_with(ImageMetrics::default).add(p);
            }
            if let Some(p) = &s.paper_observed {
                paper_observed.get_or_insert_with(ImageMetrics::default).add(p);
            }
            if let Some(c) = &s.clean {
                clean.get_or_insert_with(ImageMetrics::default).add(c);
            }
            if let Some(g) = &s.ceiling {
                ceiling.get_or_insert_with(ImageMetrics::default).add(g);
            }
        }
        PairSums { model, clean, ceiling, paper, paper_observed }
    }
}

/// The HDR-FLIP comparisons of one test image, on the window of its frame that they need.
///
/// Every comparison shares the observed image's exposures (a noise-free image can be black
/// where every lit pixel faces away), so each of the (up to four) images is prepared once,
/// whichever side of a comparison it is on. They run on a [`FlipWindow`] around the object
/// mask and every pixel where the render or a whole-frame reference (the observation without
/// its background, the noise-free image) is not 0: the masked means and the whole frame's maps
/// are then the whole frame's, bit for bit (see [`metrics::flip::window`]; outside the mask a
/// comparison with the noisy observation is not, and only its mask is read).
struct FlipPair {
    at: metrics::FlipExposures,
    window: Option<FlipWindow>,
}

impl FlipPair {
    fn new(
        test: &Image,
        observed: &Image,
        mask: &[bool],
        references: [Option<&Image>; 2],
    ) -> Result<FlipPair> {
        let range = metrics::flip::exposure_range(observed, Some(mask))?;
        let ppd = metrics::flip::DEFAULT_PPD;
        let at = metrics::FlipExposures::new(range, ppd)?;
        // A NaN counts as not 0: its image is then cropped, and refused there.
        let lit = |im: &Image| -> Vec<bool> {
            im.data().chunks_exact(3).map(|c| c.iter().any(|v| *v != 0.0)).collect()
        };
        let mut keep = mask.to_vec();
        for im in [Some(test)].into_iter().chain(references).flatten() {
            keep.iter_mut().zip(lit(im)).for_each(|(k, l)| *k |= l);
        }
        let pixels = keep.iter().enumerate().filter(|(_, k)| **k).map(|(p, _)| p);
        let window = FlipWindow::around((test.width(), test.height()), ppd, pixels)?
            .filter(|w| w.pixels() < test.pixels());
        Ok(FlipPair { at, window })
    }

    /// `image` prepared at the pair's exposures, on the window.
    fn prepare(&self, image: &Image) -> Result<metrics::FlipImage> {
        Ok(match &self.window {
            Some(w) => metrics::FlipImage::new(&w.crop(image)?, &self.at)?,
            None => metrics::FlipImage::new(image, &self.at)?,
        })
    }

    /// HDR-FLIP of two prepared images, its mean over `mask` (of the frame) and its map in
    /// the whole frame.
    fn compare(
        &self,
        test: &metrics::FlipImage,
        reference: &metrics::FlipImage,
        mask: Option<&[bool]>,
    ) -> Result<metrics::FlipResult> {
        let Some(w) = &self.window else {
            return Ok(metrics::hdr_flip_prepared(test, reference, mask)?);
        };
        let cropped = mask.map(|m| w.crop_mask(m)).transpose()?;
        let mut result = metrics::hdr_flip_prepared(test, reference, cropped.as_deref())?;
        result.map = w.embed(&result.map)?;
        if mask.is_none() {
            // The whole frame's mean, summed in its order (the zeros outside add nothing).
            let sum: f64 = result.map.iter().map(|&v| v as f64).sum();
            result.mean = sum / result.map.len() as f64;
        }
        Ok(result)
    }
}

/// The scores of one test image.
struct PairScores {
    model: ImageMetrics,
    clean: Option<ImageMetrics>,
    ceiling: Option<ImageMetrics>,
    paper: Option<ImageMetrics>,
    paper_observed: Option<ImageMetrics>,
}

/// The mean PSNR of the renders of `f` (one BRDF value per record of `data`) against the
/// observed test images: the cheap score of the run-time curve's snapshots.
pub fn mean_psnr(
    dataset: &SceneDataset,
    samples: &SampleSet,
    data: &RecordSet,
    f: &[[f32; 3]],
) -> Result<f64> {
    let t = TestImages::new(dataset, samples, data);
    let psnr: Vec<f64> = t
        .pairs
        .par_iter()
        .map(|&(vi, li)| {
            let test = to_image(t.width, t.height, &t.render(t.records(vi, li), f))?;
            let observed = to_image(t.width, t.height, &dataset.observed_image(vi, li)?)?;
            Ok(metrics::psnr_linear(&test, &observed, Some(&t.mask(vi)))?)
        })
        .collect::<Result<_>>()?;
    Ok(psnr.iter().sum::<f64>() / t.pairs.len().max(1) as f64)
}

/// Per test pair (in [`SceneDataset::pairs`] order): the PSNR (sRGB-clamped, object mask) of
/// the render of `f` against the render of `reference`, two BRDF values per record of `data`
/// rendered the same way (the export round trip's score; infinite where they agree exactly).
pub fn psnr_between(
    dataset: &SceneDataset,
    samples: &SampleSet,
    data: &RecordSet,
    f: &[[f32; 3]],
    reference: &[[f32; 3]],
) -> Result<Vec<f64>> {
    let t = TestImages::new(dataset, samples, data);
    t.pairs
        .par_iter()
        .map(|&(vi, li)| {
            let records = t.records(vi, li);
            let test = to_image(t.width, t.height, &t.render(records, f))?;
            let refr = to_image(t.width, t.height, &t.render(records, reference))?;
            Ok(metrics::psnr_linear(&test, &refr, Some(&t.mask(vi)))?)
        })
        .collect()
}

/// The test pairs of a scene and their records, for rendering.
struct TestImages<'a> {
    dataset: &'a SceneDataset,
    samples: &'a SampleSet,
    data: &'a RecordSet,
    width: usize,
    height: usize,
    pairs: Vec<(usize, usize)>,
    by_pair: HashMap<(usize, usize), Vec<usize>>,
    clip: Option<f32>,
}

impl<'a> TestImages<'a> {
    fn new(dataset: &'a SceneDataset, samples: &'a SampleSet, data: &'a RecordSet) -> Self {
        let s = &dataset.manifest.config.settings;
        let mut by_pair: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
        for (r, &i) in data.source.iter().enumerate() {
            let key = (samples.view[i] as usize, samples.light[i] as usize);
            by_pair.entry(key).or_default().push(r);
        }
        TestImages {
            dataset,
            samples,
            data,
            width: s.width as usize,
            height: s.height as usize,
            pairs: dataset.pairs(Split::Test),
            by_pair,
            clip: crate::data::clip_level(dataset),
        }
    }

    /// The records of a test pair.
    fn records(&self, vi: usize, li: usize) -> &[usize] {
        self.by_pair.get(&(vi, li)).map(Vec::as_slice).unwrap_or_default()
    }

    /// The object mask of a view.
    fn mask(&self, vi: usize) -> Vec<bool> {
        let mut mask = vec![false; self.width * self.height];
        for &p in &self.dataset.geometry.views[vi].pixels {
            mask[p as usize] = true;
        }
        mask
    }

    /// The image of `part` (one value per record of the data) at `records`, clipped.
    fn render(&self, records: &[usize], part: &[[f32; 3]]) -> Vec<[f32; 3]> {
        let mut img = vec![[0.0_f32; 3]; self.width * self.height];
        for &r in records {
            let l = shade(part[r], self.data.weight[r]);
            let p = self.samples.pixel[self.data.source[r]] as usize;
            img[p] = self.clip.map_or(l, |c| l.map(|x| x.min(c)));
        }
        img
    }
}

fn progress_bar(len: usize, visible: bool) -> ProgressBar {
    stdx::progress::bar(len as u64, "test images", "eval", visible)
}

/// The image folders of a run.
struct OutputDirs {
    renders: PathBuf,
    flips: PathBuf,
    albedo: PathBuf,
}

impl OutputDirs {
    /// Creates the folders; `None` when images are not written.
    fn new(run: &Path, write: bool) -> Result<Option<Self>> {
        if !write {
            return Ok(None);
        }
        let run = run_format::run_dir::RunDir::new(run);
        let d = OutputDirs { renders: run.renders(), flips: run.flip(), albedo: run.albedo() };
        for dir in [&d.renders, &d.flips, &d.albedo] {
            std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
        }
        Ok(Some(d))
    }

    /// The render (EXR and sRGB PNG) and the FLIP map of one test pair.
    fn write_pair(
        &self,
        stem: &str,
        (w, h): (usize, usize),
        img: &[[f32; 3]],
        flip_map: &[f32],
        mask: &[bool],
    ) -> Result<()> {
        write_exr_rgb(&self.renders.join(format!("{stem}.exr")), w, h, img)?;
        write_png_srgb_atomic(&self.renders.join(format!("{stem}.png")), w as u32, h as u32, img)?;
        let map = metrics::colormap::error_map_rgb8(flip_map, Some(mask));
        write_png_rgb8(&self.flips.join(format!("{stem}.png")), w, h, &map)
    }
}

/// Per view: the sum of pi f_d and the sample count per pixel, for the albedo maps.
#[derive(Default)]
struct AlbedoMaps(HashMap<usize, (Vec<[f32; 3]>, Vec<u32>)>);

impl AlbedoMaps {
    fn add(&mut self, view: usize, pixels: usize, values: impl Iterator<Item = (u32, [f32; 3])>) {
        let (sum, count) =
            self.0.entry(view).or_insert_with(|| (vec![[0.0; 3]; pixels], vec![0; pixels]));
        for (p, fd) in values {
            let p = p as usize;
            for c in 0..3 {
                sum[p][c] += std::f32::consts::PI * fd[c];
            }
            count[p] += 1;
        }
    }

    fn write(self, dir: &Path, (w, h): (usize, usize)) -> Result<()> {
        let mut views: Vec<_> = self.0.into_iter().collect();
        views.sort_by_key(|(vi, _)| *vi);
        for (vi, (sum, count)) in views {
            let mean: Vec<[f32; 3]> = sum
                .iter()
                .zip(&count)
                .map(|(s, &n)| if n > 0 { s.map(|x| x / n as f32) } else { [0.0; 3] })
                .collect();
            write_png_srgb_atomic(
                &dir.join(format!("view{vi:03}.png")),
                w as u32,
                h as u32,
                &mean,
            )?;
        }
        Ok(())
    }
}
