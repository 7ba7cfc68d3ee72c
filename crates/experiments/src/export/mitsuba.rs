//! A Mitsuba 3 scene of a fitted material: `object.xml` (the mesh, `mesh.ply`, with a
//! `principled` BSDF for a parametric fit, or the Python package's `neural_brdf` plugin on the
//! run's portable weights for a purely neural one, [`neural_bsdf`]) and one `view<v>_light<l>.xml` per test pair (perspective sensor, one
//! directional emitter, direct illumination), named like the run's renders.
//!
//! Render one with `mitsuba view003_light002.xml` or from Python:
//! `mi.render(mi.load_file("view003_light002.xml"))`.
//!
//! | fit | `principled` | lost |
//! | --- | --- | --- |
//! | Disney base colour, metallic, roughness, specular tint, sheen, sheen tint, clear coat, gloss | same names (`spec_tint`) | nothing in name; Mitsuba's principled is the 2015 model (its own Fresnel and sheen details) |
//! | Disney specular | `specular` (a float in Mitsuba: the mean over the vertices) | its spatial variation |
//! | Disney subsurface | not represented (`principled` has no subsurface) | the subsurface blend |
//! | TS rho_d, r | `base_color` = rho_d, `roughness` = r, `metallic` 0 | Burley's diffuse replaces Lambert's |
//! | TS F0 | `specular` = mean(F0) / 0.08 | the F0 colour |
//!
//! Spatially varying values are vertex attributes of `mesh.ply` read by `mesh_attribute`
//! textures; uniform fits get plain values. Camera: OpenCV's x right / y down become Mitsuba's
//! x left / y up (`to_world` columns -right, -down, forward, C); `fov` is the vertical one
//! (`fov_axis` y), and a principal point off the image centre becomes
//! `principal_point_offset_x/y` in units of the film size.

use super::gltf::ExportMesh;
use super::material::{ExportedMaterial, MaterialKind, column};
use super::ply::{self, VertexAttribute};
use super::{ExportCamera, ExportPair};
use crate::Result;
use std::fmt::Write as _;
use std::path::Path;

/// Samples per pixel of the written sensors.
pub const SAMPLES_PER_PIXEL: u32 = 64;

fn rgb_value(c: [f64; 3]) -> String {
    format!("{:.9}, {:.9}, {:.9}", c[0], c[1], c[2])
}

/// The `principled` parameters: (name, uniform value or mesh attribute, components).
fn principled(material: &ExportedMaterial) -> (String, Vec<VertexAttribute<'static>>) {
    let kind = material.kind;
    let uniform = material.is_uniform();
    let mean = material.mean();
    let mut xml = String::from("    <bsdf type=\"principled\">\n");
    let mut attrs = Vec::new();
    let mut param = |name: &'static str, values: Vec<f32>, comps: usize, xml: &mut String| {
        if uniform {
            if comps == 3 {
                let c = [values[0], values[1], values[2]].map(f64::from);
                let _ = writeln!(xml, "        <rgb name=\"{name}\" value=\"{}\"/>", rgb_value(c));
            } else {
                let _ =
                    writeln!(xml, "        <float name=\"{name}\" value=\"{:.9}\"/>", values[0]);
            }
        } else {
            let _ = writeln!(
                xml,
                "        <texture type=\"mesh_attribute\" name=\"{name}\">\n            \
                 <string name=\"name\" value=\"vertex_{name}\"/>\n        </texture>"
            );
            attrs.push(VertexAttribute { name, components: comps, values });
        }
    };
    let col = |c: &str| material.column(c);
    let interleave = |cols: [&str; 3]| -> Vec<f32> {
        let c = cols.map(col);
        (0..material.len()).flat_map(|i| [c[0][i], c[1][i], c[2][i]]).collect()
    };
    match kind {
        MaterialKind::Disney => {
            param(
                "base_color",
                interleave(["base_color_r", "base_color_g", "base_color_b"]),
                3,
                &mut xml,
            );
            for (ours, theirs) in [
                ("metallic", "metallic"),
                ("roughness", "roughness"),
                ("specular_tint", "spec_tint"),
                ("sheen", "sheen"),
                ("sheen_tint", "sheen_tint"),
                ("clearcoat", "clearcoat"),
                ("clearcoat_gloss", "clearcoat_gloss"),
            ] {
                param(theirs, col(ours), 1, &mut xml);
            }
            let _ = writeln!(
                xml,
                "        <float name=\"specular\" value=\"{:.9}\"/>",
                column(kind, &mean, "specular")
            );
        }
        MaterialKind::TorranceSparrow => {
            param("base_color", interleave(["diffuse_r", "diffuse_g", "diffuse_b"]), 3, &mut xml);
            param("roughness", col("roughness"), 1, &mut xml);
            let _ = writeln!(xml, "        <float name=\"metallic\" value=\"0\"/>");
            let f0 =
                ["f0_r", "f0_g", "f0_b"].iter().map(|c| column(kind, &mean, c)).sum::<f32>() / 3.0;
            let _ = writeln!(
                xml,
                "        <float name=\"specular\" value=\"{:.9}\"/>",
                (f0 / 0.08).min(1.0)
            );
        }
    }
    xml.push_str("    </bsdf>\n");
    (xml, attrs)
}

