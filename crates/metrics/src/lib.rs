//! Metrics of the comparison (spec section 7): PSNR, DSSIM, LPIPS and HDR-FLIP on renders,
//! cube-root RMSE in BRDF space, energy conservation and reciprocity analyses.
//!
//! Not built yet: see the training and evaluation issue.
