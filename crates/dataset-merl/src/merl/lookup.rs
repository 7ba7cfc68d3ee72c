//! MERL table lookup: the reference nearest-lower-bin rule and trilinear interpolation.
//!
//! Indexing (spec section 1, the MERL reference reader):
//! * theta_h: i_h = floor(sqrt(theta_h / (pi/2)) 90), 0 for theta_h <= 0 (square-root spacing);
//! * theta_d: i_d = floor(theta_d / (pi/2) 90);
//! * phi_d: folded by reciprocity into [0, pi), i_p = floor(phi_d / pi 180);
//!
//! each clamped into its range. Bin i's value is taken to sit at the bin's lower edge
//! ([`bin_lower_edges`]), which is also where tabulation evaluates a BRDF. Trilinear
//! interpolation is linear in these index coordinates, periodic in phi_d, clamped at the upper
//! theta ends; a result is invalid when any of its corners is.
//!
//! The angles come from [`angles::reciprocal_theta`], whose phi_d mod pi is bit-identical
//! under swapping l and v, so every lookup is exactly reciprocal.

use super::format::{MerlBrdf, N_PHI_D, N_THETA_D, N_THETA_H};
use angles::{Real, Vec3, reciprocal_theta};
use brdf_analytic::{Brdf, Rgb};
use std::f64::consts::{FRAC_PI_2, PI};
use std::sync::Arc;

/// How a MERL table is sampled between its bins: part of a scene's settings, so defined by the
/// scene format.
pub use scene::Lookup;

/// Continuous index coordinate of theta_h: sqrt(theta_h / (pi/2)) 90.
#[inline]
fn u_theta_h(theta_h: f64) -> f64 {
    if theta_h <= 0.0 { 0.0 } else { (theta_h / FRAC_PI_2).sqrt() * N_THETA_H as f64 }
}

#[inline]
fn u_theta_d(theta_d: f64) -> f64 {
    (theta_d / FRAC_PI_2 * N_THETA_D as f64).max(0.0)
}

/// phi_d folded into [0, pi), as a continuous index.
#[inline]
fn u_phi_d(phi_d: f64) -> f64 {
    let p = phi_d.rem_euclid(PI);
    (p / PI * N_PHI_D as f64).max(0.0)
}

#[inline]
fn clamp_index(u: f64, n: usize) -> usize {
    (u.floor().max(0.0) as usize).min(n - 1)
}

/// The reference bin indices (i_h, i_d, i_p) of Rusinkiewicz angles; phi_d may be in [0, 2 pi).
pub fn bin_indices(theta_h: f64, theta_d: f64, phi_d: f64) -> (usize, usize, usize) {
    (
        clamp_index(u_theta_h(theta_h), N_THETA_H),
        clamp_index(u_theta_d(theta_d), N_THETA_D),
        clamp_index(u_phi_d(phi_d), N_PHI_D),
    )
}

/// The angles (theta_h, theta_d, phi_d) of a bin's lower edge: ((i/90)^2 pi/2, i/90 pi/2,
/// i/180 pi), the convention every reference reader uses for the inverse.
pub fn bin_lower_edges(ih: usize, id: usize, ip: usize) -> (f64, f64, f64) {
    let h = ih as f64 / N_THETA_H as f64;
    (h * h * FRAC_PI_2, id as f64 / N_THETA_D as f64 * FRAC_PI_2, ip as f64 / N_PHI_D as f64 * PI)
}

impl MerlBrdf {
    /// The BRDF (1/sr) at Rusinkiewicz angles, or `None` where the table is invalid (negative).
    pub fn eval_angles(
        &self,
        theta_h: f64,
        theta_d: f64,
        phi_d: f64,
        mode: Lookup,
    ) -> Option<[f64; 3]> {
        match mode {
            Lookup::NearestLower => {
                let (ih, id, ip) = bin_indices(theta_h, theta_d, phi_d);
                self.bin(ih, id, ip)
            }
            Lookup::Trilinear => self.trilinear(theta_h, theta_d, phi_d),
        }
    }

    fn trilinear(&self, theta_h: f64, theta_d: f64, phi_d: f64) -> Option<[f64; 3]> {
        let axis = |u: f64, n: usize| {
            let i0 = clamp_index(u, n);
            if i0 + 1 >= n { (i0, i0, 0.0) } else { (i0, i0 + 1, (u - i0 as f64).clamp(0.0, 1.0)) }
        };
        let (h0, h1, fh) = axis(u_theta_h(theta_h), N_THETA_H);
        let (d0, d1, fd) = axis(u_theta_d(theta_d), N_THETA_D);
        let up = u_phi_d(phi_d);
        let p0 = clamp_index(up, N_PHI_D);
        let p1 = (p0 + 1) % N_PHI_D;
        let fp = (up - p0 as f64).clamp(0.0, 1.0);
        let mut acc = [0.0; 3];
        for (ih, wh) in [(h0, 1.0 - fh), (h1, fh)] {
            for (id, wd) in [(d0, 1.0 - fd), (d1, fd)] {
                for (ip, wp) in [(p0, 1.0 - fp), (p1, fp)] {
                    let v = self.bin(ih, id, ip)?;
                    let w = wh * wd * wp;
                    for c in 0..3 {
                        acc[c] += w * v[c];
                    }
                }
            }
        }
        Some(acc)
    }

    /// The BRDF (1/sr) for local-frame unit directions: `Some(0)` outside the upper hemisphere,
    /// `None` where the table is invalid.
    pub fn eval_dirs(&self, l: Vec3<f64>, v: Vec3<f64>, mode: Lookup) -> Option<[f64; 3]> {
        if !(l[2] > 0.0 && v[2] > 0.0) {
            return Some([0.0; 3]);
        }
        let t = reciprocal_theta(l, v);
        self.eval_angles(t[0], t[1], t[2], mode)
    }
}

/// A MERL table with its lookup rule, usable wherever a [`Brdf`] is: invalid bins evaluate to 0
/// (use [`MerlBrdf::eval_dirs`] to see validity).
#[derive(Clone, Debug)]
pub struct MerlMaterial {
    /// The table, shared.
    pub table: Arc<MerlBrdf>,
    /// The lookup rule.
    pub lookup: Lookup,
}

impl<T: Real> Brdf<T> for MerlMaterial {
    fn eval(&self, l: Vec3<T>, v: Vec3<T>) -> Rgb<T> {
        let to64 = |w: Vec3<T>| w.map(|x| x.to_f64_exact());
        let f = self.table.eval_dirs(to64(l), to64(v), self.lookup).unwrap_or([0.0; 3]);
        f.map(T::lit)
    }

    fn name(&self) -> &'static str {
        "MERL"
    }
}
