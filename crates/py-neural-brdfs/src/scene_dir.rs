//! A scene directory (`scene::SceneDataset`) as arrays: observed and clean images, per-pair
//! flags, object masks, cameras, lights, the mesh and the sample records of a split.
//!
//! Opening verifies the manifest's checksum and every file's hash, as `fit` and `eval` do
//! (and may write the scene's ray-cast cache under `<scene>/geometry/`). Images are `(H, W, 3)`
//! float32 linear radiance; flags `(H, W)` uint8 with the bits of `scene::flag`; cameras in
//! OpenCV convention (`x_cam = R x_world + t`, K in pixels); light directions are unit world
//! vectors towards the light.

use crate::arrays::{to_array2, to_array2_2};
use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{IntoPyArray, PyArray2, PyArray3};
use pyo3::exceptions::{PyIndexError, PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use scene::{SceneDataset, Split};
use std::path::PathBuf;

/// A scene directory, opened and verified.
#[pyclass(frozen, module = "neural_brdfs._native")]
pub struct Scene {
    dataset: SceneDataset,
}

/// A scene error as a Python exception: I/O faults as `OSError`, the rest as `ValueError`.
pub fn scene_error(e: scene::Error) -> PyErr {
    match e {
        scene::Error::Io { .. } => PyOSError::new_err(e.to_string()),
        _ => PyValueError::new_err(e.to_string()),
    }
}

/// `"train"` or `"test"`.
pub fn parse_split(split: &str) -> PyResult<Split> {
    match split {
        "train" => Ok(Split::Train),
        "test" => Ok(Split::Test),
        other => {
            Err(PyValueError::new_err(format!("split must be 'train' or 'test', got {other:?}")))
        }
    }
}

fn split_name(s: Split) -> &'static str {
    match s {
        Split::Train => "train",
        Split::Test => "test",
    }
}

fn rows3<'py>(py: Python<'py>, m: &[[f32; 3]; 3]) -> Bound<'py, PyArray2<f32>> {
    to_array2(py, m)
}

impl Scene {
    /// The dataset (for the fitted-run bindings).
    pub fn dataset(&self) -> &SceneDataset {
        &self.dataset
    }

    fn size(&self) -> (usize, usize) {
        let s = &self.dataset.manifest.config.settings;
        (s.height as usize, s.width as usize)
    }

    fn view_info(&self, view: usize) -> PyResult<&scene::manifest::ViewInfo> {
        let views = &self.dataset.manifest.views;
        views.get(view).ok_or_else(|| {
            PyIndexError::new_err(format!(
                "view {view} out of range: the scene has {} views",
                views.len()
            ))
        })
    }

    fn check_pair(&self, view: usize, light: usize) -> PyResult<()> {
        let v = self.view_info(view)?;
        if light >= v.lights.len() {
            return Err(PyIndexError::new_err(format!(
                "light {light} out of range: view {view} has {} lights",
                v.lights.len()
            )));
        }
        Ok(())
    }

    fn rgb_image<'py>(&self, py: Python<'py>, px: Vec<[f32; 3]>) -> Bound<'py, PyArray3<f32>> {
        let (h, w) = self.size();
        let flat: Vec<f32> = px.into_iter().flatten().collect();
        Array3::from_shape_vec((h, w, 3), flat).expect("scene images are H x W").into_pyarray(py)
    }
}

#[pymethods]
impl Scene {
    /// Opens and verifies the scene directory `path`.
    #[new]
    fn new(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let dataset = py.detach(|| SceneDataset::open(&path)).map_err(scene_error)?;
        Ok(Self { dataset })
    }

    /// The scene directory.
    #[getter]
    fn path(&self) -> PathBuf {
        self.dataset.dir.clone()
    }

    /// The scene's label.
    #[getter]
    fn label(&self) -> String {
        self.dataset.manifest.label.clone()
    }

    /// Image width in pixels.
    #[getter]
    fn width(&self) -> usize {
        self.size().1
    }

    /// Image height in pixels.
    #[getter]
    fn height(&self) -> usize {
        self.size().0
    }

    /// Number of views.
    #[getter]
    fn view_count(&self) -> usize {
        self.dataset.manifest.views.len()
    }

