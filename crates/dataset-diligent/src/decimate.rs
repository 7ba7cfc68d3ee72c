//! Mesh decimation to a target vertex count by quadric-error edge collapse (Garland and
//! Heckbert, "Surface Simplification Using Quadric Error Metrics", SIGGRAPH 1997), as the paper
//! decimates DiLiGenT-MV's ~1e6-vertex ground-truth meshes to ~1e5 vertices.
//!
//! Each vertex carries the sum of the area-weighted plane quadrics of its triangles (plus
//! perpendicular planes along boundary edges, weighted [`DecimateOptions::boundary_weight`] times,
//! so open borders stay in place). Edges are collapsed cheapest first from a lazily invalidated
//! heap; the merged vertex goes to the quadric's minimiser when the 3 x 3 system is well
//! conditioned and stays near the edge, otherwise to the best of the two ends and the midpoint.
//!
//! A collapse is refused when it would break the mesh: the edge has more than two triangles,
//! the link condition fails (the ends share a neighbour that is not opposite the edge), an
//! interior edge joins two boundary vertices, or a surrounding triangle would degenerate or turn
//! by more than [`DecimateOptions::max_normal_turn_deg`]. So a manifold input stays manifold.
//! Normals are not kept: they are recomputed from the result (mesh-encoding's vertex normals,
//! which the ray-casting precompute uses), as the paper does.
//!
//! Pure Rust, no dependency: `meshopt` would need a C++ build (cc) on CI's two cores for one
//! function.

use glam::{DMat3, DVec3, Vec3};
use mesh_encoding::TriMesh;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Settings of [`decimate`].
///
/// | field | default | meaning |
/// | --- | --- | --- |
/// | `target_vertices` | 100 000 | stop when this many vertices remain |
/// | `boundary_weight` | 1000 | weight of the planes that hold boundary edges in place |
/// | `max_normal_turn_deg` | 75 | largest rotation of a triangle's normal in one collapse |
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DecimateOptions {
    /// Vertex count to reach.
    pub target_vertices: usize,
    /// Boundary plane weight (relative to the area weighting of the surface planes).
    pub boundary_weight: f64,
    /// Largest normal rotation allowed per collapse, degrees.
    pub max_normal_turn_deg: f64,
}

impl Default for DecimateOptions {
    fn default() -> Self {
        Self { target_vertices: 100_000, boundary_weight: 1000.0, max_normal_turn_deg: 75.0 }
    }
}

/// What [`decimate`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DecimateReport {
    /// Referenced vertices before.
    pub vertices_before: usize,
    /// Vertices after.
    pub vertices_after: usize,
    /// Triangles before.
    pub triangles_before: usize,
    /// Triangles after.
    pub triangles_after: usize,
    /// Collapses done.
    pub collapses: usize,
    /// Candidate collapses refused by the topology or normal checks.
    pub refused: usize,
    /// Square root of the largest quadric error of a collapse done (a distance, mesh units).
    pub max_error: f64,
}

/// A symmetric 4 x 4 quadric: a00 a01 a02 a03 a11 a12 a13 a22 a23 a33.
#[derive(Clone, Copy, Debug, Default)]
struct Quadric([f64; 10]);

impl Quadric {
    /// w (n . x + d)^2.
    fn plane(n: DVec3, d: f64, w: f64) -> Self {
        Self([
            w * n.x * n.x,
            w * n.x * n.y,
            w * n.x * n.z,
            w * n.x * d,
            w * n.y * n.y,
            w * n.y * n.z,
            w * n.y * d,
            w * n.z * n.z,
            w * n.z * d,
            w * d * d,
        ])
    }

    fn add(&self, o: &Self) -> Self {
        let mut r = self.0;
        r.iter_mut().zip(&o.0).for_each(|(a, b)| *a += b);
        Self(r)
    }

    fn eval(&self, p: DVec3) -> f64 {
        let a = &self.0;
        let quad = a[0] * p.x * p.x
            + a[4] * p.y * p.y
            + a[7] * p.z * p.z
            + 2.0 * (a[1] * p.x * p.y + a[2] * p.x * p.z + a[5] * p.y * p.z);
        (quad + 2.0 * (a[3] * p.x + a[6] * p.y + a[8] * p.z) + a[9]).max(0.0)
    }

