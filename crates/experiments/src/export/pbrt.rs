//! A pbrt-v4 scene of a fitted material: `object.pbrt` (the material and `mesh.ply` as a
//! `plymesh`) and one `view<v>_light<l>.pbrt` per test pair (camera, film, a `distant` light,
//! direct lighting only: `path` with `maxdepth` 1). Render with `pbrt view003_light002.pbrt`.
//!
//! pbrt-v4 has no Disney material and its `plymesh` carries no per-vertex material values, so
//! the material is the closest built-in one with the object's mean parameters:
//!
//! | fit | pbrt-v4 | lost |
//! | --- | --- | --- |
//! | TS | `coateddiffuse`: `reflectance` rho_d, `roughness` alpha = r^2 (`remaproughness` false), `eta` from mean F0, eta = (1 + sqrt F0) / (1 - sqrt F0) | F0's colour; the coating's layered (energy-conserving) transport replaces TS's sum |
//! | Disney, metallic < 0.5 | `coateddiffuse`: `reflectance` base (1 - metallic), alpha = roughness^2, eta from F0 = 0.08 specular | subsurface, sheen, clear coat, tints |
//! | Disney, metallic >= 0.5 | `conductor`: `reflectance` = base colour, alpha = roughness^2 | the diffuse share, sheen, clear coat |
//! | any spatially varying fit | the mean over the vertices | the variation (use the glTF or Mitsuba export) |
//!
//! Camera: `Scale -1 1 1` then `LookAt C, C + forward, -down` (pbrt's camera space is
//! left-handed), `fov` along the shorter image axis, and a `screenwindow` that puts the
//! principal point where the calibration has it. pbrt-v4 is not installed where this was
//! written: the files follow its file-format documentation and were not rendered by pbrt.

use super::gltf::ExportMesh;
use super::material::{ExportedMaterial, MaterialKind, column};
use super::{ExportCamera, ExportPair};
use crate::Result;
use std::path::Path;

/// eta of a dielectric with normal-incidence reflectance `f0`.
pub fn eta_from_f0(f0: f64) -> f64 {
    let s = f0.clamp(0.0, 0.99).sqrt();
    (1.0 + s) / (1.0 - s)
}

/// The `Material` directive of a row.
pub fn material_directive(kind: MaterialKind, row: &[f32]) -> String {
    let c = |n: &str| column(kind, row, n) as f64;
    let rgb = |v: [f64; 3]| format!("[ {:.9} {:.9} {:.9} ]", v[0], v[1], v[2]);
    match kind {
        MaterialKind::TorranceSparrow => {
            let f0 = (c("f0_r") + c("f0_g") + c("f0_b")) / 3.0;
            format!(
                "Material \"coateddiffuse\"\n    \"rgb reflectance\" {}\n    \"float roughness\" {:.9}\n    \
                 \"bool remaproughness\" false\n    \"float eta\" {:.9}\n",
                rgb([c("diffuse_r"), c("diffuse_g"), c("diffuse_b")]),
                c("roughness").powi(2),
                eta_from_f0(f0)
            )
        }
        MaterialKind::Disney => {
            let base = [c("base_color_r"), c("base_color_g"), c("base_color_b")];
            let alpha = c("roughness").powi(2).max(0.001);
            if c("metallic") >= 0.5 {
                format!(
                    "Material \"conductor\"\n    \"rgb reflectance\" {}\n    \"float roughness\" {alpha:.9}\n    \
                     \"bool remaproughness\" false\n",
                    rgb(base)
                )
            } else {
                let m = c("metallic");
                format!(
                    "Material \"coateddiffuse\"\n    \"rgb reflectance\" {}\n    \"float roughness\" {alpha:.9}\n    \
                     \"bool remaproughness\" false\n    \"float eta\" {:.9}\n",
                    rgb(base.map(|x| x * (1.0 - m))),
                    eta_from_f0(0.08 * c("specular"))
                )
            }
        }
    }
}

/// The camera block of a view.
pub fn camera_block(c: &ExportCamera) -> String {
    let (w, h) = (c.width as f64, c.height as f64);
    let target: Vec<f64> = (0..3).map(|i| c.center[i] + c.forward[i]).collect();
    let up = c.down.map(|x| -x);
    // Screen space spans [-1, 1] along the shorter axis: s units per pixel.
    let (short, f) = if w <= h { (w, c.fx) } else { (h, c.fy) };
    let s = 2.0 / short;
    let fov = 2.0 * (0.5 * short / f).atan().to_degrees();
    format!(
        "Scale -1 1 1\nLookAt {} {} {}\n       {} {} {}\n       {} {} {}\n\
         Camera \"perspective\" \"float fov\" {fov:.9}\n    \"float screenwindow\" [ {:.9} {:.9} {:.9} {:.9} ]\n\
         Film \"rgb\" \"integer xresolution\" {} \"integer yresolution\" {}\n",
        c.center[0],
        c.center[1],
        c.center[2],
        target[0],
        target[1],
        target[2],
        up[0],
        up[1],
        up[2],
        -c.cx * s,
        (w - c.cx) * s,
        -(h - c.cy) * s,
        c.cy * s,
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
    super::ply::write(&dir.join("mesh.ply"), mesh, &[])?;
    let row = material.uniform_or_mean();
    let object = format!(
        "# The fitted material on its mesh (written by neural-brdf experiments export).\nAttributeBegin\n{}Shape \"plymesh\" \"string filename\" \"mesh.ply\"\nAttributeEnd\n",
        material_directive(material.kind, &row)
    );
    stdx::fs::write_atomic(&dir.join("object.pbrt"), object.as_bytes())?;
    let mut files = vec!["mesh.ply".to_string(), "object.pbrt".to_string()];
    for p in pairs {
        let e = p.irradiance;
        let light = match p.position {
            // pbrt-v4's point light: radiant intensity I, inverse-square falloff.
            Some(q) => format!(
                "LightSource \"point\" \"point3 from\" [ {} {} {} ]\n    \"rgb I\" [ {} {} {} ]\n",
                q[0], q[1], q[2], e[0], e[1], e[2]
            ),
            None => {
                let d = p.direction;
                format!(
                    "LightSource \"distant\" \"point3 from\" [ {} {} {} ] \"point3 to\" [ 0 0 0 ]\n    \"rgb L\" [ {} {} {} ]\n",
                    d[0], d[1], d[2], e[0], e[1], e[2]
                )
            }
        };
        let text = format!(
            "{}    \"string filename\" \"{}.exr\"\nSampler \"independent\" \"integer pixelsamples\" 64\n\
             Integrator \"path\" \"integer maxdepth\" 1\nWorldBegin\n{light}\
             Include \"object.pbrt\"\n",
            camera_block(&p.camera),
            p.stem(),
        );
        let name = format!("{}.pbrt", p.stem());
        stdx::fs::write_atomic(&dir.join(&name), text.as_bytes())?;
        files.push(name);
    }
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eta_inverts_schlick_f0() {
        for f0 in [0.02, 0.04, 0.2] {
            let eta = eta_from_f0(f0);
            let back = ((eta - 1.0) / (eta + 1.0)).powi(2);
            assert!((back - f0).abs() < 1e-12, "{f0} {eta} {back}");
        }
        assert!((eta_from_f0(0.04) - 1.5).abs() < 1e-12);
    }
}
