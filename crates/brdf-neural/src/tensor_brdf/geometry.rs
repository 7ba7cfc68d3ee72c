//! Per-sample geometry of the direction pairs, computed on the CPU with exactly the scalar
//! formulas of `brdf-analytic` and uploaded as constant tensors.
//!
//! Every quantity here depends on l and v only, never on a trainable parameter, so computing it
//! outside the autodiff graph loses nothing; it also makes the tensor BRDFs mirror their scalar
//! twins operation for operation. Pairs outside the upper hemisphere are replaced by l = v = n
//! (every term finite) and zeroed through `mask` at the end.

use angles::Vec3;
use brdf_analytic::microfacet::{PairGeometry, schlick_weight};
use burn::tensor::{Device, Tensor, TensorData};

/// FMBRDF's cosine clamp epsilon (official code: 1e-6).
pub(crate) const COS_EPS: f64 = 1e-6;
/// FMBRDF's denominator epsilon (official code: 1e-9).
pub(crate) const DEN_EPS: f64 = 1e-9;

/// Geometry of a batch of local-frame direction pairs; every tensor is `[batch, 1]` unless noted.
#[derive(Clone, Debug)]
pub struct Geometry {
    /// 1 where n.l > 0 and n.v > 0, else 0.
    pub mask: Tensor<2>,
    /// n.l (clamped to at most 1).
    pub nl: Tensor<2>,
    /// n.v (clamped to at most 1).
    pub nv: Tensor<2>,
    /// sin^2(theta_h).
    pub sin2_h: Tensor<2>,
    /// l.h = |l + v| / 2.
    pub lh: Tensor<2>,
    /// Schlick weights (1 - u)^5 of n.l, n.v and l.h, `[batch, 3]` in that order.
    pub schlick: Tensor<2>,
    /// 1 / max(n.l + n.v, 1e-12) (Disney subsurface).
    pub inv_cos_sum: Tensor<2>,
    /// r.v of the mirror direction r of l, clamped into [1e-20, 1] (Realistic Phong).
    pub rv: Tensor<2>,
    /// 1 where r.v > 0, else 0.
    pub rv_positive: Tensor<2>,
    /// FMBRDF terms, when asked for.
    pub fmbrdf: Option<FmbrdfGeometry>,
}

/// The l, v-only terms of FMBRDF (spec section 3.4 and its addendum), each `[batch, 1]` unless
/// noted.
#[derive(Clone, Debug)]
pub struct FmbrdfGeometry {
    /// n.l.
    pub nl: Tensor<2>,
    /// n.v.
    pub nv: Tensor<2>,
    /// n.h.
    pub nh: Tensor<2>,
    /// theta_h, at least arccos(1 - 1e-6).
    pub theta_h: Tensor<2>,
    /// min(n.h, 1 - 1e-6).
    pub cos_h: Tensor<2>,
    /// cos r = v.h, clamped into [0, 1 - 1e-6].
    pub cos_r: Tensor<2>,
    /// sin r.
    pub sin_r: Tensor<2>,
    /// tan(theta_l), tan(theta_v) stacked: `[2 batch, 1]`.
    pub tan_lv: Tensor<2>,
    /// Body-network frame features (n''_x, n''_y, n''_z, l''_x, l''_z, n''.l''): `[batch, 6]`.
    pub body: Tensor<2>,
}

const N_BASE: usize = 11;
const N_FM: usize = 15;

