//! Per-sample geometry of the direction pairs, computed on the CPU with exactly the scalar
//! formulas of `brdf-analytic` and uploaded as constant tensors.
//!
//! Every quantity here depends on l and v only, never on a trainable parameter, so computing it
//! outside the autodiff graph loses nothing; it also makes the tensor BRDFs mirror their scalar
//! twins operation for operation. Pairs outside the upper hemisphere are replaced by l = v = n
//! (every term finite) and zeroed through `mask` at the end.

use angles::Vec3;
use brdf_analytic::microfacet::{PairGeometry, schlick_weight};
use burn::tensor::{Device, Int, Tensor, TensorData};
use std::sync::Arc;

/// FMBRDF's cosine clamp epsilon (official code: 1e-6).
pub(crate) const COS_EPS: f64 = 1e-6;
/// FMBRDF's denominator epsilon (official code: 1e-9).
pub(crate) const DEN_EPS: f64 = 1e-9;

/// Geometry of a batch of local-frame direction pairs; every tensor is `[batch, 1]` unless noted.
///
/// Besides the pair's own terms it holds every direction-only sub-expression of the tensor
/// BRDFs, computed here with the tensor twins' own operations in the same order (so each value is
/// the one the tensor op would give, to the bit): on the CPU a term costs a few nanoseconds a
/// pair, where as a tensor op it costs an allocation and a pass of its own.
#[derive(Clone, Debug)]
pub struct Geometry {
    /// 1 where n.l > 0 and n.v > 0, else 0.
    pub mask: Tensor<2>,
    /// n.l (clamped to at most 1).
    pub nl: Tensor<2>,
    /// n.v (clamped to at most 1).
    pub nv: Tensor<2>,
    /// (n.l)^2 (Smith visibility).
    pub nl2: Tensor<2>,
    /// (n.v)^2 (Smith visibility).
    pub nv2: Tensor<2>,
    /// sin^2(theta_h).
    pub sin2_h: Tensor<2>,
    /// cos^2(theta_h) = 1 - sin^2(theta_h) (GGX D).
    pub cos2_h: Tensor<2>,
    /// (l.h)^2, with l.h = |l + v| / 2 (Disney's F_D90).
    pub lh2: Tensor<2>,
    /// Schlick weight (1 - n.l)^5.
    pub schlick_l: Tensor<2>,
    /// Schlick weight (1 - n.v)^5.
    pub schlick_v: Tensor<2>,
    /// Schlick weight (1 - l.h)^5.
    pub schlick_h: Tensor<2>,
    /// 1 / max(n.l + n.v, 1e-12) - 0.5 (Disney's Hanrahan-Krueger subsurface).
    pub subsurface_cos: Tensor<2>,
    /// 0.04 + 0.96 (1 - l.h)^5 (Disney's clearcoat Fresnel).
    pub clearcoat_fresnel: Tensor<2>,
    /// Smith-GGX visibility at alpha = 0.25 of n.l times that of n.v (Disney's clearcoat).
    pub clearcoat_visibility: Tensor<2>,
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
    /// The same values on the host, for the Lambda network's segment search
    /// ([`super::FmbrdfNets::lambda`]).
    pub tan_lv_host: Arc<[f32]>,
    /// Body-network frame features (n''_x, n''_y, n''_z, l''_x, l''_z, n''.l''): `[batch, 6]`.
    pub body: Tensor<2>,
}

/// Number of per-pair terms of [`Geometry`] (without FMBRDF's).
const N_BASE: usize = 16;
/// Number of FMBRDF terms stored one per row ([`FmbrdfGeometry`] without the body features).
const N_FM: usize = 9;
/// Number of FMBRDF body features.
const N_BODY: usize = 6;

/// Smith-GGX visibility 1 / (c + sqrt(a^2 + c^2 - a^2 c^2)) from a^2 and c^2, in the operation
/// order of the tensor twin `smith_visibility`.
fn smith_visibility(c: f32, c2: f32, a2: f32) -> f32 {
    1.0 / (c + ((a2 + c2) - a2 * c2).sqrt())
}

