//! Weights others can read: a fitted model as `model.safetensors` and `model.json`, written
//! beside `weights.bpk` with the results of a run's evaluation ([`fitted_files`], which the
//! run's holder writes; the `fit` command writes them when it finishes; [`write()`] on demand
//! for older runs and bundles), so that a
//! PyTorch or numpy user can rebuild and evaluate the model without this workspace (the
//! reference modules ship in the Python package: `neural_brdfs.reference_numpy`,
//! `neural_brdfs.reference_torch`).
//!
//! **`model.safetensors`** ([safetensors](https://github.com/huggingface/safetensors): a u64
//! LE header length, a JSON header, the raw little-endian data), tensors in name order:
//!
//! | tensor | dtype, shape | what |
//! | :-- | :-- | :-- |
//! | `<net>.layers.<i>.weight` | F32 `[out, in]` | linear layers, PyTorch layout (burn's `[in, out]` transposed) |
//! | `<net>.layers.<i>.bias` | F32 `[out]` | their biases |
//! | `<net>.skip.weight`, `<net>.late.weight` | F32 `[out, in]` | the skip (and NOL) input layers, no bias |
//! | `fm_alpha`, `fm_beta` | F32 `[1, 1]` | FMBRDF's global raw parameters |
//! | `spatial.vertex_features` | F32 `[V, dim]` | the per-vertex spatial features (LBO eigenfunctions, positions, or ones) |
//! | `spatial.triangles` | I32 `[T, 3]` | the mesh's triangles: a point's features interpolate its triangle's rows with weights `(1 - b1 - b2, b1, b2)` |
//!
//! The model's names are burn's module paths without the enum variant (`SingleMlp.mlp...`
//! becomes `mlp...`).
//!
//! **`model.json`**: `format` (`neural-brdfs-weights`), `version` (1), `kind` (the model kind's
//! configuration name), `paper_name`, `model` (the `ModelConfig` as in `config.toml`: widths,
//! layers, skips, angle features and encodings, heads), `spatial` (`kind`, `dim`) and
//! `conventions` (frames and units, in words).

use crate::data::vertex_features;
use crate::fitted::{FittedRun, weight_pack};
use crate::{Error, Result};
use burn::tensor::DType;
use run_format::config::RunConfig;
use run_format::held_run::PortableFiles;
use run_format::run_dir::RunDir;
use scene::SceneDataset;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The `format` field of the description.
pub const FORMAT: &str = "neural-brdfs-weights";
/// The `version` field of the description.
pub const VERSION: u32 = 1;

/// A tensor on its way into the file.
struct Entry {
    dtype: &'static str,
    shape: Vec<usize>,
    bytes: Vec<u8>,
}

/// The portable files of a fitted run, serialised from its model in memory (the same tensors
/// as its final weights' file, which export does not read back); its holder writes them
/// ([`run_format::held_run::HeldRun::write_results`]).
pub fn fitted_files(fitted: &FittedRun) -> Result<PortableFiles> {
    let pack = burn_pack::Reader::from_bytes(weight_pack(&fitted.model)?);
    let tensors = model_tensors(pack, Path::new("weights.bpk"))?;
    files(tensors, &fitted.config, &fitted.dataset, &fitted.cache)
}

/// Writes `model.safetensors` and `model.json` ([`RunDir::portable_weights`],
/// [`RunDir::portable_description`]) of `out` for the weights in `weights_bpk` (a burnpack of
/// `config.model`) and the scene's spatial features (the folder is created if needed; each
/// file atomically). Returns the two paths.
///
/// # Errors
/// A weights file that does not read or holds non-f32 tensors, feature or I/O failures.
pub fn write(
    out: &RunDir,
    weights_bpk: &Path,
    config: &RunConfig,
    scene: &SceneDataset,
    cache: &Path,
) -> Result<[PathBuf; 2]> {
    let tensors = model_tensors(burn_pack::Reader::from_file(weights_bpk), weights_bpk)?;
    Ok(files(tensors, config, scene, cache)?.write_to(out)?)
}

/// The portable files of the model's tensors `tensors` ([`model_tensors`]) and the scene's
/// spatial features.
fn files(
    mut tensors: BTreeMap<String, Entry>,
    config: &RunConfig,
    scene: &SceneDataset,
    cache: &Path,
) -> Result<PortableFiles> {
    let js = Path::new("model.json");
    let (table, dim) = vertex_features(scene, config, cache)?;
    let vertices = table.len() / dim.max(1);
    tensors.insert(
        "spatial.vertex_features".into(),
        Entry { dtype: "F32", shape: vec![vertices, dim], bytes: le_bytes(&table) },
    );
    let tris: Vec<i32> = scene.mesh.triangles.iter().flatten().map(|&i| i as i32).collect();
    tensors.insert(
        "spatial.triangles".into(),
        Entry {
            dtype: "I32",
            shape: vec![scene.mesh.triangles.len(), 3],
            bytes: tris.iter().flat_map(|x| x.to_le_bytes()).collect(),
        },
    );
    let description = serde_json::json!({
        "format": FORMAT,
        "version": VERSION,
        "kind": config.model.kind.config_name(),
        "paper_name": config.model.kind.paper_name(),
        "model": serde_json::to_value(&config.model)
            .map_err(|e| Error::format(js, format!("model configuration: {e}")))?,
        "spatial": {
            "kind": serde_json::to_value(config.features.spatial)
                .map_err(|e| Error::format(js, format!("spatial kind: {e}")))?,
            "dim": dim,
        },
        "conventions": {
            "directions": "unit vectors in the local shading frame (normal +z): l towards the \
                light, v towards the viewer; the frame of a world normal n is Duff et al. \
                2017's orthonormal basis",
            "output": "f_r, linear RGB, 1/sr, without the cosine",
            "linear_weights": "[out, in] (PyTorch layout)",
        },
    });
    let json =
        serde_json::to_string_pretty(&description).map_err(|e| Error::format(js, e.to_string()))?;
    Ok(PortableFiles { weights: safetensors_bytes(&tensors), description: (json + "\n").into() })
}

