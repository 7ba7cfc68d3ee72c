//! The analytic BRDFs of `brdf-analytic` as one Python class, `AnalyticBrdf(kind, **params)`.
//!
//! | kind (aliases) | parameters (range; default) |
//! | :-- | :-- |
//! | `lambert` | `albedo` RGB [0, 1]; 0.5 |
//! | `realistic_phong` (`rp`, `phong`) | `kd`, `ks` RGB [0, 1], kd + ks <= 1; 0.4 / `exponent` [1, 1e6]; 32 |
//! | `torrance_sparrow` (`ts`) | `roughness` [0, 1]; 0.5 / `diffuse` RGB; 0.5 / `f0` RGB; 0.04 |
//! | `disney` | `base_color` RGB / `metallic`, `subsurface`, `specular`, `roughness`, `specular_tint`, `sheen`, `sheen_tint`, `clearcoat`, `clearcoat_gloss` [0, 1] / `gamma_base_color` bool |
//! | `fmbrdf` | `eta` [1.1, 2.5] / `rho` RGB / `k_s` [0, 100] / `alpha` rad / `beta` [0.5, 4] / `kappa` [0, 100] |
//!
//! An RGB parameter is a number (grey) or three. A value out of range is a `ValueError` naming
//! the model, the parameter and its range (the models' `try_new`); an unknown keyword a
//! `TypeError` listing the known ones. Conventions are the crate's: local shading frame with
//! the normal on +z, `l` towards the light, `v` towards the viewer, both unit; `eval` gives
//! f_r in 1/sr without the cosine; `sample(v, u)` draws `l` with weight f cos / pdf; `pdf(v, l)`
//! is per solid angle. Evaluation is f64, parallel (rayon) and releases the GIL.

use crate::arrays::{rows, same_len, to_array1, to_array2};
use brdf_analytic::{
    Brdf, Disney, DisneyParams, Fmbrdf, FmbrdfParams, Lambert, LambertParams, ParamError,
    RealisticPhong, RealisticPhongParams, TorranceSparrow, TorranceSparrowParams,
};
use numpy::{PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;

/// A parameter value as the user sees it.
#[derive(Clone, Copy, Debug)]
enum Value {
    Scalar(f64),
    Rgb([f64; 3]),
    Flag(bool),
}

/// An analytic BRDF with its (clamped, as used) parameters.
#[pyclass(frozen, module = "neural_brdfs._native")]
pub struct AnalyticBrdf {
    model: Box<dyn Brdf<f64>>,
    kind: &'static str,
    params: Vec<(&'static str, Value)>,
}

/// The keyword arguments of one construction: each parameter is taken once; what is left over
/// is an unknown keyword.
struct Kwargs<'py> {
    kind: &'static str,
    left: Option<Bound<'py, PyDict>>,
    known: Vec<&'static str>,
}

impl<'py> Kwargs<'py> {
    fn new(kind: &'static str, given: Option<&Bound<'py, PyDict>>) -> PyResult<Self> {
        let left = given.map(|d| d.copy()).transpose()?;
        Ok(Self { kind, left, known: Vec::new() })
    }

    fn take(&mut self, name: &'static str) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.known.push(name);
        let Some(d) = &self.left else { return Ok(None) };
        let v = d.get_item(name)?;
        if v.is_some() {
            d.del_item(name)?;
        }
        Ok(v)
    }

    fn scalar(&mut self, name: &'static str, default: f64) -> PyResult<f64> {
        let kind = self.kind;
        match self.take(name)? {
            None => Ok(default),
            Some(v) => v.extract::<f64>().map_err(|_| {
                PyTypeError::new_err(format!("{kind}: {name} must be a number, got {v}"))
            }),
        }
    }

    fn rgb(&mut self, name: &'static str, default: [f64; 3]) -> PyResult<[f64; 3]> {
        let kind = self.kind;
        match self.take(name)? {
            None => Ok(default),
            Some(v) => v.extract::<f64>().map(|g| [g; 3]).or_else(|_| {
                v.extract::<[f64; 3]>().map_err(|_| {
                    PyTypeError::new_err(format!(
                        "{kind}: {name} must be a number or three numbers (RGB), got {v}"
                    ))
                })
            }),
        }
    }

    fn flag(&mut self, name: &'static str, default: bool) -> PyResult<bool> {
        let kind = self.kind;
        match self.take(name)? {
            None => Ok(default),
            Some(v) => v.extract::<bool>().map_err(|_| {
                PyTypeError::new_err(format!("{kind}: {name} must be True or False, got {v}"))
            }),
        }
    }

    /// Fails on any keyword that no parameter took.
    fn finish(self) -> PyResult<()> {
        let Some(d) = self.left else { return Ok(()) };
        if let Some((k, _)) = d.iter().next() {
            return Err(PyTypeError::new_err(format!(
                "{}: unknown parameter {k}; the parameters are {}",
                self.kind,
                self.known.join(", ")
            )));
        }
        Ok(())
    }
}

fn param_error(e: ParamError) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// The canonical kind of a name or alias.
fn canonical(kind: &str) -> PyResult<&'static str> {
    Ok(match kind.to_ascii_lowercase().replace('-', "_").as_str() {
        "lambert" => "lambert",
        "realistic_phong" | "rp" | "phong" => "realistic_phong",
        "torrance_sparrow" | "ts" => "torrance_sparrow",
        "disney" => "disney",
        "fmbrdf" => "fmbrdf",
        _ => {
            return Err(PyValueError::new_err(format!(
                "unknown analytic BRDF {kind:?}; the kinds are lambert, realistic_phong (rp), \
                 torrance_sparrow (ts), disney, fmbrdf"
            )));
        }
    })
}