impl Geometry {
    /// Computes the geometry of the pairs (l_i, v_i), both local-frame directions.
    ///
    /// The terms are uploaded as one `[terms, batch]` tensor, one term a row, so that each
    /// field is a contiguous view (element-wise ops on a strided column take the backends'
    /// slow path).
    ///
    /// # Panics
    /// If `l` and `v` differ in length.
    pub fn new(l: &[Vec3<f32>], v: &[Vec3<f32>], fmbrdf: bool, device: &Device) -> Self {
        assert_eq!(l.len(), v.len(), "Geometry: l and v lengths");
        let n = l.len();
        let terms = Terms::of(l, v, fmbrdf);
        let rows = |count: usize, buf: &[f32]| {
            let mut out = Vec::with_capacity(n * count);
            for k in 0..count {
                out.extend_from_slice(&buf[k * terms.stride..k * terms.stride + n]);
            }
            out
        };
        let base = rows(N_BASE, &terms.base);
        let fm = if fmbrdf { rows(N_FM, &terms.fm) } else { Vec::new() };
        let t = Tensor::<2>::from_data(TensorData::new(base, [N_BASE, n]), device);
        let row = |t: &Tensor<2>, k: usize| t.clone().narrow(0, k, 1).reshape([n, 1]);
        let c = |k: usize| row(&t, k);
        let fmbrdf = fmbrdf.then(|| {
            let tan_lv_host: Arc<[f32]> = fm[7 * n..9 * n].into();
            let t = Tensor::<2>::from_data(TensorData::new(fm, [N_FM, n]), device);
            let c = |k: usize| row(&t, k);
            FmbrdfGeometry {
                nl: c(0),
                nv: c(1),
                nh: c(2),
                theta_h: c(3),
                cos_h: c(4),
                cos_r: c(5),
                sin_r: c(6),
                tan_lv: t.clone().narrow(0, 7, 2).reshape([2 * n, 1]),
                tan_lv_host,
                body: Tensor::from_data(TensorData::new(terms.body, [n, N_BODY]), device),
            }
        });
        Self {
            mask: c(0),
            nl: c(1),
            nv: c(2),
            nl2: c(3),
            nv2: c(4),
            sin2_h: c(5),
            cos2_h: c(6),
            lh2: c(7),
            schlick_l: c(8),
            schlick_v: c(9),
            schlick_h: c(10),
            subsurface_cos: c(11),
            clearcoat_fresnel: c(12),
            clearcoat_visibility: c(13),
            rv: c(14),
            rv_positive: c(15),
            fmbrdf,
        }
    }

