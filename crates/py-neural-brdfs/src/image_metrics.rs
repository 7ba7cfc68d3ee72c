//! The image and BRDF metrics of `metrics` on numpy arrays, each returning `(value, settings)`:
//! the settings are exactly what the computation used (defaults filled in, exposures that
//! HDR-FLIP derived from the reference, counts of dropped samples), so a number can always be
//! reported with its conditions.
//!
//! Images are `(H, W, 3)` float32 RGB (display values in [0, 1] for PSNR and SSIM in the
//! `display` space; linear radiance for HDR-FLIP and the `linear` space, where the clamped
//! sRGB OETF is applied first); masks `(H, W)` bool.

use crate::arrays::{flat, rows, same_len};
use metrics::rmse::{CubeRootRmse, RmseConfig};
use metrics::{FlipConfig, Image, SsimConfig};
use numpy::ndarray::Array2;
use numpy::{
    IntoPyArray, PyArray2, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Registers the metric functions on the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("FLIP_DEFAULT_PPD", metrics::flip::DEFAULT_PPD)?;
    m.add_function(wrap_pyfunction!(psnr, m)?)?;
    m.add_function(wrap_pyfunction!(ssim, m)?)?;
    m.add_function(wrap_pyfunction!(hdr_flip, m)?)?;
    m.add_function(wrap_pyfunction!(cube_root_rmse, m)?)?;
    Ok(())
}

fn metric_error(e: metrics::Error) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// An `(H, W, 3)` array as an [`Image`].
fn image(a: &PyReadonlyArray3<'_, f32>, name: &str) -> PyResult<Image> {
    let s = a.shape();
    if s[2] != 3 {
        return Err(PyValueError::new_err(format!(
            "{name}: expected an (H, W, 3) RGB image, got ({}, {}, {})",
            s[0], s[1], s[2]
        )));
    }
    let data = a
        .as_slice()
        .map_err(|_| PyValueError::new_err(format!("{name}: not C-contiguous")))?
        .to_vec();
    Image::new(s[1], s[0], data).map_err(|e| PyValueError::new_err(format!("{name}: {e}")))
}

fn mask(m: &Option<PyReadonlyArray2<'_, bool>>, like: &Image) -> PyResult<Option<Vec<bool>>> {
    let Some(m) = m else { return Ok(None) };
    let s = m.shape();
    if (s[0], s[1]) != (like.height(), like.width()) {
        return Err(PyValueError::new_err(format!(
            "mask: shape ({}, {}) but the images are ({}, {})",
            s[0],
            s[1],
            like.height(),
            like.width()
        )));
    }
    Ok(Some(m.as_slice().map_err(|_| PyValueError::new_err("mask: not C-contiguous"))?.to_vec()))
}

/// The images in the space a metric works in.
fn in_space(space: &str, test: Image, reference: Image) -> PyResult<(Image, Image)> {
    match space {
        "display" => Ok((test, reference)),
        "linear" => {
            Ok((metrics::srgb::to_srgb_clamped(&test), metrics::srgb::to_srgb_clamped(&reference)))
        }
        other => Err(PyValueError::new_err(format!(
            "space must be 'display' (values in [0, 1]) or 'linear' (clamped sRGB OETF first), \
             got {other:?}"
        ))),
    }
}

fn masked_pixels(mask: &Option<Vec<bool>>, img: &Image) -> usize {
    mask.as_ref().map_or(img.width() * img.height(), |m| m.iter().filter(|&&b| b).count())
}

/// PSNR in dB with data range 1 (`+inf` for identical images).
#[pyfunction]
#[pyo3(signature = (test, reference, mask=None, space="display"))]
fn psnr<'py>(
    py: Python<'py>,
    test: PyReadonlyArray3<'py, f32>,
    reference: PyReadonlyArray3<'py, f32>,
    mask: Option<PyReadonlyArray2<'py, bool>>,
    space: &str,
) -> PyResult<(f64, Bound<'py, PyDict>)> {
    let (t, r) = (image(&test, "test")?, image(&reference, "reference")?);
    let m = self::mask(&mask, &r)?;
    let (t, r) = in_space(space, t, r)?;
    let value = py.detach(|| metrics::psnr(&t, &r, m.as_deref())).map_err(metric_error)?;
    let s = PyDict::new(py);
    s.set_item("metric", "psnr")?;
    s.set_item("space", space)?;
    s.set_item("data_range", 1.0)?;
    s.set_item("channels", "RGB, mean squared error over channels")?;
    s.set_item("pixels", masked_pixels(&m, &r))?;
    Ok((value, s))
}

/// SSIM (Gaussian window, scikit-image's conventions; see `metrics::ssim`).
#[pyfunction]
#[pyo3(signature = (test, reference, mask=None, space="display", sigma=1.5, truncate=3.5,
    k1=0.01, k2=0.03, data_range=1.0))]
