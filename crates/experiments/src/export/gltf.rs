//! A fitted material on its mesh as a glTF 2.0 asset (`<name>.gltf` + `<name>.bin`) with a
//! metallic-roughness material.
//!
//! | fit | glTF | what a glTF renderer loses |
//! | --- | --- | --- |
//! | TS rho_d | `baseColorFactor` (uniform) or `COLOR_0` (per vertex), `metallicFactor` 0 | glTF weights its diffuse by 1 - F (energy-conserving layering); TS adds it |
//! | TS F0 | `KHR_materials_specular.specularColorFactor` = F0 / 0.04 (`specularFactor` 1, ior 1.5) | nothing: dielectric F0 = 0.04 specularColor |
//! | TS r | `roughnessFactor` = r (alpha = r^2 in both) | nothing |
//! | Disney base colour, metallic, roughness | `baseColor`, `metallicFactor`, `roughnessFactor` | Burley's retro-reflective diffuse becomes Lambertian |
//! | Disney specular, specular tint | `specularColorFactor` = 0.08 specular mix(1, tint, specular_tint) / 0.04 | nothing for F0 |
//! | Disney clear coat, gloss | `KHR_materials_clearcoat`: factor 0.25 clearcoat, roughness sqrt(mix(0.1, 0.001, gloss)) | GTR1 becomes GGX |
//! | Disney subsurface, sheen, sheen tint | not represented (KHR_materials_sheen's lobe differs) | those lobes |
//!
//! The exact parameters travel with the asset so that nothing is lost for tools that know them:
//! the material's `extras.neural_brdf` holds the model, its column names and, for a spatially
//! uniform fit, the row; a spatially varying fit puts every column per vertex (colour columns in
//! `COLOR_0`, the others as application-specific attributes `_<COLUMN>`, which glTF reserves for
//! this). The scene format's meshes carry no UVs, so per-vertex values are vertex attributes, not
//! textures; viewers then see the per-vertex base colour and the mean of every other factor.
//! [`read`] reads an asset back with the `gltf` crate (the round trip's input).

use super::material::{ExportedMaterial, MaterialKind, column};
use crate::{Error, Result};
use serde_json::{Value, json};
use std::path::Path;

/// glTF's `ARRAY_BUFFER` and `ELEMENT_ARRAY_BUFFER` targets, and component types.
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;

/// The `extras` key of the exact parameters.
pub const EXTRAS_KEY: &str = "neural_brdf";

/// The mesh a material is exported on.
pub struct ExportMesh<'a> {
    /// Vertex positions.
    pub positions: &'a [[f32; 3]],
    /// Unit vertex normals (the scene's shading normals).
    pub normals: &'a [[f32; 3]],
    /// Triangles, counter-clockwise from the front.
    pub triangles: &'a [[u32; 3]],
}

/// The glTF attribute name of a non-colour column.
fn attribute_name(column: &str) -> String {
    format!("_{}", column.to_uppercase())
}

/// The colour columns (written as `COLOR_0`) of a model.
fn colour_columns(kind: MaterialKind) -> [&'static str; 3] {
    match kind {
        MaterialKind::Disney => ["base_color_r", "base_color_g", "base_color_b"],
        MaterialKind::TorranceSparrow => ["diffuse_r", "diffuse_g", "diffuse_b"],
    }
}

/// The glTF material of one row (the uniform or mean parameters); see the module table.
pub fn material_json(kind: MaterialKind, row: &[f32], per_vertex_colour: bool) -> Value {
    let c = |name: &str| column(kind, row, name) as f64;
    let rgb = |names: [&str; 3]| [c(names[0]), c(names[1]), c(names[2])];
    let colour = if per_vertex_colour { [1.0; 3] } else { rgb(colour_columns(kind)) };
    let base = json!([colour[0], colour[1], colour[2], 1.0]);
    match kind {
        MaterialKind::TorranceSparrow => {
            let f0 = rgb(["f0_r", "f0_g", "f0_b"]);
            json!({
                "name": "torrance_sparrow",
                "pbrMetallicRoughness": {
                    "baseColorFactor": base,
                    "metallicFactor": 0.0,
                    "roughnessFactor": c("roughness"),
                },
                "extensions": {
                    "KHR_materials_specular": {
                        "specularFactor": 1.0,
                        "specularColorFactor": f0.map(|x| x / 0.04),
                    },
                },
            })
        }
        MaterialKind::Disney => {
            let lin = rgb(colour_columns(kind));
            // The Disney tint: the base colour's hue at unit luminance.
            let lum = 0.3 * lin[0] + 0.6 * lin[1] + 0.1 * lin[2];
            let tint = lin.map(|x| if lum > 0.0 { x / lum } else { 1.0 });
            let st = c("specular_tint");
            let spec = tint.map(|t| 0.08 * c("specular") * (1.0 - st + st * t) / 0.04);
            let gloss = c("clearcoat_gloss");
            json!({
                "name": "disney",
                "pbrMetallicRoughness": {
                    "baseColorFactor": base,
                    "metallicFactor": c("metallic"),
                    "roughnessFactor": c("roughness"),
                },
                "extensions": {
                    "KHR_materials_specular": {
                        "specularFactor": 1.0,
                        "specularColorFactor": spec,
                    },
                    "KHR_materials_clearcoat": {
                        "clearcoatFactor": 0.25 * c("clearcoat"),
                        "clearcoatRoughnessFactor": (0.1 + (0.001 - 0.1) * gloss).sqrt(),
                    },
                },
            })
        }
    }
}