    /// The minimiser, when the system is well conditioned.
    fn optimum(&self) -> Option<DVec3> {
        let a = &self.0;
        let m = DMat3::from_cols(
            DVec3::new(a[0], a[1], a[2]),
            DVec3::new(a[1], a[4], a[5]),
            DVec3::new(a[2], a[5], a[7]),
        );
        let trace = a[0] + a[4] + a[7];
        let det = m.determinant();
        if !(trace > 0.0 && det.abs() > 1e-9 * trace * trace * trace) {
            return None;
        }
        let p = m.inverse() * -DVec3::new(a[3], a[6], a[8]);
        p.is_finite().then_some(p)
    }
}

/// A heap entry: collapse b into a at `p`, valid while both stamps are unchanged.
struct Candidate {
    cost: f64,
    a: u32,
    b: u32,
    stamps: (u32, u32),
    p: DVec3,
}

impl PartialEq for Candidate {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for Candidate {}
impl PartialOrd for Candidate {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Candidate {
    /// Reversed, so that the max-heap pops the cheapest; ties by vertex ids (deterministic).
    fn cmp(&self, o: &Self) -> Ordering {
        o.cost.total_cmp(&self.cost).then((o.a, o.b).cmp(&(self.a, self.b)))
    }
}

struct State {
    pos: Vec<DVec3>,
    quadric: Vec<Quadric>,
    tris: Vec<[u32; 3]>,
    tri_dead: Vec<bool>,
    vtris: Vec<Vec<u32>>,
    stamp: Vec<u32>,
    cos_turn: f64,
}

impl State {
    fn normal(&self, t: [u32; 3], moved: u32, to: DVec3) -> DVec3 {
        let p = t.map(|v| if v == moved { to } else { self.pos[v as usize] });
        (p[1] - p[0]).cross(p[2] - p[0])
    }

    /// Neighbours of v (sorted, unique) into `out`.
    fn neighbours(&self, v: u32, out: &mut Vec<u32>) {
        out.clear();
        for &t in &self.vtris[v as usize] {
            out.extend(self.tris[t as usize].iter().copied().filter(|&u| u != v));
        }
        out.sort_unstable();
        out.dedup();
    }

    /// Whether v lies on a boundary: some edge at v has one triangle.
    fn on_boundary(&self, v: u32, scratch: &mut Vec<u32>) -> bool {
        scratch.clear();
        for &t in &self.vtris[v as usize] {
            scratch.extend(self.tris[t as usize].iter().copied().filter(|&u| u != v));
        }
        scratch.sort_unstable();
        // Every neighbour of an interior vertex appears twice.
        let mut i = 0;
        while i < scratch.len() {
            let mut j = i;
            while j < scratch.len() && scratch[j] == scratch[i] {
                j += 1;
            }
            if j - i == 1 {
                return true;
            }
            i = j;
        }
        false
    }

    fn candidate(&self, a: u32, b: u32) -> Candidate {
        let q = self.quadric[a as usize].add(&self.quadric[b as usize]);
        let (pa, pb) = (self.pos[a as usize], self.pos[b as usize]);
        let mid = 0.5 * (pa + pb);
        let reach = 2.0 * pa.distance(pb);
        let mut best = (q.eval(mid), mid);
        for p in [pa, pb].into_iter().chain(q.optimum().filter(|p| p.distance(mid) <= reach)) {
            let c = q.eval(p);
            if c < best.0 {
                best = (c, p);
            }
        }
        let stamps = (self.stamp[a as usize], self.stamp[b as usize]);
        Candidate { cost: best.0, a, b, stamps, p: best.1 }
    }

