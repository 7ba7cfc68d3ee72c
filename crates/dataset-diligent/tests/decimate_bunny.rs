//! Decimation of a real shared mesh (the Stanford bunny, ~35k vertices, to 5 000): the target
//! is reached, the surface stays manifold with its borders, and the two-sided surface distance
//! (a Hausdorff estimate over vertices) stays small against the mesh's size.

mod common;

use dataset_diligent::decimate::{DecimateOptions, decimate, recomputed_normals};
use glam::Vec3;
use mesh_encoding::{LoadOptions, Topology, TriMesh, load_mesh};
use std::collections::HashMap;

/// Closest point on triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5).
fn closest_on_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

/// Distances from points to a mesh's surface through a uniform grid of triangles.
struct SurfaceGrid<'a> {
    mesh: &'a TriMesh,
    cell: f32,
    cells: HashMap<[i32; 3], Vec<u32>>,
}

impl<'a> SurfaceGrid<'a> {
    fn new(mesh: &'a TriMesh, cell: f32) -> Self {
        let mut cells: HashMap<[i32; 3], Vec<u32>> = HashMap::new();
        let key = |p: Vec3| (p / cell).floor().as_ivec3().to_array();
        for t in 0..mesh.triangles.len() {
            let c = mesh.corners(t);
            let (lo, hi) = (key(c[0].min(c[1]).min(c[2])), key(c[0].max(c[1]).max(c[2])));
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        cells.entry([x, y, z]).or_default().push(t as u32);
                    }
                }
            }
        }
        Self { mesh, cell, cells }
    }

    fn distance(&self, p: Vec3) -> f32 {
        let k = (p / self.cell).floor().as_ivec3();
        let mut best = f32::INFINITY;
        for ring in 0i32..64 {
            for x in -ring..=ring {
                for y in -ring..=ring {
                    for z in -ring..=ring {
                        if x.abs().max(y.abs()).max(z.abs()) != ring {
                            continue;
                        }
                        let key = [k.x + x, k.y + y, k.z + z];
                        for &t in self.cells.get(&key).map(Vec::as_slice).unwrap_or_default() {
                            let c = self.mesh.corners(t as usize);
                            best = best.min(p.distance(closest_on_triangle(p, c[0], c[1], c[2])));
                        }
                    }
                }
            }
            if best <= ring as f32 * self.cell {
                break;
            }
        }
        best
    }
}

fn one_sided(from: &TriMesh, to: &TriMesh, cell: f32) -> (f32, f32) {
    let grid = SurfaceGrid::new(to, cell);
    let d: Vec<f32> = from.positions.iter().map(|&p| grid.distance(p)).collect();
    (d.iter().sum::<f32>() / d.len() as f32, d.iter().copied().fold(0.0, f32::max))
}

#[test]
fn bunny_decimates_to_5000_vertices_with_small_error() {
    let Some(dir) = common::shared("meshes") else { return };
    let mesh = load_mesh(dir.join("stanford-bunny.obj"), &LoadOptions::default()).unwrap().mesh;
    let before = Topology::of(&mesh);
    let start = std::time::Instant::now();
    let (d, r) = decimate(&mesh, &DecimateOptions { target_vertices: 5000, ..Default::default() });
    let seconds = start.elapsed().as_secs_f64();
    let after = Topology::of(&d);
    let diag = mesh.diagonal();
    let cell = 0.01 * diag;
    let (mean_fwd, max_fwd) = one_sided(&mesh, &d, cell);
    let (mean_bwd, max_bwd) = one_sided(&d, &mesh, cell);
    eprintln!(
        "bunny: {} -> {} vertices, {} -> {} triangles in {seconds:.2} s ({} collapses, {} refused); \
         topology before {before:?} after {after:?}; surface distance / diagonal: original->decimated \
         mean {:.2e} max {:.2e}, decimated->original mean {:.2e} max {:.2e}",
        r.vertices_before,
        r.vertices_after,
        r.triangles_before,
        r.triangles_after,
        r.collapses,
        r.refused,
        mean_fwd / diag,
        max_fwd / diag,
        mean_bwd / diag,
        max_bwd / diag
    );
    assert_eq!(r.vertices_after, 5000);
    assert_eq!(after.non_manifold_edges, 0, "{after:?}");
    assert!(after.components <= before.components, "{before:?} {after:?}");
    assert!(max_fwd.max(max_bwd) < 0.01 * diag && mean_fwd.max(mean_bwd) < 5e-4 * diag);
    // Normals are recomputed from the decimated surface: unit and finite.
    assert!(recomputed_normals(&d).iter().all(|n| (n.length() - 1.0).abs() < 1e-4));
}