/// Little-endian bytes of f32 values.
fn f32_bytes(v: impl IntoIterator<Item = f32>) -> Vec<u8> {
    v.into_iter().flat_map(f32::to_le_bytes).collect()
}

/// Writes `<dir>/<name>.gltf` and `<dir>/<name>.bin` (each atomically).
pub fn write(
    dir: &Path,
    name: &str,
    mesh: &ExportMesh<'_>,
    material: &ExportedMaterial,
) -> Result<()> {
    let n = mesh.positions.len();
    if material.len() != n || mesh.normals.len() != n {
        return Err(Error::config(
            "material",
            format!(
                "{} material rows and {} normals for {n} vertices",
                material.len(),
                mesh.normals.len()
            ),
        ));
    }
    let kind = material.kind;
    let uniform = material.is_uniform();
    let row = material.uniform_or_mean();
    let attributes = vertex_attributes(mesh, material);
    let mut bin = Vec::new();
    let (mut views, mut accessors, mut attr_json) = (vec![], vec![], serde_json::Map::new());
    for (i, (attr, comps, bytes)) in attributes.iter().enumerate() {
        views.push(json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len(),
                          "target": ARRAY_BUFFER}));
        let ty = if *comps == 3 { "VEC3" } else { "SCALAR" };
        let mut acc = json!({"bufferView": i, "componentType": FLOAT, "count": n, "type": ty});
        if attr == "POSITION" {
            let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
            for p in mesh.positions {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
            acc["min"] = json!(lo);
            acc["max"] = json!(hi);
        }
        accessors.push(acc);
        attr_json.insert(attr.clone(), json!(i));
        bin.extend_from_slice(bytes);
    }
    let indices = mesh.triangles.iter().flatten().flat_map(|i| i.to_le_bytes()).collect::<Vec<_>>();
    views.push(json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": indices.len(),
                      "target": ELEMENT_ARRAY_BUFFER}));
    accessors.push(json!({"bufferView": views.len() - 1, "componentType": UNSIGNED_INT,
                          "count": mesh.triangles.len() * 3, "type": "SCALAR"}));
    bin.extend_from_slice(&indices);
    let mat = material_with_extras(kind, &row, uniform);
    let mut used = vec!["KHR_materials_specular"];
    if kind == MaterialKind::Disney {
        used.push("KHR_materials_clearcoat");
    }
    let doc = json!({
        "asset": {"version": "2.0", "generator": concat!("neural-brdf experiments ", env!("CARGO_PKG_VERSION"))},
        "extensionsUsed": used,
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": name}],
        "meshes": [{"name": name, "primitives": [{
            "attributes": attr_json, "indices": accessors.len() - 1, "material": 0, "mode": 4}]}],
        "materials": [mat],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"uri": format!("{name}.bin"), "byteLength": bin.len()}],
    });
    stdx::fs::write_atomic(&dir.join(format!("{name}.bin")), &bin)?;
    let text = serde_json::to_vec_pretty(&doc).map_err(|e| Error::format(dir, e.to_string()))?;
    stdx::fs::write_atomic(&dir.join(format!("{name}.gltf")), &text)?;
    Ok(())
}

/// (name, component count, bytes) of every vertex attribute: positions, normals and, for a
/// spatially varying material, its colour and every other parameter column.
fn vertex_attributes(
    mesh: &ExportMesh<'_>,
    material: &ExportedMaterial,
) -> Vec<(String, usize, Vec<u8>)> {
    let (n, kind) = (mesh.positions.len(), material.kind);
    let mut attributes: Vec<(String, usize, Vec<u8>)> = vec![
        ("POSITION".into(), 3, f32_bytes(mesh.positions.iter().flatten().copied())),
        ("NORMAL".into(), 3, f32_bytes(mesh.normals.iter().flatten().copied())),
    ];
    if !material.is_uniform() {
        let colour = colour_columns(kind).map(|c| material.column(c));
        let rgb = (0..n).flat_map(|i| [colour[0][i], colour[1][i], colour[2][i]]);
        attributes.push(("COLOR_0".into(), 3, f32_bytes(rgb)));
        for &c in kind.columns() {
            if !colour_columns(kind).contains(&c) {
                attributes.push((attribute_name(c), 1, f32_bytes(material.column(c))));
            }
        }
    }
    attributes
}