    /// Checks the collapse of b into a at p; returns the triangles of the edge.
    fn allowed(&self, a: u32, b: u32, p: DVec3, s: &mut [Vec<u32>; 3]) -> Option<Vec<u32>> {
        let shared: Vec<u32> = self.vtris[a as usize]
            .iter()
            .copied()
            .filter(|&t| self.tris[t as usize].contains(&b))
            .collect();
        if shared.is_empty() || shared.len() > 2 {
            return None;
        }
        let [na, nb, opp] = s;
        self.neighbours(a, na);
        self.neighbours(b, nb);
        opp.clear();
        for &t in &shared {
            opp.extend(self.tris[t as usize].iter().copied().filter(|&u| u != a && u != b));
        }
        opp.sort_unstable();
        let common = na.iter().filter(|u| nb.binary_search(u).is_ok()).count();
        if common != opp.len() || opp.iter().any(|u| na.binary_search(u).is_err()) {
            return None;
        }
        if shared.len() == 2 && self.on_boundary(a, na) && self.on_boundary(b, nb) {
            return None;
        }
        for (v, other) in [(a, b), (b, a)] {
            for &t in &self.vtris[v as usize] {
                let tri = self.tris[t as usize];
                if tri.contains(&other) {
                    continue;
                }
                let before = self.normal(tri, u32::MAX, DVec3::ZERO);
                let after = self.normal(tri, v, p);
                let (lb, la) = (before.length(), after.length());
                if la <= 1e-12 * lb.max(f64::MIN_POSITIVE) || la == 0.0 {
                    return None;
                }
                if lb > 0.0 && before.dot(after) < self.cos_turn * lb * la {
                    return None;
                }
            }
        }
        Some(shared)
    }

    fn collapse(&mut self, a: u32, b: u32, p: DVec3, shared: &[u32]) {
        for &t in shared {
            self.tri_dead[t as usize] = true;
            for v in self.tris[t as usize] {
                self.vtris[v as usize].retain(|&u| u != t);
            }
        }
        let moved = std::mem::take(&mut self.vtris[b as usize]);
        for &t in &moved {
            for v in &mut self.tris[t as usize] {
                if *v == b {
                    *v = a;
                }
            }
        }
        self.vtris[a as usize].extend(moved);
        self.pos[a as usize] = p;
        self.quadric[a as usize] = self.quadric[a as usize].add(&self.quadric[b as usize]);
        self.stamp[a as usize] += 1;
        self.stamp[b as usize] += 1;
    }
}

/// Decimates `mesh` to at most `options.target_vertices` vertices (fewer collapses when the
/// checks refuse the rest; the report says how many remain). A mesh already small enough is
/// returned unchanged (unreferenced vertices dropped).
pub fn decimate(mesh: &TriMesh, options: &DecimateOptions) -> (TriMesh, DecimateReport) {
    let (mut st, edges) = State::new(mesh, options);
    let vertices_before = st.vtris.iter().filter(|t| !t.is_empty()).count();
    let mut report =
        DecimateReport { vertices_before, triangles_before: st.tris.len(), ..Default::default() };
    let alive = st.collapse_until(vertices_before, options.target_vertices, &edges, &mut report);
    let out = st.compact(alive);
    report.vertices_after = out.positions.len();
    report.triangles_after = out.triangles.len();
    (out, report)
}

impl State {
    /// The state of `mesh` (degenerate triangles dropped) with every vertex's quadric: its
    /// triangles' planes weighted by area, plus the boundary planes; and the unique edges.
    fn new(mesh: &TriMesh, options: &DecimateOptions) -> (Self, Vec<(u32, u32)>) {
        let n = mesh.positions.len();
        let tris: Vec<[u32; 3]> = mesh
            .triangles
            .iter()
            .copied()
            .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
            .collect();
        let mut st = State {
            pos: mesh.positions.iter().map(|p| p.as_dvec3()).collect(),
            quadric: vec![Quadric::default(); n],
            tri_dead: vec![false; tris.len()],
            vtris: vec![Vec::new(); n],
            stamp: vec![0; n],
            tris,
            cos_turn: options.max_normal_turn_deg.to_radians().cos(),
        };
        let mut edges: Vec<(u32, u32, u32)> = Vec::with_capacity(3 * st.tris.len());
        for (ti, t) in st.tris.iter().enumerate() {
            let c = (st.pos[t[1] as usize] - st.pos[t[0] as usize])
                .cross(st.pos[t[2] as usize] - st.pos[t[0] as usize]);
            let area = 0.5 * c.length();
            if let Some(nrm) = c.try_normalize() {
                let q = Quadric::plane(nrm, -nrm.dot(st.pos[t[0] as usize]), area);
                for &v in t {
                    st.quadric[v as usize] = st.quadric[v as usize].add(&q);
                }
            }
            for k in 0..3 {
                st.vtris[t[k] as usize].push(ti as u32);
                let (u, v) = (t[k], t[(k + 1) % 3]);
                edges.push((u.min(v), u.max(v), ti as u32));
            }
        }
        edges.sort_unstable();
        let unique = st.add_boundary_planes(&edges, options.boundary_weight);
        (st, unique)
    }