/// The model's tensors from a burnpack (`reader`; `path` names it in errors), renamed and in
/// PyTorch layout.
fn model_tensors(
    reader: std::result::Result<burn_pack::Reader, burn_pack::Error>,
    path: &Path,
) -> Result<BTreeMap<String, Entry>> {
    let bad = |m: String| Error::format(path, m);
    let reader = reader.map_err(|e| bad(format!("cannot read weights: {e:?}")))?;
    let mut out = BTreeMap::new();
    for t in reader.into_tensors().map_err(|e| bad(format!("cannot read weights: {e:?}")))? {
        let (name, dtype, shape, _, bytes) =
            t.into_parts().map_err(|e| bad(format!("cannot read weights: {e:?}")))?;
        if dtype != DType::F32 {
            return Err(bad(format!("tensor {name} is {dtype:?}, expected f32")));
        }
        let shape = shape.to_vec();
        let values: Vec<f32> =
            bytes.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
        // Without the enum variant: `SingleMlp.mlp.layers.0.weight` -> `mlp.layers.0.weight`.
        let short = name.split_once('.').map_or(name.as_str(), |(_, rest)| rest).to_string();
        let (shape, values) = if short.ends_with(".weight") && shape.len() == 2 {
            let (rows, cols) = (shape[0], shape[1]);
            let mut t = vec![0.0f32; values.len()];
            for r in 0..rows {
                for c in 0..cols {
                    t[c * rows + r] = values[r * cols + c];
                }
            }
            (vec![cols, rows], t)
        } else {
            (shape, values)
        };
        out.insert(short, Entry { dtype: "F32", shape, bytes: le_bytes(&values) });
    }
    Ok(out)
}

fn le_bytes(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// The safetensors encoding: header (name order, padded with spaces to a multiple of 8 so the
/// data is aligned), then the tensors' bytes in the same order.
fn safetensors_bytes(tensors: &BTreeMap<String, Entry>) -> Vec<u8> {
    let mut header = serde_json::Map::new();
    header.insert(
        "__metadata__".into(),
        serde_json::json!({ "format": "pt", "producer": "neural-brdfs" }),
    );
    let mut offset = 0usize;
    for (name, e) in tensors {
        header.insert(
            name.clone(),
            serde_json::json!({
                "dtype": e.dtype,
                "shape": e.shape,
                "data_offsets": [offset, offset + e.bytes.len()],
            }),
        );
        offset += e.bytes.len();
    }
    let mut text = serde_json::Value::Object(header).to_string().into_bytes();
    while !text.len().is_multiple_of(8) {
        text.push(b' ');
    }
    let mut out = Vec::with_capacity(8 + text.len() + offset);
    out.extend_from_slice(&(text.len() as u64).to_le_bytes());
    out.extend_from_slice(&text);
    for e in tensors.values() {
        out.extend_from_slice(&e.bytes);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn safetensors_layout_is_aligned_and_offsets_are_contiguous() {
        let mut t = BTreeMap::new();
        t.insert("b".into(), Entry { dtype: "F32", shape: vec![2], bytes: le_bytes(&[1.0, 2.0]) });
        t.insert("a".into(), Entry { dtype: "I32", shape: vec![1, 1], bytes: vec![7, 0, 0, 0] });
        let bytes = safetensors_bytes(&t);
        let n = u64::from_le_bytes(bytes[..8].try_into().unwrap()) as usize;
        assert!(n.is_multiple_of(8), "the data starts 8-byte aligned");
        let header: serde_json::Value = serde_json::from_slice(&bytes[8..8 + n]).unwrap();
        assert_eq!(header["a"]["data_offsets"], serde_json::json!([0, 4]));
        assert_eq!(header["b"]["data_offsets"], serde_json::json!([4, 12]));
        assert_eq!(header["b"]["shape"], serde_json::json!([2]));
        let data = &bytes[8 + n..];
        assert_eq!(data.len(), 12);
        assert_eq!(f32::from_le_bytes(data[8..12].try_into().unwrap()), 2.0);
    }
}
