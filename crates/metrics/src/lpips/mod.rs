//! LPIPS (Zhang et al. 2018), AlexNet backbone with the v0.1 linear layers, on burn
//! (spec section 7; richzhang/PerceptualSimilarity `lpips/lpips.py`).
//!
//! d(x, y) = sum over the five ReLU outputs of AlexNet's conv layers of
//! mean over pixels of sum_c w_c (n_x - n_y)_c^2, where n is the feature vector of a pixel divided
//! by (its L2 norm + 1e-10) and w the non-negative 1x1 `lin` weights. Inputs are sRGB in [0, 1],
//! mapped to [-1, 1] and then by (x - shift) / scale with shift = (-0.030, -0.088, -0.188),
//! scale = (0.458, 0.448, 0.450). AlexNet: conv1 11x11 stride 4 pad 2 (64), max-pool 3/2,
//! conv2 5x5 pad 2 (192), max-pool 3/2, conv3, conv4, conv5 3x3 pad 1 (384, 256, 256).
//!
//! The weights are not shipped (and these machines cannot download them): [`weights`] documents
//! the file, its default location and how to make it; without it [`lpips_score`] returns
//! [`Score::Unavailable`](crate::aggregate::Score::Unavailable)`("weights missing")`, which tables print as "n/a (weights missing)".

#[cfg(feature = "lpips")]
mod net;
pub mod weights;

#[cfg(feature = "lpips")]
pub use net::Lpips;

#[cfg(feature = "lpips")]
/// The LPIPS of two sRGB images in [0, 1] with the weights at `path`, or
/// [`Score::Unavailable`](crate::aggregate::Score::Unavailable) ("weights missing") when the
/// file does not exist.
pub fn lpips_score(
    test: &crate::image::Image,
    reference: &crate::image::Image,
    path: &std::path::Path,
) -> crate::error::Result<crate::aggregate::Score> {
    use crate::aggregate::Score;
    if !path.exists() {
        return Ok(Score::Unavailable("weights missing".into()));
    }
    let net = Lpips::load(path, &burn::tensor::Device::default())?;
    Ok(Score::Value(net.distance(test, reference)?))
}
