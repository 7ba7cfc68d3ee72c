//! The exact settings behind every score of `metrics.json` (`test.settings`), so that a number
//! can be compared with another paper's without guessing: colour space, range, mask, window or
//! filter, FLIP's pixels per degree and exposures, the LPIPS network and its input, the RMSE's
//! angle cut, and how many images and pixels entered. Values come from the metric
//! implementations' own defaults, the ones `eval` calls them with.

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
                "linear RGB renders (f_r times E cos, {clip}) against the observed test images; \
                 only the object's pixels of the test view (its foreground mask) are scored"
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