impl Geometry {
    /// Computes the geometry of the pairs (l_i, v_i), both local-frame directions.
    ///
    /// # Panics
    /// If `l` and `v` differ in length.
    pub fn new(l: &[Vec3<f32>], v: &[Vec3<f32>], fmbrdf: bool, device: &Device) -> Self {
        assert_eq!(l.len(), v.len(), "Geometry: l and v lengths");
        let n = l.len();
        let mut base = Vec::with_capacity(n * N_BASE);
        let mut fm = Vec::with_capacity(if fmbrdf { n * N_FM } else { 0 });
        let up = [0.0_f32, 0.0, 1.0];
        for (&li, &vi) in l.iter().zip(v) {
            let (g, valid) = match PairGeometry::of(li, vi) {
                Some(g) => (g, true),
                None => (PairGeometry::of(up, up).expect("normal pair"), false),
            };
            let rv = li[2] * vi[2] - (li[0] * vi[0] + li[1] * vi[1]);
            let (rv, rv_pos) = if valid { (rv, rv > 0.0) } else { (1.0, true) };
            base.extend_from_slice(&[
                f32::from(u8::from(valid)),
                g.nl,
                g.nv,
                g.sin2_h,
                g.lh,
                schlick_weight(g.nl),
                schlick_weight(g.nv),
                schlick_weight(g.lh),
                (g.nl + g.nv).max(1e-12).recip(),
                rv.clamp(1e-20, 1.0),
                f32::from(u8::from(rv_pos)),
            ]);
            if fmbrdf {
                let (lu, vu) = match (unit(li), unit(vi)) {
                    (Some(a), Some(b)) if valid && a[2] > 0.0 && b[2] > 0.0 => (a, b),
                    _ => (up, up),
                };
                fm.extend_from_slice(&fm_terms(lu, vu));
            }
        }
        let t = Tensor::<2>::from_data(TensorData::new(base, [n, N_BASE]), device);
        let c = |k: usize| t.clone().narrow(1, k, 1);
        let fmbrdf = fmbrdf.then(|| {
            let t = Tensor::<2>::from_data(TensorData::new(fm, [n, N_FM]), device);
            let c = |k: usize| t.clone().narrow(1, k, 1);
            FmbrdfGeometry {
                nl: c(0),
                nv: c(1),
                nh: c(2),
                theta_h: c(3),
                cos_h: c(4),
                cos_r: c(5),
                sin_r: c(6),
                tan_lv: Tensor::cat(vec![c(7), c(8)], 0),
                body: t.clone().narrow(1, 9, 6),
            }
        });
        Self {
            mask: c(0),
            nl: c(1),
            nv: c(2),
            sin2_h: c(3),
            lh: c(4),
            schlick: t.clone().narrow(1, 5, 3),
            inv_cos_sum: c(8),
            rv: c(9),
            rv_positive: c(10),
            fmbrdf,
        }
    }

    /// Number of pairs.
    pub fn len(&self) -> usize {
        self.mask.dims()[0]
    }

    /// Whether the batch is empty.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// FMBRDF's unit(): keeps nearly unit vectors as they are, normalizes others.
fn unit(w: Vec3<f32>) -> Option<Vec3<f32>> {
    let len2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
    if (len2 - 1.0).abs() <= 16.0 * f32::EPSILON { Some(w) } else { angles::vec3::try_normalize(w) }
}

/// The 15 FMBRDF geometry values of a valid pair, in the column order of [`FmbrdfGeometry`].
fn fm_terms(l: Vec3<f32>, v: Vec3<f32>) -> [f32; N_FM] {
    let (nl, nv) = (l[2].min(1.0), v[2].min(1.0));
    let a = [l[0] + v[0], l[1] + v[1], l[2] + v[2]];
    let txy = a[0].hypot(a[1]);
    let len = txy.hypot(a[2]);
    let nh = (a[2] / len).min(1.0);
    let theta_h_min = (1.0 - COS_EPS).acos() as f32;
    let theta_h = txy.atan2(a[2]).max(theta_h_min);
    let cos_h = nh.min((1.0 - COS_EPS) as f32);
    let cos_r = (0.5 * len).clamp(0.0, (1.0 - COS_EPS) as f32);
    let sin_r = ((1.0 - cos_r) * (1.0 + cos_r)).sqrt();
    let b = body_features(l, v);
    [
        nl,
        nv,
        nh,
        theta_h,
        cos_h,
        cos_r,
        sin_r,
        smith_tan(nl),
        smith_tan(nv),
        b[0],
        b[1],
        b[2],
        b[3],
        b[4],
        b[5],
    ]
}

/// The body-reflection network's frame (spec addendum), shared with the scalar model: rotate so
/// that -v is +z, then about z so that l has no y component.
pub(crate) use brdf_analytic::fmbrdf_body_features as body_features;
/// tan(theta) from cos(theta), clamped like the official code (shared with the scalar model).
pub(crate) use brdf_analytic::fmbrdf_smith_tan as smith_tan;
