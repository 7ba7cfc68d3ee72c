//! Assembly of the discrete Laplace-Beltrami operator: the cotangent stiffness matrix `L` and the
//! mixed-Voronoi lumped mass matrix `M` (spec section 5.2), as libigl's `cotmatrix` (negated) and
//! `massmatrix(..., MASSMATRIX_TYPE_VORONOI)` build them.
//!
//! * **Stiffness** `L` (symmetric positive semi-definite): every triangle adds, for each of its
//!   edges `(i, j)` with opposite angle `a`, `-cot(a) / 2` to `L[i][j]` and `L[j][i]` and
//!   `+cot(a) / 2` to `L[i][i]` and `L[j][j]`. Rows sum to zero, so constants (one per connected
//!   component) span the kernel. On a boundary edge only one triangle contributes: that is the
//!   natural (Neumann) boundary condition of the weak form, nothing else is needed.
//! * **Mass** `M` (diagonal, Meyer et al. 2003): a non-obtuse triangle gives each corner its
//!   circumcentric Voronoi share; an obtuse triangle gives its obtuse corner half its area and
//!   the two others a quarter each. The shares of a triangle sum to its area.
//!
//! Cotangents are computed as `dot / |cross|` of the two edge vectors in f64. A triangle whose
//! doubled area is zero or not finite (collinear corners) is skipped and counted in
//! [`LboMatrices::skipped_triangles`]: it contributes nothing rather than an infinite or NaN
//! cotangent. A vertex left with zero mass (unreferenced, or only in skipped triangles) makes
//! `M` singular and is an error; [`crate::TriMesh::cleanup`] removes such vertices.

use faer::sparse::{SparseColMat, Triplet};

use crate::TriMesh;
use crate::error::{Error, Result};

/// The stiffness and mass matrices of a triangle mesh.
#[derive(Debug, Clone)]
pub struct LboMatrices {
    /// Cotangent stiffness `L`, `n x n`, both triangles stored; positive semi-definite.
    pub stiffness: SparseColMat<usize, f64>,
    /// Diagonal of the lumped mass matrix `M` (mixed Voronoi areas), one positive entry per
    /// vertex; sums to the surface area of the non-skipped triangles.
    pub mass: Vec<f64>,
    /// Triangles with zero or non-finite area that were left out.
    pub skipped_triangles: usize,
}

impl LboMatrices {
    /// The product `L X` of the stiffness matrix with a dense block of columns.
    pub fn stiffness_times(&self, x: faer::MatRef<'_, f64>, par: faer::Par) -> faer::Mat<f64> {
        let mut out = faer::Mat::<f64>::zeros(x.nrows(), x.ncols());
        faer::sparse::linalg::matmul::sparse_dense_matmul(
            out.as_mut(),
            faer::Accum::Replace,
            self.stiffness.as_ref(),
            x,
            1.0,
            par,
        );
        out
    }

    /// Assembles `L` and `M` from vertex positions and triangles.
    ///
    /// # Errors
    /// [`Error::Lbo`] when there are no triangles, an index is out of range, a coordinate is
    /// not finite, or a vertex gets zero mass (unreferenced or only in degenerate triangles).
    pub fn assemble(vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> Result<Self> {
        let n = vertices.len();
        if n == 0 || triangles.is_empty() {
            return Err(Error::lbo("the mesh has no vertices or no triangles"));
        }
        if let Some(v) = vertices.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
            return Err(Error::lbo(format!("vertex {v} has a non-finite coordinate")));
        }
        let mut triplets = Vec::with_capacity(triangles.len() * 12);
        let mut mass = vec![0.0; n];
        let mut skipped_triangles = 0;
        for (t, tri) in triangles.iter().enumerate() {
            if let Some(&i) = tri.iter().find(|&&i| i as usize >= n) {
                return Err(Error::lbo(format!(
                    "triangle {t} refers to vertex {i}, out of range for {n} vertices"
                )));
            }
            let idx = tri.map(|i| i as usize);
            let p = idx.map(|i| vertices[i]);
            let Some(local) = triangle_terms(p) else {
                skipped_triangles += 1;
                continue;
            };
            for c in 0..3 {
                // Edge opposite corner c joins corners c+1 and c+2.
                let (i, j) = (idx[(c + 1) % 3], idx[(c + 2) % 3]);
                let w = 0.5 * local.cot[c];
                triplets.push(Triplet::new(i, j, -w));
                triplets.push(Triplet::new(j, i, -w));
                triplets.push(Triplet::new(i, i, w));
                triplets.push(Triplet::new(j, j, w));
                mass[idx[c]] += local.mass[c];
            }
        }
        if let Some(v) = mass.iter().position(|&m| m.is_nan() || m <= 0.0) {
            return Err(Error::lbo(format!(
                "vertex {v} has zero mass (unreferenced or only in degenerate triangles); \
                 run TriMesh::cleanup first"
            )));
        }
        let stiffness = SparseColMat::try_new_from_triplets(n, n, &triplets)
            .map_err(|e| Error::lbo(format!("cannot build the stiffness matrix: {e:?}")))?;
        Ok(LboMatrices { stiffness, mass, skipped_triangles })
    }