type Built = (Box<dyn Brdf<f64>>, Vec<(&'static str, Value)>);

fn build(kind: &'static str, kw: &mut Kwargs<'_>) -> PyResult<Built> {
    use Value::{Flag, Rgb, Scalar};
    Ok(match kind {
        "lambert" => {
            let d = LambertParams::<f64>::default();
            let p = LambertParams { albedo: kw.rgb("albedo", d.albedo)? };
            let m = Lambert::try_new(p).map_err(param_error)?;
            let q = *m.params();
            (Box::new(m), vec![("albedo", Rgb(q.albedo))])
        }
        "realistic_phong" => {
            let d = RealisticPhongParams::<f64>::default();
            let p = RealisticPhongParams {
                kd: kw.rgb("kd", d.kd)?,
                ks: kw.rgb("ks", d.ks)?,
                exponent: kw.scalar("exponent", d.exponent)?,
            };
            let m = RealisticPhong::try_new(p).map_err(param_error)?;
            let q = *m.params();
            let params =
                vec![("kd", Rgb(q.kd)), ("ks", Rgb(q.ks)), ("exponent", Scalar(q.exponent))];
            (Box::new(m), params)
        }
        "torrance_sparrow" => {
            let d = TorranceSparrowParams::<f64>::default();
            let p = TorranceSparrowParams {
                roughness: kw.scalar("roughness", d.roughness)?,
                diffuse: kw.rgb("diffuse", d.diffuse)?,
                f0: kw.rgb("f0", d.f0)?,
            };
            let m = TorranceSparrow::try_new(p).map_err(param_error)?;
            let q = *m.params();
            let params = vec![
                ("roughness", Scalar(q.roughness)),
                ("diffuse", Rgb(q.diffuse)),
                ("f0", Rgb(q.f0)),
            ];
            (Box::new(m), params)
        }
        "disney" => {
            let d = DisneyParams::<f64>::default();
            let p = DisneyParams {
                base_color: kw.rgb("base_color", d.base_color)?,
                metallic: kw.scalar("metallic", d.metallic)?,
                subsurface: kw.scalar("subsurface", d.subsurface)?,
                specular: kw.scalar("specular", d.specular)?,
                roughness: kw.scalar("roughness", d.roughness)?,
                specular_tint: kw.scalar("specular_tint", d.specular_tint)?,
                sheen: kw.scalar("sheen", d.sheen)?,
                sheen_tint: kw.scalar("sheen_tint", d.sheen_tint)?,
                clearcoat: kw.scalar("clearcoat", d.clearcoat)?,
                clearcoat_gloss: kw.scalar("clearcoat_gloss", d.clearcoat_gloss)?,
                gamma_base_color: kw.flag("gamma_base_color", d.gamma_base_color)?,
            };
            let m = Disney::try_new(p).map_err(param_error)?;
            let q = *m.params();
            let params = vec![
                ("base_color", Rgb(q.base_color)),
                ("metallic", Scalar(q.metallic)),
                ("subsurface", Scalar(q.subsurface)),
                ("specular", Scalar(q.specular)),
                ("roughness", Scalar(q.roughness)),
                ("specular_tint", Scalar(q.specular_tint)),
                ("sheen", Scalar(q.sheen)),
                ("sheen_tint", Scalar(q.sheen_tint)),
                ("clearcoat", Scalar(q.clearcoat)),
                ("clearcoat_gloss", Scalar(q.clearcoat_gloss)),
                ("gamma_base_color", Flag(q.gamma_base_color)),
            ];
            (Box::new(m), params)
        }
        "fmbrdf" => {
            let d = FmbrdfParams::<f64>::default();
            let p = FmbrdfParams {
                eta: kw.scalar("eta", d.eta)?,
                rho: kw.rgb("rho", d.rho)?,
                k_s: kw.scalar("k_s", d.k_s)?,
                alpha: kw.scalar("alpha", d.alpha)?,
                beta: kw.scalar("beta", d.beta)?,
                kappa: kw.scalar("kappa", d.kappa)?,
            };
            let m = Fmbrdf::try_new(p).map_err(param_error)?;
            let q = *m.params();
            let params = vec![
                ("eta", Scalar(q.eta)),
                ("rho", Rgb(q.rho)),
                ("k_s", Scalar(q.k_s)),
                ("alpha", Scalar(q.alpha)),
                ("beta", Scalar(q.beta)),
                ("kappa", Scalar(q.kappa)),
            ];
            (Box::new(m), params)
        }
        _ => unreachable!("canonical kinds only"),
    })
}

/// Checks that every row is a finite unit vector (to 1e-3): the models assume unit directions,
/// and a silently unnormalised input would give silently wrong values.
fn unit_rows(a: &PyReadonlyArray2<'_, f64>, name: &str) -> PyResult<Vec<[f64; 3]>> {
    let flat = rows::<f64, 3>(a, name)?;
    let out = crate::arrays::as_vec3(flat);
    // NaN fails the comparison, so a non-finite row is not a unit vector either.
    let unit = |r: &[f64; 3]| ((r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt() - 1.0).abs() < 1e-3;
    if let Some((i, r)) = out.iter().enumerate().find(|(_, r)| !unit(r)) {
        return Err(PyValueError::new_err(format!(
            "{name}: row {i} is {r:?}, not a finite unit vector (normalise directions first)"
        )));
    }
    Ok(out)
}

#[pymethods]
impl AnalyticBrdf {
    /// `AnalyticBrdf(kind, **params)`: see the module table for kinds and parameters.
    #[new]
    #[pyo3(signature = (kind, **params))]
    fn new(kind: &str, params: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let kind = canonical(kind)?;
        let mut kw = Kwargs::new(kind, params)?;
        let (model, params) = build(kind, &mut kw)?;
        kw.finish()?;
        Ok(Self { model, kind, params })
    }

    /// The canonical kind (`lambert`, `realistic_phong`, ...).
    #[getter]
    fn kind(&self) -> &'static str {
        self.kind
    }

    /// Whether f(l, v) = f(v, l) (all but FMBRDF).
    #[getter]
    fn reciprocal(&self) -> bool {
        self.model.is_reciprocal()
    }

    /// The parameters as used (after the models' own clamping), RGB ones as 3-tuples.
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (name, v) in &self.params {
            match *v {
                Value::Scalar(x) => d.set_item(name, x)?,
                Value::Rgb(c) => d.set_item(name, (c[0], c[1], c[2]))?,
                Value::Flag(b) => d.set_item(name, b)?,
            }
        }
        Ok(d)
    }

    /// f_r(l, v) for `(n, 3)` unit directions: `(n, 3)` RGB, 1/sr, without the cosine; zero
    /// below the horizon.
    fn eval<'py>(
        &self,
        py: Python<'py>,
        l: PyReadonlyArray2<'py, f64>,
        v: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let (l, v) = (unit_rows(&l, "l")?, unit_rows(&v, "v")?);
        let n = same_len(&[("l", l.len()), ("v", v.len())])?;
        let mut out = vec![[0.0f64; 3]; n];
        py.detach(|| brdf_analytic::par_eval_batch(&*self.model, &l, &v, &mut out));
        Ok(to_array2(py, &out))
    }

    /// Draws `l` for each `v` from uniforms `u` (`(n, 2)` in [0, 1)): `(l, weight, pdf,
    /// valid)` with weight = f cos / pdf; rows where no sample exists (v below the horizon or
    /// a reflection below it) have `valid` false and zeros.
    #[allow(clippy::type_complexity)]
    fn sample<'py>(
        &self,
        py: Python<'py>,
        v: PyReadonlyArray2<'py, f64>,
        u: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<(
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<bool>>,
    )> {
        let v = unit_rows(&v, "v")?;
        let u = rows::<f64, 2>(&u, "u")?;
        same_len(&[("v", v.len()), ("u", u.len() / 2)])?;
        let drawn: Vec<_> = py.detach(|| {
            v.par_iter()
                .zip(u.par_chunks_exact(2))
                .map(|(&v, u)| self.model.sample(v, [u[0], u[1]]))
                .collect()
        });
        let l: Vec<[f64; 3]> = drawn.iter().map(|s| s.map_or([0.0; 3], |s| s.l)).collect();
        let w: Vec<[f64; 3]> = drawn.iter().map(|s| s.map_or([0.0; 3], |s| s.weight)).collect();
        let pdf: Vec<f64> = drawn.iter().map(|s| s.map_or(0.0, |s| s.pdf)).collect();
        let valid: Vec<bool> = drawn.iter().map(Option::is_some).collect();
        Ok((to_array2(py, &l), to_array2(py, &w), to_array1(py, pdf), to_array1(py, valid)))
    }

    /// The sampling density of `l` given `v`, per solid angle: `(n,)`.
    fn pdf<'py>(
        &self,
        py: Python<'py>,
        v: PyReadonlyArray2<'py, f64>,
        l: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (v, l) = (unit_rows(&v, "v")?, unit_rows(&l, "l")?);
        same_len(&[("v", v.len()), ("l", l.len())])?;
        let pdf: Vec<f64> = py.detach(|| {
            v.par_iter().zip(l.par_iter()).map(|(&v, &l)| self.model.pdf(v, l)).collect()
        });
        Ok(to_array1(py, pdf))
    }

    fn __repr__(&self) -> String {
        let params: Vec<String> = self
            .params
            .iter()
            .map(|(k, v)| match v {
                Value::Scalar(x) => format!("{k}={x}"),
                Value::Rgb(c) => format!("{k}=({}, {}, {})", c[0], c[1], c[2]),
                Value::Flag(b) => format!("{k}={}", if *b { "True" } else { "False" }),
            })
            .collect();
        format!("AnalyticBrdf({:?}, {})", self.kind, params.join(", "))
    }
}