/// The glTF material of `row` with this crate's exact values in its `extras` (the uniform row,
/// or the mean of a varying one).
fn material_with_extras(kind: MaterialKind, row: &[f32], uniform: bool) -> serde_json::Value {
    let mut mat = material_json(kind, row, !uniform);
    let model = match kind {
        MaterialKind::Disney => "disney",
        MaterialKind::TorranceSparrow => "torrance_sparrow",
    };
    let mut extras = json!({"model": model, "columns": kind.columns(), "uniform": uniform});
    if uniform {
        extras["values"] = json!(row);
    } else {
        extras["mean"] = json!(row);
    }
    mat["extras"] = json!({ EXTRAS_KEY: extras });
    mat
}

/// Reads the exact per-vertex parameters back from an asset [`write`](fn@write) made, with the `gltf`
/// crate (which validates the document): the uniform row from `extras`, or every column from
/// the vertex attributes.
pub fn read(path: &Path) -> Result<ExportedMaterial> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let doc = gltf::Gltf::from_slice(&bytes).map_err(|e| Error::format(path, e.to_string()))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut buffers = Vec::new();
    for b in doc.buffers() {
        match b.source() {
            gltf::buffer::Source::Uri(uri) => {
                let p = dir.join(uri);
                let data = std::fs::read(&p).map_err(|e| Error::io(&p, e))?;
                if data.len() < b.length() {
                    return Err(Error::format(
                        &p,
                        format!("{} bytes, the asset says {}", data.len(), b.length()),
                    ));
                }
                buffers.push(data);
            }
            gltf::buffer::Source::Bin => {
                buffers.push(doc.blob.clone().ok_or_else(|| Error::format(path, "no GLB blob"))?)
            }
        }
    }
    let bad = |m: &str| Error::format(path, m.to_string());
    let mesh = doc.meshes().next().ok_or_else(|| bad("no mesh"))?;
    let prim = mesh.primitives().next().ok_or_else(|| bad("no primitive"))?;
    let material = prim.material();
    let extras: Value = material
        .extras()
        .as_ref()
        .map(|raw| serde_json::from_str(raw.get()))
        .transpose()
        .map_err(|e| bad(&format!("material extras: {e}")))?
        .ok_or_else(|| bad("the material has no extras (not written by `experiments export`)"))?;
    let ours = extras.get(EXTRAS_KEY).ok_or_else(|| bad("no extras.neural_brdf"))?;
    let kind = match ours.get("model").and_then(Value::as_str) {
        Some("disney") => MaterialKind::Disney,
        Some("torrance_sparrow") => MaterialKind::TorranceSparrow,
        other => return Err(bad(&format!("unknown model {other:?}"))),
    };
    let reader = prim.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
    let n = reader.read_positions().ok_or_else(|| bad("no POSITION"))?.count();
    let values = if ours.get("uniform").and_then(Value::as_bool) == Some(true) {
        let row: Vec<f32> = serde_json::from_value(ours.get("values").cloned().unwrap_or_default())
            .map_err(|e| bad(&format!("extras values: {e}")))?;
        if row.len() != kind.width() {
            return Err(bad(&format!("{} values for {} columns", row.len(), kind.width())));
        }
        row.repeat(n)
    } else {
        let colour: Vec<[f32; 3]> =
            reader.read_colors(0).ok_or_else(|| bad("no COLOR_0"))?.into_rgb_f32().collect();
        let mut cols: Vec<Vec<f32>> = Vec::new();
        for &c in kind.columns() {
            if let Some(k) = colour_columns(kind).iter().position(|x| *x == c) {
                cols.push(colour.iter().map(|rgb| rgb[k]).collect());
                continue;
            }
            let name = attribute_name(c);
            let (_, acc) = prim
                .attributes()
                .find(|(s, _)| matches!(s, gltf::Semantic::Extras(x) if *x == name[1..]))
                .ok_or_else(|| bad(&format!("no attribute {name}")))?;
            let iter = gltf::accessor::Iter::<f32>::new(acc, |b| {
                buffers.get(b.index()).map(Vec::as_slice)
            })
            .ok_or_else(|| bad(&format!("cannot read {name}")))?;
            cols.push(iter.collect());
        }
        if cols.iter().any(|c| c.len() != n) {
            return Err(bad("attribute lengths differ"));
        }
        (0..n).flat_map(|i| cols.iter().map(move |c| c[i]).collect::<Vec<_>>()).collect()
    };
    ExportedMaterial::new(kind, values)
}
