//! `experiments export`: a finished Disney or Torrance-Sparrow run as renderer files, written
//! atomically into one folder:
//!
//! ```text
//! <out>/gltf/<name>.gltf, <name>.bin      glTF 2.0, metallic-roughness (+ specular, clear coat)
//! <out>/mitsuba/object.xml, mesh.ply, view<v>_light<l>.xml   Mitsuba 3
//! <out>/pbrt/object.pbrt, mesh.ply, view<v>_light<l>.pbrt    pbrt-v4
//! <out>/export.json                        what was written, the mapping's model and the round trip
//! ```
//!
//! The glTF asset is read back with the `gltf` crate and re-rendered ([`super::round_trip`]).

use super::gltf::ExportMesh;
use super::material::{ExportedMaterial, MaterialKind};
use super::round_trip::{RoundTrip, round_trip};
use super::{gltf, mitsuba, pbrt, test_pairs};
use crate::fitted::FittedRun;
use crate::{Error, Result};
use brdf_neural::BrdfModel;
use run_format::run_dir::RunDir;
use serde::Serialize;
use std::path::Path;

/// A renderer format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Format {
    /// glTF 2.0 (`.gltf` + `.bin`).
    Gltf,
    /// Mitsuba 3 scene XML.
    Mitsuba,
    /// pbrt-v4 scene.
    Pbrt,
}

impl Format {
    /// Every format.
    pub const ALL: [Format; 3] = [Format::Gltf, Format::Mitsuba, Format::Pbrt];

    /// Parses `gltf`, `mitsuba`, `pbrt` or `all` (every format).
    pub fn parse_list(text: &str) -> Result<Vec<Format>> {
        let mut out = Vec::new();
        for name in text.split(',').map(str::trim) {
            match name {
                "gltf" => out.push(Format::Gltf),
                "mitsuba" => out.push(Format::Mitsuba),
                "pbrt" => out.push(Format::Pbrt),
                "all" => out.extend(Format::ALL),
                other => {
                    return Err(Error::config(
                        "format",
                        format!("{other:?}: expected gltf, mitsuba, pbrt or all"),
                    ));
                }
            }
        }
        out.dedup();
        Ok(out)
    }

    /// The sub-folder name.
    pub fn dir(self) -> &'static str {
        match self {
            Format::Gltf => "gltf",
            Format::Mitsuba => "mitsuba",
            Format::Pbrt => "pbrt",
        }
    }
}

/// What [`export`] wrote (also `<out>/export.json`).
#[derive(Clone, Debug, Serialize)]
pub struct ExportSummary {
    /// `disney` or `torrance_sparrow` (a parametric fit's material), or the model kind of a
    /// purely neural fit (`single_mlp`, ...).
    pub model: &'static str,
    /// Whether the fit is spatially uniform (one parameter row for the object).
    pub uniform: bool,
    /// Mesh vertices (= material rows).
    pub vertices: usize,
    /// The mean parameter row, by column name.
    pub mean_parameters: serde_json::Map<String, serde_json::Value>,
    /// Test (view, light) pairs written as renderer scenes.
    pub test_pairs: usize,
    /// Files, relative to the output folder.
    pub files: Vec<String>,
    /// The glTF round trip (when glTF was written).
    pub round_trip: Option<RoundTrip>,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// Exports the finished run `run` into the folder `out` (replaced atomically).
pub fn export(
    run: &Path,
    out: &Path,
    formats: &[Format],
    scene: Option<&Path>,
    cache: Option<&Path>,
) -> Result<ExportSummary> {
    let start = std::time::Instant::now();
    let fitted = FittedRun::open(run, scene, cache)?;
    if !matches!(fitted.model, BrdfModel::Parametric(_)) {
        return export_neural(run, out, formats, &fitted, start);
    }
    let material = ExportedMaterial::from_run(&fitted)?;
    let (positions, normals) = mesh_arrays(&fitted);
    let triangles = &fitted.dataset.mesh.triangles;
    let export_mesh = ExportMesh { positions: &positions, normals: &normals, triangles };
    let pairs = test_pairs(&fitted.dataset);
    let name = match material.kind {
        MaterialKind::Disney => "disney",
        MaterialKind::TorranceSparrow => "torrance_sparrow",
    };
    let dirs: Vec<&str> = formats.iter().map(|f| f.dir()).collect();
    stdx::fs::write_dir_atomic(out, &dirs, |tmp| {
        let mut files = Vec::new();
        let mut trip = None;
        for &f in formats {
            let dir = tmp.join(f.dir());
            let written = match f {
                Format::Gltf => {
                    gltf::write(&dir, name, &export_mesh, &material)?;
                    let back = gltf::read(&dir.join(format!("{name}.gltf")))?;
                    trip = Some(round_trip(&fitted, &back)?);
                    vec![format!("{name}.gltf"), format!("{name}.bin")]
                }
                Format::Mitsuba => mitsuba::write(&dir, &export_mesh, &material, &pairs)?,
                Format::Pbrt => pbrt::write(&dir, &export_mesh, &material, &pairs)?,
            };
            files.extend(written.into_iter().map(|w| format!("{}/{w}", f.dir())));
        }
        let mean = material.mean();
        let summary = ExportSummary {
            model: name,
            uniform: material.is_uniform(),
            vertices: material.len(),
            mean_parameters: material
                .kind
                .columns()
                .iter()
                .zip(&mean)
                .map(|(c, v)| (c.to_string(), serde_json::json!(v)))
                .collect(),
            test_pairs: pairs.len(),
            files,
            round_trip: trip,
            seconds: start.elapsed().as_secs_f64(),
        };
        let json =
            serde_json::to_vec_pretty(&summary).map_err(|e| Error::format(out, e.to_string()))?;
        stdx::fs::write_atomic(&tmp.join("export.json"), &json)?;
        Ok(summary)
    })
}

/// The mesh of `fitted`'s scene with its vertex normals, as the exporters take it.
fn mesh_arrays(fitted: &FittedRun) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    let mesh = &fitted.dataset.mesh;
    let positions = mesh.positions.iter().map(|p| p.to_array()).collect();
    let normals = mesh
        .vertex_normals(mesh_encoding::NormalWeighting::default())
        .iter()
        .map(|n| n.to_array())
        .collect();
    (positions, normals)
}

