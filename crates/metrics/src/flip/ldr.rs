//! LDR-FLIP of two images given in YCxCz (the per-exposure step of HDR-FLIP).

use super::color::{linrgb_to_hunt_lab, xyz_to_linrgb, ycxcz_to_xyz};
use super::filter::{Feature, Separable, csf_kernel, feature_kernel};

/// FLIP's fixed exponents and remapping constants.
const QC: f32 = 0.7;
const QF: f32 = 0.5;
const PC: f32 = 0.4;
const PT: f32 = 0.95;

/// Filters and constants for one pixels-per-degree value, built once per HDR-FLIP call.
pub(crate) struct LdrFlip {
    csf: [Separable; 3],
    edge: Separable,
    edge_t: Separable,
    point: Separable,
    point_t: Separable,
    cmax: f32,
}

impl LdrFlip {
    pub(crate) fn new(ppd: f64) -> Self {
        let edge = feature_kernel(ppd, Feature::Edge);
        let point = feature_kernel(ppd, Feature::Point);
        let green = linrgb_to_hunt_lab([0.0, 1.0, 0.0]);
        let blue = linrgb_to_hunt_lab([0.0, 0.0, 1.0]);
        Self {
            csf: [csf_kernel(ppd, 0), csf_kernel(ppd, 1), csf_kernel(ppd, 2)],
            edge_t: edge.transposed(),
            point_t: point.transposed(),
            edge,
            point,
            cmax: super::color::hyab(green, blue).powf(QC),
        }
    }

    /// Filters a YCxCz image (three planes) with the CSFs and returns Hunt-adjusted Lab pixels
    /// of the filtered image clamped to the RGB cube.
    fn color_pre(&self, ycxcz: &[Vec<f32>; 3], w: usize, h: usize) -> Vec<[f32; 3]> {
        let f: Vec<Vec<f32>> = (0..3).map(|c| self.csf[c].apply(&ycxcz[c], w, h)).collect();
        (0..w * h)
            .map(|i| {
                let rgb = xyz_to_linrgb(ycxcz_to_xyz([f[0][i], f[1][i], f[2][i]]));
                linrgb_to_hunt_lab(rgb.map(|v| v.clamp(0.0, 1.0)))
            })
            .collect()
    }

    /// Edge and point magnitudes of the normalised luminance (Y' + 16) / 116.
    fn features(&self, y: &[f32], w: usize, h: usize) -> (Vec<f32>, Vec<f32>) {
        let yn: Vec<f32> = y.iter().map(|v| (v + 16.0) / 116.0).collect();
        let norm = |a: Vec<f32>, b: Vec<f32>| -> Vec<f32> {
            a.iter().zip(&b).map(|(p, q)| (p * p + q * q).sqrt()).collect()
        };
        let e = norm(self.edge.apply(&yn, w, h), self.edge_t.apply(&yn, w, h));
        let p = norm(self.point.apply(&yn, w, h), self.point_t.apply(&yn, w, h));
        (e, p)
    }

    /// What LDR-FLIP needs of one image (planar YCxCz), whichever side of a comparison it is
    /// on: its CSF-filtered Hunt Lab pixels and its edge and point magnitudes.
    pub(crate) fn prepare(&self, ycxcz: &[Vec<f32>; 3], w: usize, h: usize) -> Prepared {
        let lab = self.color_pre(ycxcz, w, h);
        let (edge, point) = self.features(&ycxcz[0], w, h);
        Prepared { lab, edge, point }
    }

    /// The per-pixel LDR-FLIP error map of `test` against `reference`, both prepared.
    pub(crate) fn error_map(&self, test: &Prepared, reference: &Prepared) -> Vec<f32> {
        let (lab_r, lab_t) = (&reference.lab, &test.lab);
        let (er, pr, et, pt) = (&reference.edge, &reference.point, &test.edge, &test.point);
        let pccmax = PC * self.cmax;
        (0..lab_r.len())
            .map(|i| {
                let dc = super::color::hyab(lab_r[i], lab_t[i]).powf(QC);
                let dc = if dc < pccmax {
                    (PT / pccmax) * dc
                } else {
                    PT + ((dc - pccmax) / (self.cmax - pccmax)) * (1.0 - PT)
                };
                let df = (er[i] - et[i]).abs().max((pr[i] - pt[i]).abs());
                let df = (std::f32::consts::FRAC_1_SQRT_2 * df).powf(QF);
                dc.powf(1.0 - df)
            })
            .collect()
    }
}

/// One image's LDR-FLIP inputs at one exposure (see [`LdrFlip::prepare`]).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Prepared {
    lab: Vec<[f32; 3]>,
    edge: Vec<f32>,
    point: Vec<f32>,
}