    /// Assembles `L` and `M` for a [`TriMesh`] (positions widened to f64).
    ///
    /// # Errors
    /// As [`LboMatrices::assemble`]; a cleaned-up mesh only fails if it is empty.
    pub fn from_mesh(mesh: &TriMesh) -> Result<Self> {
        let vertices: Vec<[f64; 3]> =
            mesh.positions.iter().map(|p| p.as_dvec3().to_array()).collect();
        Self::assemble(&vertices, &mesh.triangles)
    }

    /// Number of vertices `n`.
    pub fn vertex_count(&self) -> usize {
        self.mass.len()
    }

    /// Total mass (the surface area of the non-skipped triangles).
    pub fn total_mass(&self) -> f64 {
        self.mass.iter().sum()
    }

    /// `y = L x` for a single vector.
    ///
    /// # Panics
    /// If `x` or `y` does not have `n` entries.
    pub fn apply_stiffness(&self, x: &[f64], y: &mut [f64]) {
        let n = self.vertex_count();
        assert!(x.len() == n && y.len() == n, "vector length must equal the vertex count");
        y.fill(0.0);
        let l = self.stiffness.as_ref();
        for (j, &xj) in x.iter().enumerate() {
            for (i, &v) in l.row_idx_of_col(j).zip(l.val_of_col(j)) {
                y[i] += v * xj;
            }
        }
    }
}

/// Per-triangle contributions: cotangent of each corner's angle and each corner's mass share.
struct TriangleTerms {
    cot: [f64; 3],
    mass: [f64; 3],
}

