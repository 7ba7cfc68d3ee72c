//! The exact settings behind every score of `metrics.json`, so that a number can be compared
//! with another paper's without guessing: colour space, range, mask, window or filter, FLIP's
//! pixels per degree and exposures, the LPIPS network and its input, the RMSE's angle cut, and
//! how many images and pixels entered. Values come from the metric implementations' own
//! defaults, the ones `eval` calls them with.
//!
//! Two protocols score every run (docs/reproduce.md, "Two protocols"):
//!
//! * **ours** ([`MetricSettings`], `test.settings`; the scores at the top of `test`): the
//!   object mask, against the observed (noisy) test images, beside the noise ceiling;
//! * **the paper's** ([`PaperSettings`], `test.paper.settings`; the scores in `test.paper`):
//!   the whole frame, against the noise-free renders, as the paper's Table 1 scores.

use serde::{Deserialize, Serialize};

/// Settings of the image metrics and the BRDF-space RMSE.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MetricSettings {
    /// Test images scored.
    pub images: usize,
    /// Pixels scored over all test images (the object masks' sizes summed).
    pub pixels: usize,
    /// What every image score is computed on.
    pub image_input: String,
    /// PSNR.
    pub psnr: String,
    /// DSSIM and its SSIM window.
    pub dssim: String,
    /// HDR-FLIP.
    pub flip: String,
    /// LPIPS.
    pub lpips: String,
    /// Cube-root RMSE of the BRDF.
    pub rmse_cbrt: String,
    /// How the per-image scores become the run's.
    pub aggregation: String,
}

/// The settings of the paper's protocol.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PaperSettings {
    /// The protocol's name and one line on it.
    pub protocol: String,
    /// Test images scored.
    pub images: usize,
    /// Pixels scored over all test images (whole frames).
    pub pixels: usize,
    /// What every image score is computed on.
    pub image_input: String,
    /// PSNR.
    pub psnr: String,
    /// DSSIM.
    pub dssim: String,
    /// HDR-FLIP.
    pub flip: String,
    /// LPIPS.
    pub lpips: String,
    /// How the per-image scores become the run's and the table's.
    pub aggregation: String,
}

impl PaperSettings {
    /// The settings for `images` test images of `pixels` frame pixels in all; `noise_free`
    /// says whether the scene has noise-free renders (semi-synthetic) or not (a capture).
    pub fn current(images: usize, pixels: usize, noise_free: bool) -> Self {
        let s = metrics::SsimConfig::default();
        let flip = metrics::FlipConfig::default();
        let reference = if noise_free {
            "the noise-free test renders (the ground-truth BRDF's render, without sensor noise; \
             0 outside the object, like every render)"
        } else {
            "the observed test images with the pixels outside the object mask set to 0 (a \
             capture has no noise-free image; every render is 0 there)"
        };
        PaperSettings {
            protocol: "paper: the whole frame against the noise-free renders, as the paper's \
                       Table 1"
                .into(),
            images,
            pixels,
            image_input: format!(
                "linear RGB renders (f_r times E cos, clipped like the observations) against \
                 {reference}; every pixel of the frame is scored, background included"
            ),
            psnr: "10 log10(1 / MSE) on sRGB-encoded values clamped to [0, 1] (data range 1), \
                   MSE over every pixel of the frame and 3 channels"
                .into(),
            dssim: format!(
                "(1 - SSIM) / 2 on sRGB clamped to [0, 1], SSIM as skimage (channel-wise, \
                 Gaussian window sigma {} truncated at {} sigma, K1 {}, K2 {}, data range {}, \
                 population covariance), mean of the SSIM map over the whole frame away from \
                 the image border",
                s.sigma, s.truncate, s.k1, s.k2, s.data_range
            ),
            flip: format!(
                "HDR-FLIP of linear values, {:.2} pixels per degree, mean of the map over \
                 every pixel of the frame; start and stop exposures from the object's pixels \
                 of the observed image (a frame whose background is black has a zero median \
                 luminance, hence no exposure range of its own)",
                flip.pixels_per_degree
            ),
            lpips: "LPIPS v0.1, AlexNet with the linear layers, on the whole sRGB frame \
                    clamped to [0, 1] (absent without the weights file)"
                .into(),
            aggregation: "mean over the test images of the per-image score; tables average \
                          per object, then over objects"
                .into(),
        }
    }
}

impl MetricSettings {
    /// The settings `eval` scores with, for `images` test images of `pixels` masked pixels in
    /// all; `clip` is the saturation level renders are clipped at (semi-synthetic scenes).
    pub fn current(images: usize, pixels: usize, clip: Option<f32>) -> Self {
        let s = metrics::SsimConfig::default();
        let flip = metrics::FlipConfig::default();
        let rmse = metrics::rmse::RmseConfig::default();
        let clip = clip.map_or("not clipped (captured scene)".to_string(), |c| {
            format!("clipped at the scene's saturation level {c}")
        });
        MetricSettings {
            images,
            pixels,
            image_input: format!(
                "ours: linear RGB renders (f_r times E cos, {clip}) against the observed test \
                 images; only the object's pixels of the test view (its foreground mask) are \
                 scored"
            ),
            psnr: "10 log10(1 / MSE) on sRGB-encoded values (IEC 61966-2-1) clamped to [0, 1] \
                   (peak 1), MSE over the masked pixels and 3 channels"
                .into(),
            dssim: format!(
                "(1 - SSIM) / 2 on sRGB clamped to [0, 1], SSIM as skimage (channel-wise, \
                 Gaussian window sigma {} truncated at {} sigma, K1 {}, K2 {}, data range {}, \
                 population covariance), mean of the SSIM map over the masked pixels away from \
                 the image border (skimage's crop of the window radius)",
                s.sigma, s.truncate, s.k1, s.k2, s.data_range
            ),
            flip: format!(
                "HDR-FLIP (Andersson et al. 2021) of linear values, {:.2} pixels per degree; \
                 start and stop exposures derived from the observed image of each test pair \
                 and shared by the model, noise-free and ceiling scores; mean of the map over \
                 the masked pixels",
                flip.pixels_per_degree
            ),
            lpips:
                "LPIPS v0.1, AlexNet backbone with the linear layers, on sRGB clamped to [0, 1] \
                    mapped to [-1, 1] then by the network's shift and scale, pixels outside the \
                    mask set to 0, the whole image as input (absent without the weights file)"
                    .into(),
            rmse_cbrt: format!(
                "RMSE of the cube roots of f_r (1/sr, per RGB channel) against the ground-truth \
                 BRDF at the test samples, samples with theta_l or theta_v above {} degrees \
                 dropped (semi-synthetic scenes only)",
                rmse.max_angle_deg
            ),
            aggregation: "each image metric is the mean over the test images of the per-image \
                          score"
                .into(),
        }
    }
}