    /// Adds, for every boundary edge (one with a single triangle), the plane through it
    /// perpendicular to its triangle, weighted by `weight` times its squared length, to both
    /// end vertices. `edges` are (min vertex, max vertex, triangle), sorted; returns the unique
    /// edges.
    fn add_boundary_planes(&mut self, edges: &[(u32, u32, u32)], weight: f64) -> Vec<(u32, u32)> {
        let mut i = 0;
        let mut unique = Vec::with_capacity(edges.len() / 2);
        while i < edges.len() {
            let mut j = i + 1;
            while j < edges.len() && edges[j].0 == edges[i].0 && edges[j].1 == edges[i].1 {
                j += 1;
            }
            let (u, v, t) = edges[i];
            unique.push((u, v));
            if j - i == 1 {
                let tri = self.tris[t as usize];
                let fnrm = self.normal(tri, u32::MAX, DVec3::ZERO);
                let e = self.pos[v as usize] - self.pos[u as usize];
                if let Some(bn) = e.cross(fnrm).try_normalize() {
                    let w = weight * e.length_squared();
                    let q = Quadric::plane(bn, -bn.dot(self.pos[u as usize]), w);
                    for x in [u, v] {
                        self.quadric[x as usize] = self.quadric[x as usize].add(&q);
                    }
                }
            }
            i = j;
        }
        unique
    }

    /// Collapses the cheapest allowed edges until `target` of the `alive` vertices remain (or
    /// no candidate is left); returns the vertices alive.
    fn collapse_until(
        &mut self,
        mut alive: usize,
        target: usize,
        edges: &[(u32, u32)],
        report: &mut DecimateReport,
    ) -> usize {
        if alive <= target {
            return alive;
        }
        let mut heap: BinaryHeap<Candidate> =
            edges.iter().map(|&(u, v)| self.candidate(u, v)).collect();
        let mut scratch = [Vec::new(), Vec::new(), Vec::new()];
        let mut nbrs = Vec::new();
        while alive > target {
            let Some(c) = heap.pop() else { break };
            let (a, b) = (c.a, c.b);
            if (self.stamp[a as usize], self.stamp[b as usize]) != c.stamps
                || self.vtris[a as usize].is_empty()
                || self.vtris[b as usize].is_empty()
            {
                continue;
            }
            let Some(shared) = self.allowed(a, b, c.p, &mut scratch) else {
                report.refused += 1;
                continue;
            };
            self.collapse(a, b, c.p, &shared);
            alive -= 1;
            report.collapses += 1;
            report.max_error = report.max_error.max(c.cost.sqrt());
            self.neighbours(a, &mut nbrs);
            for &u in &nbrs {
                heap.push(self.candidate(a, u));
            }
        }
        alive
    }

    /// The mesh of the live vertices and triangles, vertices renumbered in order.
    fn compact(&self, alive: usize) -> TriMesh {
        let mut remap = vec![u32::MAX; self.pos.len()];
        let mut positions = Vec::with_capacity(alive);
        for (v, slot) in remap.iter_mut().enumerate() {
            if !self.vtris[v].is_empty() {
                *slot = positions.len() as u32;
                positions.push(self.pos[v].as_vec3());
            }
        }
        let triangles: Vec<[u32; 3]> = self
            .tris
            .iter()
            .zip(&self.tri_dead)
            .filter(|(_, d)| !**d)
            .map(|(t, _)| t.map(|v| remap[v as usize]))
            .collect();
        TriMesh { positions, triangles }
    }
}

/// The decimated mesh's vertex normals, recomputed (angle-weighted), for callers that want them
/// explicitly; the ray-casting precompute recomputes the same normals itself.
pub fn recomputed_normals(mesh: &TriMesh) -> Vec<Vec3> {
    mesh.vertex_normals(mesh_encoding::NormalWeighting::Angle)
}

#[cfg(test)]
mod tests {
    use super::*;
    use mesh_encoding::Topology;