/// Cotangents and mixed-Voronoi shares of one triangle, `None` when it is degenerate.
fn triangle_terms(p: [[f64; 3]; 3]) -> Option<TriangleTerms> {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    };
    let e1 = sub(p[1], p[0]);
    let e2 = sub(p[2], p[0]);
    let cr = cross(e1, e2);
    let dbl_area = dot(cr, cr).sqrt();
    if dbl_area.is_nan() || dbl_area <= 0.0 || !dbl_area.is_finite() {
        return None;
    }
    let mut cot = [0.0; 3];
    let mut cos = [0.0; 3];
    let mut len = [0.0; 3];
    for c in 0..3 {
        let a = sub(p[(c + 1) % 3], p[c]);
        let b = sub(p[(c + 2) % 3], p[c]);
        let d = dot(a, b);
        cot[c] = d / dbl_area;
        cos[c] = d / (dot(a, a) * dot(b, b)).sqrt();
        let opposite = sub(p[(c + 2) % 3], p[(c + 1) % 3]);
        len[c] = dot(opposite, opposite).sqrt();
    }
    let area = 0.5 * dbl_area;
    let mass = if let Some(obtuse) = (0..3).find(|&c| cos[c] < 0.0) {
        let mut m = [0.25 * area; 3];
        m[obtuse] = 0.5 * area;
        m
    } else {
        // Circumcentre barycentrics are proportional to l_c cos(A_c); `partial[c]` is the area of
        // the sub-triangle (circumcentre, edge opposite c), and a corner gets half of the two
        // sub-triangles next to it.
        let bary = [len[0] * cos[0], len[1] * cos[1], len[2] * cos[2]];
        let sum = bary[0] + bary[1] + bary[2];
        let partial = bary.map(|b| b / sum * area);
        [
            0.5 * (partial[1] + partial[2]),
            0.5 * (partial[2] + partial[0]),
            0.5 * (partial[0] + partial[1]),
        ]
    };
    if cot.iter().chain(&mass).any(|v| !v.is_finite()) {
        return None;
    }
    Some(TriangleTerms { cot, mass })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[allow(clippy::needless_range_loop)]
    fn dense(l: &SparseColMat<usize, f64>) -> Vec<Vec<f64>> {
        let n = l.nrows();
        let mut d = vec![vec![0.0; n]; n];
        let l = l.as_ref();
        for j in 0..n {
            for (i, &v) in l.row_idx_of_col(j).zip(l.val_of_col(j)) {
                d[i][j] += v;
            }
        }
        d
    }

    #[test]
    fn right_isoceles_triangle_matches_hand_values() {
        // Angles 90 deg at vertex 0, 45 deg at 1 and 2: cot = 0, 1, 1.
        let m = LboMatrices::assemble(
            &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            &[[0, 1, 2]],
        )
        .unwrap();
        let d = dense(&m.stiffness);
        // Edge (1, 2) is opposite the right angle: weight 0; edges (0, 2), (0, 1) weight 1/2.
        assert!((d[1][2]).abs() < 1e-15);
        assert!((d[0][1] + 0.5).abs() < 1e-15 && (d[0][2] + 0.5).abs() < 1e-15);
        assert!((d[0][0] - 1.0).abs() < 1e-15 && (d[1][1] - 0.5).abs() < 1e-15);
        // Right triangle: circumcentre at the hypotenuse midpoint; corner 0 gets 1/4, the others
        // 1/8 each.
        assert!((m.mass[0] - 0.25).abs() < 1e-15, "{:?}", m.mass);
        assert!((m.mass[1] - 0.125).abs() < 1e-15 && (m.mass[2] - 0.125).abs() < 1e-15);
    }

    #[test]
    fn obtuse_and_equilateral_mass_shares() {
        let s = 3f64.sqrt();
        let eq =
            LboMatrices::assemble(&[[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, s, 0.0]], &[[0, 1, 2]])
                .unwrap();
        for m in &eq.mass {
            assert!((m - s / 3.0).abs() < 1e-14);
        }
        // Obtuse at vertex 2 (apex at height 0.1): area 0.1.
        let ob = LboMatrices::assemble(
            &[[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, 0.1, 0.0]],
            &[[0, 1, 2]],
        )
        .unwrap();
        assert!((ob.mass[2] - 0.05).abs() < 1e-15 && (ob.mass[0] - 0.025).abs() < 1e-15);
        assert!((ob.total_mass() - 0.1).abs() < 1e-15);
    }

    #[test]
    fn degenerate_triangles_are_skipped_and_rows_sum_to_zero() {
        let v = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [2.0, 0.0, 0.0]];
        // Triangle [0, 1, 3] is collinear; every vertex still has a proper triangle.
        let m = LboMatrices::assemble(&v, &[[0, 1, 2], [1, 3, 2], [0, 1, 3], [1, 1, 2]]).unwrap();
        assert_eq!(m.skipped_triangles, 2);
        let d = dense(&m.stiffness);
        for row in &d {
            assert!(row.iter().all(|x| x.is_finite()));
            assert!(row.iter().sum::<f64>().abs() < 1e-14);
        }
        for (i, row) in d.iter().enumerate() {
            for (j, x) in row.iter().enumerate() {
                assert_eq!(*x, d[j][i]);
            }
        }
    }

    #[test]
    fn unreferenced_vertex_is_an_error() {
        let e = LboMatrices::assemble(
            &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [5.0, 5.0, 5.0]],
            &[[0, 1, 2]],
        )
        .unwrap_err();
        assert!(e.to_string().contains("vertex 3") && e.to_string().contains("cleanup"), "{e}");
        let e = LboMatrices::assemble(&[[0.0; 3]; 3], &[[0, 1, 7]]).unwrap_err();
        assert!(e.to_string().contains("out of range"), "{e}");
    }

    #[test]
    fn stiffness_quadratic_form_is_the_dirichlet_energy_of_a_linear_function() {
        // For f linear, f^T L f = integral |grad f|^2 over the (flat) mesh.
        let v =
            [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 1.0, 0.0], [0.0, 1.0, 0.0], [0.7, 0.4, 0.0]];
        let t = [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]];
        let m = LboMatrices::assemble(&v, &t).unwrap();
        let f: Vec<f64> = v.iter().map(|p| 3.0 * p[0] - 2.0 * p[1]).collect();
        let mut lf = vec![0.0; 5];
        m.apply_stiffness(&f, &mut lf);
        let energy: f64 = f.iter().zip(&lf).map(|(a, b)| a * b).sum();
        assert!((energy - 13.0 * 2.0).abs() < 1e-12, "{energy}");
        assert!((m.total_mass() - 2.0).abs() < 1e-14);
    }
}