    /// The scene's configuration (material, settings) as JSON text.
    fn config_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.dataset.manifest.config)
            .map_err(|e| PyValueError::new_err(format!("scene configuration: {e}")))
    }

    /// Camera of a view: `{"K": (3, 3), "R": (3, 3), "t": (3,), "width", "height", "split"}`.
    fn camera<'py>(&self, py: Python<'py>, view: usize) -> PyResult<Bound<'py, PyDict>> {
        let v = self.view_info(view)?;
        let d = PyDict::new(py);
        d.set_item("K", rows3(py, &v.k))?;
        d.set_item("R", rows3(py, &v.r))?;
        d.set_item("t", Array1::from_vec(v.t.to_vec()).into_pyarray(py))?;
        d.set_item("width", self.width())?;
        d.set_item("height", self.height())?;
        d.set_item("split", split_name(v.split))?;
        Ok(d)
    }

    /// Lights of a view: `{"direction": (L, 3), "intensity": (L, 3), "position": (L, 3),
    /// "split": [str]}`; `position` is NaN for a directional light, and a point light's
    /// `intensity` is its radiant intensity (E = I / d^2; the samples' `irradiance` has it
    /// applied).
    fn lights<'py>(&self, py: Python<'py>, view: usize) -> PyResult<Bound<'py, PyDict>> {
        let v = self.view_info(view)?;
        let dirs: Vec<[f32; 3]> = v.lights.iter().map(|l| l.direction).collect();
        let int: Vec<[f32; 3]> = v.lights.iter().map(|l| l.intensity).collect();
        let pos: Vec<[f32; 3]> =
            v.lights.iter().map(|l| l.position.unwrap_or([f32::NAN; 3])).collect();
        let split: Vec<&str> = v.lights.iter().map(|l| split_name(l.split)).collect();
        let d = PyDict::new(py);
        d.set_item("direction", to_array2(py, &dirs))?;
        d.set_item("intensity", to_array2(py, &int))?;
        d.set_item("position", to_array2(py, &pos))?;
        d.set_item("split", split)?;
        Ok(d)
    }

    /// The observed (noisy, possibly saturated) image of a (view, light) pair.
    fn image<'py>(
        &self,
        py: Python<'py>,
        view: usize,
        light: usize,
    ) -> PyResult<Bound<'py, PyArray3<f32>>> {
        self.check_pair(view, light)?;
        let px = py.detach(|| self.dataset.observed_image(view, light)).map_err(scene_error)?;
        Ok(self.rgb_image(py, px))
    }

    /// The noise-free render of a test pair, or `None` where the scene has none.
    fn clean_image<'py>(
        &self,
        py: Python<'py>,
        view: usize,
        light: usize,
    ) -> PyResult<Option<Bound<'py, PyArray3<f32>>>> {
        self.check_pair(view, light)?;
        let px = py.detach(|| self.dataset.clean_image(view, light)).map_err(scene_error)?;
        Ok(px.map(|px| self.rgb_image(py, px)))
    }

    /// The per-pixel flags of a pair (`(H, W)` uint8, bits of `scene::flag`).
    fn flags<'py>(
        &self,
        py: Python<'py>,
        view: usize,
        light: usize,
    ) -> PyResult<Bound<'py, PyArray2<u8>>> {
        self.check_pair(view, light)?;
        let f = py.detach(|| self.dataset.flags_image(view, light)).map_err(scene_error)?;
        let (h, w) = self.size();
        Array2::from_shape_vec((h, w), f)
            .map(|a| a.into_pyarray(py))
            .map_err(|e| PyValueError::new_err(format!("flags of view {view}, light {light}: {e}")))
    }

    /// The object mask of a view (`(H, W)` bool): the pixels whose camera ray hits the mesh.
    fn mask<'py>(&self, py: Python<'py>, view: usize) -> PyResult<Bound<'py, PyArray2<bool>>> {
        let Some(g) = self.dataset.geometry.views.get(view) else {
            return Err(PyIndexError::new_err(format!(
                "view {view} out of range: the scene has {} views",
                self.view_count()
            )));
        };
        let (h, w) = self.size();
        let mut m = vec![false; h * w];
        for &p in &g.pixels {
            if let Some(b) = m.get_mut(p as usize) {
                *b = true;
            }
        }
        Ok(Array2::from_shape_vec((h, w), m).expect("H x W").into_pyarray(py))
    }

    /// The mesh: `(positions (V, 3) float32, triangles (T, 3) uint32)`.
    fn mesh<'py>(&self, py: Python<'py>) -> (Bound<'py, PyArray2<f32>>, Bound<'py, PyArray2<u32>>) {
        let p: Vec<[f32; 3]> = self.dataset.mesh.positions.iter().map(|v| v.to_array()).collect();
        (to_array2(py, &p), to_array2(py, &self.dataset.mesh.triangles))
    }

    /// The lit sample records of a split as a dict of arrays (struct of arrays; index `i`
    /// across all of them is one (pixel, light) sample; directions in world space).
    fn samples<'py>(&self, py: Python<'py>, split: &str) -> PyResult<Bound<'py, PyDict>> {
        let split = parse_split(split)?;
        let s = py.detach(|| self.dataset.samples(split)).map_err(scene_error)?;
        samples_dict(py, &s)
    }
}

/// A [`scene::SampleSet`] as a dict of arrays.
pub fn samples_dict<'py>(py: Python<'py>, s: &scene::SampleSet) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("view", s.view.clone().into_pyarray(py))?;
    d.set_item("light", s.light.clone().into_pyarray(py))?;
    d.set_item("pixel", s.pixel.clone().into_pyarray(py))?;
    d.set_item("triangle", s.triangle.clone().into_pyarray(py))?;
    d.set_item("barycentric", to_array2_2(py, &s.barycentric))?;
    for (name, rows) in [
        ("position", &s.position),
        ("normal", &s.normal),
        ("l", &s.l),
        ("v", &s.v),
        ("irradiance", &s.irradiance),
        ("observed", &s.observed),
        ("gt_brdf", &s.gt_brdf),
    ] {
        d.set_item(name, to_array2(py, rows))?;
    }
    d.set_item("gt_valid", s.gt_valid.clone().into_pyarray(py))?;
    d.set_item("saturated", s.saturated.clone().into_pyarray(py))?;
    Ok(d)
}