    /// A closed UV sphere of radius 1.
    fn sphere(rings: u32, segs: u32) -> TriMesh {
        let mut p = vec![Vec3::Z];
        for i in 1..rings {
            let th = std::f32::consts::PI * i as f32 / rings as f32;
            for j in 0..segs {
                let ph = std::f32::consts::TAU * j as f32 / segs as f32;
                p.push(Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()));
            }
        }
        p.push(-Vec3::Z);
        let idx = |i: u32, j: u32| 1 + (i - 1) * segs + j % segs;
        let last = p.len() as u32 - 1;
        let mut t = Vec::new();
        for j in 0..segs {
            t.push([0, idx(1, j), idx(1, j + 1)]);
            t.push([last, idx(rings - 1, j + 1), idx(rings - 1, j)]);
        }
        for i in 1..rings - 1 {
            for j in 0..segs {
                let (a, b, c, d) = (idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1));
                t.push([a, b, c]);
                t.push([a, c, d]);
            }
        }
        TriMesh::new(p, t).unwrap()
    }

    #[test]
    fn sphere_decimates_to_target_stays_closed_and_round() {
        let m = sphere(60, 120);
        let before = Topology::of(&m);
        assert!(before.is_closed_manifold());
        let (d, r) = decimate(&m, &DecimateOptions { target_vertices: 800, ..Default::default() });
        assert_eq!(r.vertices_after, 800, "{r:?}");
        let topo = Topology::of(&d);
        assert!(topo.is_closed_manifold(), "{topo:?}");
        assert_eq!(topo.triangles, 2 * 800 - 4); // Euler: a closed genus-0 surface
        for p in &d.positions {
            assert!((p.length() - 1.0).abs() < 0.02, "{p}");
        }
        let normals = recomputed_normals(&d);
        let worst = d
            .positions
            .iter()
            .zip(&normals)
            .map(|(p, n)| p.normalize().dot(*n))
            .fold(1.0, f32::min);
        assert!(worst > 0.99, "{worst}");
    }

    #[test]
    fn open_border_stays_in_place() {
        // A flat grid with a bump: the border must keep its square outline.
        let n = 40;
        let mut p = Vec::new();
        for i in 0..=n {
            for j in 0..=n {
                let (x, y) = (i as f32 / n as f32, j as f32 / n as f32);
                let z = 0.1 * (-((x - 0.5).powi(2) + (y - 0.5).powi(2)) * 20.0).exp();
                p.push(Vec3::new(x, y, z));
            }
        }
        let mut t = Vec::new();
        let id = |i: u32, j: u32| i * (n + 1) + j;
        for i in 0..n {
            for j in 0..n {
                t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let m = TriMesh::new(p, t).unwrap();
        let (d, r) = decimate(&m, &DecimateOptions { target_vertices: 300, ..Default::default() });
        assert!(r.vertices_after <= 300, "{r:?}");
        let topo = Topology::of(&d);
        assert_eq!((topo.non_manifold_edges, topo.components), (0, 1), "{topo:?}");
        let (lo, hi) = d.bounding_box();
        assert!(lo.x.abs() < 1e-6 && lo.y.abs() < 1e-6 && (hi.x - 1.0).abs() < 1e-6, "{lo} {hi}");
        // Winding kept: every normal points up.
        for k in 0..d.triangles.len() {
            assert!(d.doubled_area_vector(k).z > 0.0);
        }
    }

    #[test]
    fn small_meshes_are_kept() {
        let m = sphere(8, 8);
        let (d, r) = decimate(&m, &DecimateOptions { target_vertices: 1000, ..Default::default() });
        assert_eq!((r.collapses, d.positions.len()), (0, m.positions.len()));
    }
}