    /// The geometry of the pairs `host[i]` (also uploaded as `index`), selected on the device:
    /// the values [`Geometry::new`] gives for those pairs, without computing or uploading them
    /// (a training loop's table of every record, [`crate::RecordTable`]).
    pub fn select(&self, index: &Tensor<1, Int>, host: &[u32]) -> Self {
        let pick = |t: &Tensor<2>| t.clone().select(0, index.clone());
        let fmbrdf = self.fmbrdf.as_ref().map(|f| {
            let n = f.nl.dims()[0];
            let (tan_l, tan_v) =
                (f.tan_lv.clone().narrow(0, 0, n), f.tan_lv.clone().narrow(0, n, n));
            let tan_lv_host: Arc<[f32]> = host
                .iter()
                .map(|&i| f.tan_lv_host[i as usize])
                .chain(host.iter().map(|&i| f.tan_lv_host[n + i as usize]))
                .collect();
            FmbrdfGeometry {
                nl: pick(&f.nl),
                nv: pick(&f.nv),
                nh: pick(&f.nh),
                theta_h: pick(&f.theta_h),
                cos_h: pick(&f.cos_h),
                cos_r: pick(&f.cos_r),
                sin_r: pick(&f.sin_r),
                tan_lv: Tensor::cat(vec![pick(&tan_l), pick(&tan_v)], 0),
                tan_lv_host,
                body: pick(&f.body),
            }
        });
        Self {
            mask: pick(&self.mask),
            nl: pick(&self.nl),
            nv: pick(&self.nv),
            nl2: pick(&self.nl2),
            nv2: pick(&self.nv2),
            sin2_h: pick(&self.sin2_h),
            cos2_h: pick(&self.cos2_h),
            lh2: pick(&self.lh2),
            schlick_l: pick(&self.schlick_l),
            schlick_v: pick(&self.schlick_v),
            schlick_h: pick(&self.schlick_h),
            subsurface_cos: pick(&self.subsurface_cos),
            clearcoat_fresnel: pick(&self.clearcoat_fresnel),
            clearcoat_visibility: pick(&self.clearcoat_visibility),
            rv: pick(&self.rv),
            rv_positive: pick(&self.rv_positive),
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

/// The terms of the pairs: `base` and `fm` term-major (the values of the first term, then
/// of the second, ..., each term's run starting `stride` values after the previous one's),
/// `body` pair-major.
///
/// The stride is `len` plus one cache line: with a stride of exactly `len` (a multiple of 4 KiB
/// for a batch of 8,192), the 16 writes of one pair would land in the same L1 cache set. The
/// `tensor_brdf` bench measures `Geometry::new` with and without the padding; one thread, in
/// one piece, was the fastest (`benches/README.md`).
struct Terms {
    stride: usize,
    base: Vec<f32>,
    fm: Vec<f32>,
    body: Vec<f32>,
}

impl Terms {
    fn of(l: &[Vec3<f32>], v: &[Vec3<f32>], fmbrdf: bool) -> Self {
        let n = l.len();
        let stride = n + 16;
        let mut base = vec![0.0_f32; stride * N_BASE];
        let mut fm = vec![0.0_f32; if fmbrdf { stride * N_FM } else { 0 }];
        let mut body = Vec::with_capacity(if fmbrdf { n * N_BODY } else { 0 });
        let up = [0.0_f32, 0.0, 1.0];
        // The clearcoat's alpha: 0.25 exactly, squared as the tensor twin squares it.
        let cc_a2 = 0.25_f32 * 0.25;
        for (i, (&li, &vi)) in l.iter().zip(v).enumerate() {
            let (g, valid) = match PairGeometry::of(li, vi) {
                Some(g) => (g, true),
                None => (PairGeometry::of(up, up).expect("normal pair"), false),
            };
            let rv = li[2] * vi[2] - (li[0] * vi[0] + li[1] * vi[1]);
            let (rv, rv_pos) = if valid { (rv, rv > 0.0) } else { (1.0, true) };
            let (nl2, nv2) = (g.nl * g.nl, g.nv * g.nv);
            let schlick_h = schlick_weight(g.lh);
            let terms: [f32; N_BASE] = [
                f32::from(u8::from(valid)),
                g.nl,
                g.nv,
                nl2,
                nv2,
                g.sin2_h,
                -g.sin2_h + 1.0,
                g.lh * g.lh,
                schlick_weight(g.nl),
                schlick_weight(g.nv),
                schlick_h,
                (g.nl + g.nv).max(1e-12).recip() - 0.5,
                schlick_h * 0.96 + 0.04,
                smith_visibility(g.nl, nl2, cc_a2) * smith_visibility(g.nv, nv2, cc_a2),
                rv.clamp(1e-20, 1.0),
                f32::from(u8::from(rv_pos)),
            ];
            for (k, t) in terms.into_iter().enumerate() {
                base[k * stride + i] = t;
            }
            if fmbrdf {
                let (lu, vu) = match (unit(li), unit(vi)) {
                    (Some(a), Some(b)) if valid && a[2] > 0.0 && b[2] > 0.0 => (a, b),
                    _ => (up, up),
                };
                let (terms, b) = fm_terms(lu, vu);
                for (k, t) in terms.into_iter().enumerate() {
                    fm[k * stride + i] = t;
                }
                body.extend_from_slice(&b);
            }
        }
        Self { stride, base, fm, body }
    }
}

/// FMBRDF's unit(): keeps nearly unit vectors as they are, normalizes others.
fn unit(w: Vec3<f32>) -> Option<Vec3<f32>> {
    let len2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
    if (len2 - 1.0).abs() <= 16.0 * f32::EPSILON { Some(w) } else { angles::vec3::try_normalize(w) }
}

/// The FMBRDF geometry values of a valid pair, in the field order of [`FmbrdfGeometry`]: the
/// nine one-per-row terms (tan theta_l and tan theta_v last), then the six body features.
fn fm_terms(l: Vec3<f32>, v: Vec3<f32>) -> ([f32; N_FM], [f32; N_BODY]) {
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
    let terms = [nl, nv, nh, theta_h, cos_h, cos_r, sin_r, smith_tan(nl), smith_tan(nv)];
    (terms, body_features(l, v))
}

/// The body-reflection network's frame (spec addendum), shared with the scalar model: rotate so
/// that -v is +z, then about z so that l has no y component.
pub(crate) use brdf_analytic::fmbrdf_body_features as body_features;
/// tan(theta) from cos(theta), clamped like the official code (shared with the scalar model).
pub(crate) use brdf_analytic::fmbrdf_smith_tan as smith_tan;
