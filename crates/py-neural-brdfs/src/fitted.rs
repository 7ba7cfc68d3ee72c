//! A fitted run (`experiments::fitted::FittedRun`): its model evaluated at surface points and
//! directions, and its exports.
//!
//! A surface point is a triangle of the scene's mesh and barycentrics `(b1, b2)` of the hit
//! (`P = (1 - b1 - b2) v0 + b1 v1 + b2 v2`), exactly as the scene's sample records give them:
//! the models read spatial features (LBO eigenfunctions interpolated from the vertices, or the
//! position), not raw coordinates. Directions are local-frame unit vectors (normal on +z), or
//! world-space ones with the shading normal given, rotated with the frame training used.

use crate::arrays::{as_vec3, flat, rows, same_len, to_array2};
use crate::scene_dir::samples_dict;
use angles::Frame;
use brdf_neural::fitted::{PointRows, Records, predict};
use experiments::data::spatial_features;
use experiments::export::SurfacePoint;
use experiments::fitted::FittedRun;
use numpy::{PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::{PyIndexError, PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use scene::SampleSet;
use std::path::{Path, PathBuf};

/// An experiments error as a Python exception: I/O faults as `OSError`, the rest as
/// `ValueError`.
fn run_error(e: experiments::Error) -> PyErr {
    match e {
        experiments::Error::Run(run_format::Error::Io { .. }) => PyOSError::new_err(e.to_string()),
        _ => PyValueError::new_err(e.to_string()),
    }
}

/// A finished run with its model loaded and its scene opened.
#[pyclass(module = "neural_brdfs._native", unsendable)]
pub struct Run {
    /// Boxed: the model holds 64-byte aligned data, and Python allocates its objects with a
    /// smaller alignment.
    run: Box<FittedRun>,
    dir: PathBuf,
    scene: Option<PathBuf>,
    cache: Option<PathBuf>,
}

#[pymethods]
impl Run {
    /// Opens the run directory `path`; `scene` overrides its configured scene directory and
    /// `cache` its eigenpair cache.
    #[new]
    #[pyo3(signature = (path, scene=None, cache=None))]
    fn new(path: PathBuf, scene: Option<PathBuf>, cache: Option<PathBuf>) -> PyResult<Self> {
        let run = FittedRun::open(&path, scene.as_deref(), cache.as_deref()).map_err(run_error)?;
        Ok(Self { run: Box::new(run), dir: path, scene, cache })
    }

    /// The run directory.
    #[getter]
    fn path(&self) -> PathBuf {
        self.dir.clone()
    }

    /// The model kind's configuration name (`single_mlp`, `disney`, ...).
    #[getter]
    fn kind(&self) -> &'static str {
        self.run.config.model.kind.config_name()
    }

    /// The model kind's name in the paper.
    #[getter]
    fn paper_name(&self) -> &'static str {
        self.run.config.model.kind.paper_name()
    }

    /// The scene directory the run was opened with.
    #[getter]
    fn scene_path(&self) -> PathBuf {
        self.run.dataset.dir.clone()
    }

    /// The run's configuration as TOML text.
    fn config_toml(&self) -> PyResult<String> {
        self.run.config.to_toml().map_err(|e| run_error(e.into()))
    }

    /// The lit sample records of the run's scene for a split (as `Scene.samples`).
    fn samples<'py>(&self, py: Python<'py>, split: &str) -> PyResult<Bound<'py, PyDict>> {
        let split = crate::scene_dir::parse_split(split)?;
        let s = self.run.dataset.samples(split).map_err(crate::scene_dir::scene_error)?;
        samples_dict(py, &s)
    }

    /// f_r at surface points (`triangle` `(n,)`, `barycentric` `(n, 2)`) for directions `l`,
    /// `v` `(n, 3)`: local-frame unit vectors, or world-space ones when `normal` `(n, 3)`
    /// gives the shading normals. Returns `(n, 3)` float32 RGB in 1/sr; with `parts`, a dict
    /// `{"f", "diffuse", "diffuse_raw", "specular"}` (the parts of additive models, else
    /// only `f`).
    #[pyo3(signature = (triangle, barycentric, l, v, normal=None, parts=false))]
    #[allow(clippy::too_many_arguments)]
    fn eval<'py>(
        &self,
        py: Python<'py>,
        triangle: PyReadonlyArray1<'py, u32>,
        barycentric: PyReadonlyArray2<'py, f32>,
        l: PyReadonlyArray2<'py, f32>,
        v: PyReadonlyArray2<'py, f32>,
        normal: Option<PyReadonlyArray2<'py, f32>>,
        parts: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let tri = flat(&triangle, "triangle")?;
        let bary = rows::<f32, 2>(&barycentric, "barycentric")?;
        let (lw, vw) = (as_vec3(rows::<f32, 3>(&l, "l")?), as_vec3(rows::<f32, 3>(&v, "v")?));
        let nw = normal.as_ref().map(|n| rows::<f32, 3>(n, "normal").map(as_vec3)).transpose()?;
        let mut lens = vec![
            ("triangle", tri.len()),
            ("barycentric", bary.len() / 2),
            ("l", lw.len()),
            ("v", vw.len()),
        ];
        if let Some(n) = &nw {
            lens.push(("normal", n.len()));
        }
        same_len(&lens)?;
        let samples = self.points(tri, bary)?;
        let (l, v) = match &nw {
            None => (lw, vw),
            Some(normals) => {
                let frames: Vec<Frame<f32>> =
                    normals.iter().map(|&n| Frame::from_normal(n)).collect();
                (
                    frames.iter().zip(&lw).map(|(f, &w)| f.to_local(w)).collect(),
                    frames.iter().zip(&vw).map(|(f, &w)| f.to_local(w)).collect(),
                )
            }
        };
        let r = &self.run;
        let spatial = spatial_features(&r.dataset, &samples, &r.config.features, (&r.cache, None))
            .map_err(run_error)?;
        let points = PointRows { spatial: &spatial.table, dim: spatial.dim, point: &spatial.point };
        let records = Records { points, l: &l, v: &v };
        let p = predict(&r.model, &r.config.model, records, &r.device, parts)
            .map_err(|e| run_error(e.into()))?;
        let (f, split_parts) = (p.f, [p.diffuse, p.diffuse_raw, p.specular]);
        if !parts {
            return Ok(to_array2(py, &f).into_any());
        }
        let d = PyDict::new(py);
        d.set_item("f", to_array2(py, &f))?;
        for (name, p) in ["diffuse", "diffuse_raw", "specular"].iter().zip(&split_parts) {
            if let Some(p) = p {
                d.set_item(name, to_array2(py, p))?;
            }
        }
        Ok(d.into_any())
    }

    /// Tabulates the fitted BRDF at one surface point as a MERL binary file at `out`
    /// (`vertex`: a mesh vertex; default the representative one). Returns what was written.
    #[pyo3(signature = (out, vertex=None))]
    fn export_merl<'py>(
        &self,
        py: Python<'py>,
        out: PathBuf,
        vertex: Option<usize>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let point = vertex.map_or(SurfacePoint::Representative, SurfacePoint::Vertex);
        let (dir, scene, cache) = (&self.dir, self.scene_override(), self.cache.as_deref());
        let e = py
            .detach(|| experiments::export::export_merl(dir, &out, point, scene, cache, false))
            .map_err(run_error)?;
        let d = PyDict::new(py);
        d.set_item("path", out)?;
        d.set_item("vertex", e.vertex)?;
        d.set_item("position", e.position)?;
        d.set_item("below_horizon_bins", e.below_horizon)?;
        d.set_item("seconds", e.seconds)?;
        Ok(d)
    }

    /// Writes the model as `model.safetensors` + `model.json` into `out` (what training writes
    /// into the run directory; for runs trained before it did). Returns the two paths.
    fn save_portable(&self, py: Python<'_>, out: PathBuf) -> PyResult<Vec<PathBuf>> {
        let r = &self.run;
        let weights = run_format::RunDir::new(&self.dir).weights();
        let paths = py
            .detach(|| {
                let out = run_format::RunDir::new(&out);
                experiments::portable::write(&out, &weights, &r.config, &r.dataset, &r.cache)
            })
            .map_err(run_error)?;
        Ok(paths.to_vec())
    }

    /// Exports the fitted material and the scene's test views for renderers (`formats`:
    /// `gltf`, `mitsuba`, `pbrt`, comma-separated, or `all`) into `out`. Returns a summary.
    #[pyo3(signature = (out, formats="all"))]
    fn export<'py>(
        &self,
        py: Python<'py>,
        out: PathBuf,
        formats: &str,
    ) -> PyResult<Bound<'py, PyDict>> {
        let formats = experiments::export::Format::parse_list(formats).map_err(run_error)?;
        let (dir, scene, cache) = (&self.dir, self.scene_override(), self.cache.as_deref());
        let s = py
            .detach(|| experiments::export::export(dir, &out, &formats, scene, cache))
            .map_err(run_error)?;
        let d = PyDict::new(py);
        d.set_item("model", s.model)?;
        d.set_item("uniform", s.uniform)?;
        d.set_item("vertices", s.vertices)?;
        d.set_item("test_pairs", s.test_pairs)?;
        d.set_item("files", s.files)?;
        let mean = serde_json::to_string(&s.mean_parameters)
            .map_err(|e| PyValueError::new_err(format!("mean parameters: {e}")))?;
        d.set_item("mean_parameters_json", mean)?;
        Ok(d)
    }
}