/// A purely neural fit: the Mitsuba 3 scene with the `neural_brdf` BSDF of the Python package
/// (`neural_brdfs.mitsuba`) and the run's portable weights beside it. glTF and pbrt-v4 have
/// no neural material: asking for one of them alone is an error naming the alternatives;
/// asking for all formats writes the Mitsuba scene only.
fn export_neural(
    run: &Path,
    out: &Path,
    formats: &[Format],
    fitted: &FittedRun,
    start: std::time::Instant,
) -> Result<ExportSummary> {
    let kind = fitted.config.model.kind.config_name();
    if !formats.contains(&Format::Mitsuba) || formats.len() < Format::ALL.len() && formats.len() > 1
    {
        let asked: Vec<&str> = formats.iter().map(|f| f.dir()).collect();
        return Err(Error::config(
            "export.format",
            format!(
                "{kind} is a neural model: it exports to Mitsuba 3 only (`--format mitsuba`, \
                 rendered by the `neural_brdf` plugin of the Python package), not to {}; \
                 `experiments export-merl` writes a MERL table for other renderers",
                asked.join(", ")
            ),
        ));
    }
    let (positions, normals) = mesh_arrays(fitted);
    let mesh = ExportMesh {
        positions: &positions,
        normals: &normals,
        triangles: &fitted.dataset.mesh.triangles,
    };
    let pairs = test_pairs(&fitted.dataset);
    let dir_name = Format::Mitsuba.dir();
    stdx::fs::write_dir_atomic(out, &[dir_name], |tmp| {
        let dir = tmp.join(dir_name);
        let weights = RunDir::new(run).weights();
        let portable = RunDir::new(&dir);
        crate::portable::write(
            &portable,
            &weights,
            &fitted.config,
            &fitted.dataset,
            &fitted.cache,
        )?;
        let mut written =
            mitsuba::write_mitsuba_scenes(&dir, &mesh, &mitsuba::neural_bsdf(), &[], &pairs)?;
        for file in [portable.portable_weights(), portable.portable_description()] {
            written.extend(file.file_name().map(|n| n.to_string_lossy().into_owned()));
        }
        let summary = ExportSummary {
            model: kind,
            uniform: false,
            vertices: positions.len(),
            mean_parameters: serde_json::Map::new(),
            test_pairs: pairs.len(),
            files: written.into_iter().map(|w| format!("{dir_name}/{w}")).collect(),
            round_trip: None,
            seconds: start.elapsed().as_secs_f64(),
        };
        let json =
            serde_json::to_vec_pretty(&summary).map_err(|e| Error::format(out, e.to_string()))?;
        stdx::fs::write_atomic(&tmp.join("export.json"), &json)?;
        Ok(summary)
    })
}