#[allow(clippy::too_many_arguments)]
fn ssim<'py>(
    py: Python<'py>,
    test: PyReadonlyArray3<'py, f32>,
    reference: PyReadonlyArray3<'py, f32>,
    mask: Option<PyReadonlyArray2<'py, bool>>,
    space: &str,
    sigma: f64,
    truncate: f64,
    k1: f64,
    k2: f64,
    data_range: f64,
) -> PyResult<(f64, Bound<'py, PyDict>)> {
    let (t, r) = (image(&test, "test")?, image(&reference, "reference")?);
    let m = self::mask(&mask, &r)?;
    let (t, r) = in_space(space, t, r)?;
    let cfg = SsimConfig { sigma, truncate, k1, k2, data_range };
    let value =
        py.detach(|| metrics::ssim_with(&t, &r, m.as_deref(), &cfg)).map_err(metric_error)?;
    let s = PyDict::new(py);
    s.set_item("metric", "ssim")?;
    s.set_item("space", space)?;
    s.set_item("sigma", sigma)?;
    s.set_item("truncate", truncate)?;
    s.set_item("window", 2 * (truncate * sigma + 0.5) as usize + 1)?;
    s.set_item("k1", k1)?;
    s.set_item("k2", k2)?;
    s.set_item("data_range", data_range)?;
    s.set_item("border", "reflect; the map is cropped by the window radius")?;
    s.set_item("pixels", masked_pixels(&m, &r))?;
    Ok((value, s))
}

/// HDR-FLIP (Andersson et al. 2021) on linear images: `(mean, settings, error map (H, W))`.
#[pyfunction]
#[pyo3(signature = (test, reference, mask=None, pixels_per_degree=metrics::flip::DEFAULT_PPD,
    start_exposure=None, stop_exposure=None))]
#[allow(clippy::type_complexity)]
fn hdr_flip<'py>(
    py: Python<'py>,
    test: PyReadonlyArray3<'py, f32>,
    reference: PyReadonlyArray3<'py, f32>,
    mask: Option<PyReadonlyArray2<'py, bool>>,
    pixels_per_degree: f64,
    start_exposure: Option<f64>,
    stop_exposure: Option<f64>,
) -> PyResult<(f64, Bound<'py, PyDict>, Bound<'py, PyArray2<f32>>)> {
    let (t, r) = (image(&test, "test")?, image(&reference, "reference")?);
    let m = self::mask(&mask, &r)?;
    let cfg = FlipConfig { pixels_per_degree, start_exposure, stop_exposure };
    let res =
        py.detach(|| metrics::hdr_flip_with(&t, &r, m.as_deref(), &cfg)).map_err(metric_error)?;
    let s = PyDict::new(py);
    s.set_item("metric", "hdr-flip")?;
    s.set_item("pixels_per_degree", pixels_per_degree)?;
    s.set_item("start_exposure", res.start_exposure)?;
    s.set_item("stop_exposure", res.stop_exposure)?;
    s.set_item("exposures", res.exposures)?;
    s.set_item("exposures_from", if start_exposure.is_some() { "given" } else { "reference" })?;
    s.set_item("pixels", masked_pixels(&m, &r))?;
    let map = Array2::from_shape_vec((r.height(), r.width()), res.map)
        .map_err(|e| PyValueError::new_err(format!("FLIP map: {e}")))?
        .into_pyarray(py);
    Ok((res.mean, s, map))
}

/// Cube-root RMSE of BRDF values (Lavoue et al. 2021): `pred`, `gt` `(n, 3)` float32, the
/// cosines of theta_l and theta_v `(n,)`, optional saturation flags.
#[pyfunction]
#[pyo3(signature = (pred, gt, cos_theta_l, cos_theta_v, saturated=None, max_angle_deg=80.0))]
fn cube_root_rmse<'py>(
    py: Python<'py>,
    pred: PyReadonlyArray2<'py, f32>,
    gt: PyReadonlyArray2<'py, f32>,
    cos_theta_l: PyReadonlyArray1<'py, f32>,
    cos_theta_v: PyReadonlyArray1<'py, f32>,
    saturated: Option<PyReadonlyArray1<'py, bool>>,
    max_angle_deg: f64,
) -> PyResult<(f64, Bound<'py, PyDict>)> {
    let (p, g) = (rows::<f32, 3>(&pred, "pred")?, rows::<f32, 3>(&gt, "gt")?);
    let (cl, cv) = (flat(&cos_theta_l, "cos_theta_l")?, flat(&cos_theta_v, "cos_theta_v")?);
    let sat = saturated.as_ref().map(|s| flat(s, "saturated")).transpose()?;
    let mut lens = vec![
        ("pred", p.len() / 3),
        ("gt", g.len() / 3),
        ("cos_theta_l", cl.len()),
        ("cos_theta_v", cv.len()),
    ];
    if let Some(s) = sat {
        lens.push(("saturated", s.len()));
    }
    let n = same_len(&lens)?;
    let mut acc = CubeRootRmse::new(RmseConfig { max_angle_deg });
    for i in 0..n {
        let row = |a: &[f32]| [a[3 * i], a[3 * i + 1], a[3 * i + 2]];
        acc.push(row(p), row(g), cl[i], cv[i], sat.is_some_and(|s| s[i]));
    }
    let value = acc.value().map_err(metric_error)?;
    let s = PyDict::new(py);
    s.set_item("metric", "cube-root rmse")?;
    s.set_item("max_angle_deg", max_angle_deg)?;
    s.set_item("kept", acc.kept)?;
    s.set_item("grazing", acc.grazing)?;
    s.set_item("saturated", acc.saturated)?;
    s.set_item("invalid_gt", acc.invalid)?;
    s.set_item("scale", "raw (the paper's tables multiply by 100)")?;
    Ok((value, s))
}
