//! Small analytic meshes the scene, capture and training tests build their scenes on.

use std::fmt::Write;
use std::path::{Path, PathBuf};

/// OBJ text of a UV sphere (radius 0.5, centre (0, 0, 0.7); `rings` x `segs` quads, the poles
/// as triangle fans) above the square plane z = 0, |x|, |y| <= 1.5: the sphere shadows the
/// plane under any light above it.
pub fn sphere_over_plane_obj(rings: usize, segs: usize) -> String {
    let mut obj = String::new();
    for i in 0..=rings {
        let th = std::f64::consts::PI * i as f64 / rings as f64;
        for j in 0..segs {
            let ph = std::f64::consts::TAU * j as f64 / segs as f64;
            let (x, y, z) = (th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos());
            let _ = writeln!(obj, "v {} {} {}", 0.5 * x, 0.5 * y, 0.7 + 0.5 * z);
        }
    }
    let idx = |i: usize, j: usize| i * segs + (j % segs) + 1;
    for i in 0..rings {
        for j in 0..segs {
            let (a, b, c, d) = (idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1));
            if i != 0 {
                let _ = writeln!(obj, "f {a} {b} {d}");
            }
            if i != rings - 1 {
                let _ = writeln!(obj, "f {b} {c} {d}");
            }
        }
    }
    let base = (rings + 1) * segs;
    for (x, y) in [(-1.5, -1.5), (1.5, -1.5), (1.5, 1.5), (-1.5, 1.5)] {
        let _ = writeln!(obj, "v {x} {y} 0");
    }
    let (p, q, r, s) = (base + 1, base + 2, base + 3, base + 4);
    let _ = writeln!(obj, "f {p} {q} {r}\nf {p} {r} {s}");
    obj
}

/// [`sphere_over_plane_obj`] written to `dir/sphere_plane.obj`; returns the path.
pub fn write_sphere_over_plane(dir: &Path, rings: usize, segs: usize) -> PathBuf {
    let path = dir.join("sphere_plane.obj");
    std::fs::write(&path, sphere_over_plane_obj(rings, segs))
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    path
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_sphere_over_plane_has_its_vertices_and_faces() {
        let obj = super::sphere_over_plane_obj(4, 8);
        let count = |p: &str| obj.lines().filter(|l| l.starts_with(p)).count();
        assert_eq!(count("v "), 5 * 8 + 4);
        // Two triangles a quad, one at the pole rows, and the plane's two.
        assert_eq!(count("f "), 4 * 8 * 2 - 2 * 8 + 2);
    }
}
