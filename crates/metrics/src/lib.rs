//! Metrics of the comparison (spec section 7): PSNR, DSSIM, LPIPS and HDR-FLIP on renders,
//! cube-root RMSE in BRDF space, energy conservation and reciprocity analyses.
//!
//! Images are [`Image`]s (width x height RGB `f32`, row-major, interleaved) with an optional
//! object mask (`&[bool]`, one entry a pixel). PSNR, SSIM and LPIPS take display values in
//! [0, 1] (the `*_linear` helpers convert linear renders with the clamped sRGB OETF,
//! [`srgb::to_srgb_clamped`]); HDR-FLIP takes linear HDR values. With a mask, PSNR and SSIM
//! average over masked pixels and HDR-FLIP takes its exposure range and mean over them; without
//! one they equal the standard definitions (see [`ssim`](mod@ssim) and [`flip`](mod@flip) for the parity statements).
//!
//! Results are raw values; [`aggregate`] averages them per object then over objects and holds
//! the tables' scaling convention ([`aggregate::TableScale`]).
//!
//! The BRDF analyses ([`energy`], [`reciprocity`]) take any model through the small
//! [`brdf_analytic::SurfaceBrdf`] interface (batched over surface points, local frame), which
//! every analytic BRDF is and `brdf-neural` implements for its models.

pub mod aggregate;
pub mod colormap;
pub mod energy;
mod error;
pub mod flip;
mod image;
pub mod lpips;
pub mod psnr;
pub mod reciprocity;
pub mod rmse;
pub mod srgb;
pub mod ssim;
#[doc(hidden)]
pub mod testimg;

pub use error::{Error, Result};
pub use flip::{
    FlipConfig, FlipExposures, FlipImage, FlipResult, hdr_flip, hdr_flip_prepared, hdr_flip_with,
};
pub use image::{Image, check_pair};
pub use psnr::{psnr, psnr_linear};
pub use ssim::{SsimConfig, dssim, dssim_linear, ssim, ssim_with};
