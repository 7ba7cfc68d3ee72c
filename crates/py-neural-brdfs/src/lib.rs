//! Python bindings of the workspace (PyO3; built into the `neural_brdfs` package by maturin):
//! the native half of `neural_brdfs`. The Python half (`python/neural_brdfs/`) shapes arrays,
//! names things and adds the numpy / PyTorch reference modules; this crate only crosses the
//! boundary, with the same conventions as the Rust crates:
//!
//! * [`analytic`]: the analytic BRDFs of `brdf-analytic`, built from keyword parameters and
//!   evaluated, sampled and their pdfs on batches of local-frame directions (f64, rayon, with
//!   the GIL released).
//! * [`image_metrics`]: PSNR, SSIM / DSSIM, HDR-FLIP and cube-root RMSE of `metrics`, each
//!   returned with the exact settings it used.
//! * [`scene_dir`]: a scene directory's images, flags, masks, cameras, lights, mesh and sample
//!   records as arrays.
//! * [`fitted`]: a fitted run, evaluated at surface points and directions, and exported.
//!
//! Arrays cross as C-contiguous `float64` (directions), `float32` (images, records) and
//! integer arrays; the Python wrappers convert what users pass. Every error becomes a Python
//! exception whose message names the file or argument and the fault.

use pyo3::prelude::*;

pub mod analytic;
mod arrays;
pub mod fitted;
pub mod image_metrics;
pub mod scene_dir;

/// The native module `neural_brdfs._native`.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<analytic::AnalyticBrdf>()?;
    m.add_class::<scene_dir::Scene>()?;
    m.add_class::<fitted::Run>()?;
    image_metrics::register(m)?;
    m.add_function(wrap_pyfunction!(fmbrdf_weights_file, m)?)?;
    Ok(())
}

/// FMBRDF's helper-network weights as shipped in `brdf-analytic`
/// (`assets/fmbrdf/fmbrdf_weights.bin`, MIT): for the Mitsuba plugin's FMBRDF kind.
#[pyfunction]
fn fmbrdf_weights_file(py: Python<'_>) -> Bound<'_, pyo3::types::PyBytes> {
    pyo3::types::PyBytes::new(py, brdf_analytic::fmbrdf_weights_file())
}