impl Run {
    fn scene_override(&self) -> Option<&Path> {
        self.scene.as_deref()
    }

    /// Sample records holding just the surface points (what the spatial features read).
    fn points(&self, tri: &[u32], bary: &[f32]) -> PyResult<SampleSet> {
        let mesh = &self.run.dataset.mesh;
        let mut s = SampleSet::default();
        for (i, (&t, b)) in tri.iter().zip(bary.chunks_exact(2)).enumerate() {
            let Some(&[a, b_, c]) = mesh.triangles.get(t as usize) else {
                return Err(PyIndexError::new_err(format!(
                    "triangle[{i}] = {t} out of range: the mesh has {} triangles",
                    mesh.triangles.len()
                )));
            };
            let (b1, b2) = (b[0], b[1]);
            if !(b1.is_finite() && b2.is_finite()) {
                return Err(PyValueError::new_err(format!(
                    "barycentric[{i}] = ({b1}, {b2}) is not finite"
                )));
            }
            let [pa, pb, pc] = [a, b_, c].map(|k| mesh.positions[k as usize]);
            let p = pa * (1.0 - b1 - b2) + pb * b1 + pc * b2;
            s.pixel.push(i as u32);
            s.triangle.push(t);
            s.barycentric.push([b1, b2]);
            s.position.push(p.to_array());
        }
        Ok(s)
    }
}
