//! Shared helpers of the dataset-diligent tests: temporary directories and the shared data
//! folder.
#![allow(dead_code)]

use std::path::PathBuf;

#[allow(unused_imports)]
pub use test_support::TempDir;

use test_support as support;

/// A folder of the shared data (`NEURAL_BRDF_DATA`, default `<workspace>/../shared/data`); see
/// `test_support::shared_data_root`.
pub fn shared(sub: &str) -> Option<PathBuf> {
    support::shared_data_root(sub).map(|root| root.join(sub))
}

/// A miniature DiLiGenT-MV object written in the exact layout: a Lambertian sphere (albedo
/// [`ALBEDO`], radius 50 mm at [`CENTRE`]) seen by `views` turntable cameras, `lights` lights
/// per view, 64 x 48 16-bit PNGs, text files, masks, per-view `Normal_gt.mat`, a compressed MAT
/// v5 calibration and an ASCII PLY mesh (icosphere level 4, 2562 vertices, in mm). Like the
/// real calibration, the stored rotations are not orthonormal: Rc = [`STRETCH`] Q with the
/// stretch compensated in KK and Tc, so the projection is the true one.
pub mod miniature {
    use dataset_diligent::mat5::write_mat5;
    use glam::{DMat3, DVec3};
    use std::fmt::Write as _;
    use std::path::{Path, PathBuf};

    pub const ALBEDO: [f64; 3] = [0.5, 0.4, 0.3];
    pub const CENTRE: [f64; 3] = [10.0, -20.0, 5.0];
    pub const RADIUS: f64 = 50.0;
    pub const W: u32 = 64;
    pub const H: u32 = 48;
    /// KK (Caltech toolbox convention, pixel centres at integers).
    pub const KK: [[f64; 3]; 3] = [[450.0, 0.0, 31.5], [0.0, 452.0, 23.5], [0.0, 0.0, 1.0]];
    /// The first row of every stored rotation is this much too long (as in DiLiGenT-MV).
    pub const STRETCH: f64 = 1.003458;

    /// Camera v (0-based): on a circle of radius 1500 mm around the centre, looking at it.
    pub fn pose(v: usize) -> (DMat3, DVec3) {
        let c = DVec3::from_array(CENTRE);
        let a = 0.9 * v as f64;
        let eye = c + 1500.0 * DVec3::new(a.cos(), a.sin(), 0.3).normalize();
        let fwd = (c - eye).normalize();
        let right = fwd.cross(DVec3::Z).normalize();
        let down = fwd.cross(right);
        let r = DMat3::from_cols(right, down, fwd).transpose();
        (r, -(r * eye))
    }

    /// Light i of a view, in DiLiGenT's camera frame (x right, y up, z towards the camera).
    pub fn light(i: usize) -> [f64; 3] {
        let a = 1.3 * i as f64;
        DVec3::new(0.5 * a.cos(), 0.5 * a.sin(), 1.0).normalize().to_array()
    }

    /// Light intensity i: red strong enough to saturate the brightest pixels.
    pub fn intensity(i: usize) -> [f64; 3] {
        [2.4, 1.0 + 0.05 * i as f64, 0.8]
    }

    fn sphere_hit(o: DVec3, d: DVec3) -> Option<DVec3> {
        let c = DVec3::from_array(CENTRE);
        let oc = o - c;
        let b = oc.dot(d);
        let disc = b * b - (oc.length_squared() - RADIUS * RADIUS);
        (disc >= 0.0).then(|| o + (-b - disc.sqrt()) * d)
    }

    fn write_png16(path: &Path, px: &[[u16; 3]]) {
        let raw: Vec<u16> = px.iter().flatten().copied().collect();
        let img = image::ImageBuffer::<image::Rgb<u16>, _>::from_raw(W, H, raw).unwrap();
        img.save(path).unwrap();
    }