/// The sensor element of a camera.
pub fn sensor_xml(c: &ExportCamera, spp: u32) -> String {
    let m = |v: [f64; 3], s: f64| v.map(|x| x * s);
    let (x, y, z) = (m(c.right, -1.0), m(c.down, -1.0), c.forward);
    let o = c.center;
    let matrix = format!(
        "{} {} {} {} {} {} {} {} {} {} {} {} 0 0 0 1",
        x[0], y[0], z[0], o[0], x[1], y[1], z[1], o[1], x[2], y[2], z[2], o[2]
    );
    let (w, h) = (c.width as f64, c.height as f64);
    format!(
        "    <sensor type=\"perspective\">\n        \
         <string name=\"fov_axis\" value=\"y\"/>\n        \
         <float name=\"fov\" value=\"{:.9}\"/>\n        \
         <float name=\"principal_point_offset_x\" value=\"{:.9}\"/>\n        \
         <float name=\"principal_point_offset_y\" value=\"{:.9}\"/>\n        \
         <float name=\"near_clip\" value=\"0.001\"/>\n        \
         <transform name=\"to_world\">\n            <matrix value=\"{matrix}\"/>\n        </transform>\n        \
         <sampler type=\"independent\">\n            <integer name=\"sample_count\" value=\"{spp}\"/>\n        </sampler>\n        \
         <film type=\"hdrfilm\">\n            <integer name=\"width\" value=\"{}\"/>\n            \
         <integer name=\"height\" value=\"{}\"/>\n            <string name=\"pixel_format\" value=\"rgb\"/>\n            \
         <rfilter type=\"box\"/>\n        </film>\n    </sensor>\n",
        c.fov_y_deg(),
        (c.cx - 0.5 * w) / w,
        (c.cy - 0.5 * h) / h,
        c.width,
        c.height
    )
}

/// Writes the scene into `dir` (which exists).
pub fn write(
    dir: &Path,
    mesh: &ExportMesh<'_>,
    material: &ExportedMaterial,
    pairs: &[ExportPair],
) -> Result<Vec<String>> {
    let (bsdf, attrs) = principled(material);
    write_mitsuba_scenes(dir, mesh, &bsdf, &attrs, pairs)
}

/// The BSDF element of a purely neural fit: the Python package's `neural_brdf` plugin
/// (`neural_brdfs.mitsuba`, registered by importing it in a JIT variant such as
/// `llvm_ad_rgb`) on the portable weights `model.json` / `model.safetensors` beside the
/// scene. The plugin finds a surface point's spatial features from the mesh's triangle index
/// and barycentrics, so `mesh.ply` keeps the scene's vertex and face order and has no UVs.
pub fn neural_bsdf() -> String {
    "    <bsdf type=\"neural_brdf\">\n        \
     <string name=\"filename\" value=\"model.json\"/>\n    </bsdf>\n"
        .to_string()
}

/// Writes `mesh.ply` (with `attrs`), `object.xml` (the mesh with `bsdf`) and one scene per
/// test pair into `dir`; returns the file names.
pub fn write_mitsuba_scenes(
    dir: &Path,
    mesh: &ExportMesh<'_>,
    bsdf: &str,
    attrs: &[VertexAttribute<'_>],
    pairs: &[ExportPair],
) -> Result<Vec<String>> {
    ply::write(&dir.join("mesh.ply"), mesh, attrs)?;
    let object = format!(
        "<scene version=\"3.0.0\">\n    <shape type=\"ply\" id=\"object\">\n        \
         <string name=\"filename\" value=\"mesh.ply\"/>\n{bsdf}    </shape>\n</scene>\n"
    );
    stdx::fs::write_atomic(&dir.join("object.xml"), object.as_bytes())?;
    let mut files = vec!["mesh.ply".to_string(), "object.xml".to_string()];
    for p in pairs {
        let e = p.irradiance.map(f64::from);
        let emitter = match p.position {
            // Mitsuba 3's point emitter: radiant intensity, inverse-square falloff.
            Some(q) => format!(
                "<emitter type=\"point\">\n        <point name=\"position\" value=\"{}\"/>\n        \
                 <rgb name=\"intensity\" value=\"{}\"/>\n    </emitter>",
                rgb_value(q.map(f64::from)),
                rgb_value(e)
            ),
            None => format!(
                "<emitter type=\"directional\">\n        <vector name=\"direction\" value=\"{}\"/>\n        \
                 <rgb name=\"irradiance\" value=\"{}\"/>\n    </emitter>",
                rgb_value(p.direction.map(|x| -x as f64)),
                rgb_value(e)
            ),
        };
        let xml = format!(
            "<scene version=\"3.0.0\">\n    <integrator type=\"direct\"/>\n{}    \
             {emitter}\n    <include filename=\"object.xml\"/>\n</scene>\n",
            sensor_xml(&p.camera, SAMPLES_PER_PIXEL),
        );
        let name = format!("{}.xml", p.stem());
        stdx::fs::write_atomic(&dir.join(&name), xml.as_bytes())?;
        files.push(name);
    }
    Ok(files)
}
