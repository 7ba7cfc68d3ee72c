//! Topology statistics of a triangle mesh: connected components, boundary edges and non-manifold
//! edges. An undirected edge used by exactly one triangle is a boundary edge, by more than two a
//! non-manifold edge. Components are vertex-connected sets of triangles (two triangles sharing a
//! vertex are in one component); vertices no triangle uses are not counted.

use super::TriMesh;

/// Topology statistics of a mesh, see the module documentation.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Topology {
    /// Number of vertices.
    pub vertices: usize,
    /// Number of triangles.
    pub triangles: usize,
    /// Number of distinct undirected edges.
    pub edges: usize,
    /// Number of connected components.
    pub components: usize,
    /// Edges used by exactly one triangle.
    pub boundary_edges: usize,
    /// Edges used by three or more triangles.
    pub non_manifold_edges: usize,
}

impl Topology {
    /// Computes the statistics of `mesh`.
    pub fn of(mesh: &TriMesh) -> Self {
        let mut edges: Vec<u64> = Vec::with_capacity(3 * mesh.triangles.len());
        let mut uf = UnionFind::new(mesh.positions.len());
        let mut used = vec![false; mesh.positions.len()];
        for &[a, b, c] in &mesh.triangles {
            for (u, v) in [(a, b), (b, c), (c, a)] {
                let (lo, hi) = if u < v { (u, v) } else { (v, u) };
                edges.push((u64::from(lo) << 32) | u64::from(hi));
            }
            uf.union(a, b);
            uf.union(b, c);
            used[a as usize] = true;
            used[b as usize] = true;
            used[c as usize] = true;
        }
        edges.sort_unstable();
        let mut topo = Topology {
            vertices: mesh.positions.len(),
            triangles: mesh.triangles.len(),
            ..Default::default()
        };
        for run in edges.chunk_by(|a, b| a == b) {
            topo.edges += 1;
            match run.len() {
                1 => topo.boundary_edges += 1,
                2 => {}
                _ => topo.non_manifold_edges += 1,
            }
        }
        topo.components =
            (0..mesh.positions.len()).filter(|&v| used[v] && uf.find(v as u32) == v as u32).count();
        topo
    }

    /// True when every edge has exactly two triangles (closed, edge-manifold surface).
    pub fn is_closed_manifold(&self) -> bool {
        self.boundary_edges == 0 && self.non_manifold_edges == 0
    }
}

/// Union-find with path halving and union by size.
struct UnionFind {
    parent: Vec<u32>,
    size: Vec<u32>,
}

impl UnionFind {
    fn new(n: usize) -> Self {
        UnionFind { parent: (0..n as u32).collect(), size: vec![1; n] }
    }

    fn find(&mut self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            let grand = self.parent[self.parent[x as usize] as usize];
            self.parent[x as usize] = grand;
            x = grand;
        }
        x
    }

    fn union(&mut self, a: u32, b: u32) {
        let (mut ra, mut rb) = (self.find(a), self.find(b));
        if ra == rb {
            return;
        }
        if self.size[ra as usize] < self.size[rb as usize] {
            std::mem::swap(&mut ra, &mut rb);
        }
        self.parent[rb as usize] = ra;
        self.size[ra as usize] += self.size[rb as usize];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn tetrahedron_is_closed() {
        let m = TriMesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z],
            vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        )
        .unwrap();
        let t = Topology::of(&m);
        assert_eq!((t.edges, t.components, t.boundary_edges), (6, 1, 0));
        assert!(t.is_closed_manifold());
    }

    #[test]
    fn two_triangles_apart_and_a_fan_of_three() {
        // Component 1: three triangles sharing edge (0, 1): a non-manifold edge.
        // Component 2: a lone triangle with three boundary edges.
        let p = vec![Vec3::ZERO; 8];
        let m =
            TriMesh { positions: p, triangles: vec![[0, 1, 2], [1, 0, 3], [0, 1, 4], [5, 6, 7]] };
        let t = Topology::of(&m);
        assert_eq!(t.components, 2);
        assert_eq!(t.non_manifold_edges, 1);
        // Edges: (0,1) x3; (1,2),(2,0),(0,3),(3,1),(1,4),(4,0) x1; (5,6),(6,7),(7,5) x1.
        assert_eq!(t.boundary_edges, 9);
        assert_eq!(t.edges, 10);
        assert!(!t.is_closed_manifold());
    }
}