    /// Writes the object into `root/mvpmsData/miniPNG` and returns that directory.
    pub fn write(root: &Path, views: usize, lights: usize) -> PathBuf {
        let obj = root.join("mvpmsData/miniPNG");
        let k = DMat3::from_cols_array_2d(&KK).transpose();
        let stretch = DMat3::from_diagonal(DVec3::new(STRETCH, 1.0, 1.0));
        let mut vars: Vec<(String, Vec<usize>, Vec<f64>)> = Vec::new();
        let col_major = |m: DMat3| m.to_cols_array().to_vec();
        vars.push(("KK".into(), vec![3, 3], col_major(k * stretch.inverse())));
        vars.push(("kc".into(), vec![5, 1], vec![0.0; 5]));
        for v in 0..views {
            let dir = obj.join(format!("view_{:02}", v + 1));
            std::fs::create_dir_all(&dir).unwrap();
            let (r, t) = pose(v);
            vars.push((format!("Rc_{}", v + 1), vec![3, 3], col_major(stretch * r)));
            vars.push((format!("Tc_{}", v + 1), vec![3, 1], (stretch * t).to_array().to_vec()));
            let centre = -(r.transpose() * t);
            let (mut dirs, mut ints) = (String::new(), String::new());
            for i in 0..lights {
                let l = light(i);
                let e = intensity(i);
                let _ = writeln!(dirs, "{:.6} {:.6} {:.6}", l[0], l[1], l[2]);
                let _ = writeln!(ints, "{} {} {}", e[0], e[1], e[2]);
            }
            std::fs::write(dir.join("light_directions.txt"), dirs).unwrap();
            std::fs::write(dir.join("light_intensities.txt"), ints).unwrap();
            let mut mask = vec![0u8; (W * H * 3) as usize];
            let mut hits = vec![None; (W * H) as usize];
            for p in 0..(W * H) as usize {
                let (i, j) = ((p % W as usize) as f64, (p / W as usize) as f64);
                let d = (r.transpose() * (k.inverse() * DVec3::new(i, j, 1.0))).normalize();
                if let Some(x) = sphere_hit(centre, d) {
                    hits[p] = Some((x - DVec3::from_array(CENTRE)) / RADIUS);
                    mask[3 * p..3 * p + 3].fill(255);
                }
            }
            let m = image::RgbImage::from_raw(W, H, mask).unwrap();
            m.save(dir.join("mask.png")).unwrap();
            // Ground-truth normals in DiLiGenT's camera frame, H x W x 3 column-major.
            let (w, h) = (W as usize, H as usize);
            let mut normals = vec![0.0; w * h * 3];
            for (p, hit) in hits.iter().enumerate() {
                if let Some(n) = hit {
                    let c = r * *n;
                    for (ch, x) in [c.x, -c.y, -c.z].into_iter().enumerate() {
                        normals[p / w + h * (p % w) + h * w * ch] = x;
                    }
                }
            }
            let gt = write_mat5(&[("Normal_gt", &[h, w, 3], &normals)], true);
            std::fs::write(dir.join("Normal_gt.mat"), gt).unwrap();
            for i in 0..lights {
                let lc = light(i);
                let l = (r.transpose() * DVec3::new(lc[0], -lc[1], -lc[2])).normalize();
                let e = intensity(i);
                let px: Vec<[u16; 3]> = hits
                    .iter()
                    .map(|h| match h {
                        Some(n) => {
                            let s = n.dot(l).max(0.0);
                            [0, 1, 2].map(|c| {
                                (65535.0 * ALBEDO[c] * e[c] * s).round().min(65535.0) as u16
                            })
                        }
                        None => [0; 3],
                    })
                    .collect();
                write_png16(&dir.join(format!("{:03}.png", i + 1)), &px);
            }
        }
        let refs: Vec<(&str, &[usize], &[f64])> =
            vars.iter().map(|(n, d, x)| (n.as_str(), d.as_slice(), x.as_slice())).collect();
        std::fs::write(obj.join("Calib_Results.mat"), write_mat5(&refs, true)).unwrap();
        let mesh = dataset_diligent::ball::icosphere(4);
        let mut ply = format!(
            "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\n\
             property float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
            mesh.positions.len(),
            mesh.triangles.len()
        );
        for p in &mesh.positions {
            let q = DVec3::from_array(CENTRE) + RADIUS * p.as_dvec3();
            let _ = writeln!(ply, "{} {} {}", q.x, q.y, q.z);
        }
        for t in &mesh.triangles {
            let _ = writeln!(ply, "3 {} {} {}", t[0], t[1], t[2]);
        }
        std::fs::write(obj.join("mesh_Gt.ply"), ply).unwrap();
        obj
    }
}
