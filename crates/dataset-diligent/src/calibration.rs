//! DiLiGenT-MV's camera calibration (`Calib_Results.mat`, Caltech camera calibration toolbox):
//! shared intrinsics `KK` and per view `Rc_i`, `Tc_i` with x_c = Rc_i x_w + Tc_i (OpenCV's
//! convention), `kc` lens distortion.
//!
//! The principal point in `KK` has integer pixel centres; [`Calibration::read`] adds the
//! configured offset (0.5) for this project's cameras. DiLiGenT-MV's `Rc_i` are known not to be
//! exactly orthonormal (one row is about 0.35 % long; other loaders apply an ad hoc
//! diag(1.003458, 1, 1) correction). Since only the projection K [R | t] is calibrated, each Rc
//! is factored as U Q (RQ decomposition: U upper triangular, Q a rotation) and U moves into the
//! intrinsics: K' = KK U / U_33, R' = Q, t' = U^-1 Tc. This is the same projection with the
//! same camera centre, and exact; it is reported as a warning. A matrix further than 0.05 from
//! a rotation, or a reflection, is refused.

use crate::error::{Error, Result};
use crate::mat5::MatFile;
use glam::{DMat3, DVec3};
use std::path::Path;
use stdx::Limits;

/// Largest |R R^T - I| entry that is factored rather than refused.
const MAX_NON_ORTHONORMAL: f64 = 0.05;

/// One calibrated camera: x_c = r x_w + t, pixel = k x_c (OpenCV, pixel centres at +0.5).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CalibratedCamera {
    /// Intrinsics.
    pub k: DMat3,
    /// World-to-camera rotation (orthonormal, det 1).
    pub r: DMat3,
    /// Translation.
    pub t: DVec3,
}

/// The cameras of all views and what was noticed reading them.
#[derive(Clone, Debug, PartialEq)]
pub struct Calibration {
    /// Camera of view i + 1.
    pub cameras: Vec<CalibratedCamera>,
    /// Largest |Rc Rc^T - I| entry over the views (0 for exact rotations).
    pub max_non_orthonormal: f64,
    /// Warnings (factored rotations, ignored distortion).
    pub warnings: Vec<String>,
}

/// R = U Q with U upper triangular (positive diagonal) and Q orthonormal, by Gram-Schmidt on
/// the rows from the last; `None` for a rank-deficient R.
fn rq(r: DMat3) -> Option<(DMat3, DMat3)> {
    let (r0, r1, r2) = (r.row(0), r.row(1), r.row(2));
    let q2 = r2.try_normalize()?;
    let q1 = (r1 - r1.dot(q2) * q2).try_normalize()?;
    let q0 = (r0 - r0.dot(q2) * q2 - r0.dot(q1) * q1).try_normalize()?;
    let q = DMat3::from_cols(q0, q1, q2).transpose();
    // U is upper triangular by construction; clear the rounding noise below the diagonal so
    // that K U stays exactly upper triangular.
    let mut u = r * q.transpose();
    (u.x_axis.y, u.x_axis.z, u.y_axis.z) = (0.0, 0.0, 0.0);
    Some((u, q))
}

impl Calibration {
    /// Reads the cameras of views 1..=`views` from `path` (within `limits`); `offset` is added
    /// to the principal point.
    ///
    /// # Errors
    /// [`Error::Mat`] naming the file and the variable: missing, wrong shape, not finite, `KK`
    /// not upper triangular, `Rc_i` not (nearly) a rotation.
    pub fn read(path: &Path, views: usize, offset: f64, limits: &Limits) -> Result<Self> {
        let mat = MatFile::read(path, limits)?;
        let fault = |f: String| Error::Mat { path: path.into(), fault: f };
        let kk = mat.matrix(&["KK"], 3, 3)?;
        if kk.iter().any(|x| !x.is_finite())
            || kk[3] != 0.0
            || kk[6] != 0.0
            || kk[7] != 0.0
            || kk[8] != 1.0
            || kk[0] <= 0.0
            || kk[4] <= 0.0
        {
            return Err(fault(format!("`KK` {kk:?} is not an intrinsic matrix")));
        }
        let kk = DMat3::from_cols_array(&[
            kk[0],
            0.0,
            0.0,
            kk[1],
            kk[4],
            0.0,
            kk[2] + offset,
            kk[5] + offset,
            1.0,
        ]);
        let mut warnings = Vec::new();
        if let Some(kc) = mat.get("kc").and_then(|v| v.data.as_ref())
            && kc.iter().any(|x| x.abs() > 1e-12)
        {
            warnings.push(format!(
                "{}: lens distortion kc = {kc:?} ignored (images taken as undistorted)",
                path.display()
            ));
        }
        let mut cameras = Vec::with_capacity(views);
        let mut worst: f64 = 0.0;
        for v in 1..=views {
            let (a, b) = (format!("Rc_{v}"), format!("Rc_{v:02}"));
            let r = mat.matrix(&[&a, &b], 3, 3)?;
            let (a, b) = (format!("Tc_{v}"), format!("Tc_{v:02}"));
            let t = mat.vector(&[&a, &b], 3)?;
            let r = DMat3::from_cols_array(&[r[0], r[3], r[6], r[1], r[4], r[7], r[2], r[5], r[8]]);
            let t = DVec3::new(t[0], t[1], t[2]);
            if !r.is_finite() || !t.is_finite() {
                return Err(fault(format!("`Rc_{v}` or `Tc_{v}` is not finite")));
            }
            let dev = (r * r.transpose() - DMat3::IDENTITY)
                .to_cols_array()
                .iter()
                .fold(0.0_f64, |m, e| m.max(e.abs()));
            let factored = rq(r).filter(|(_, q)| q.determinant() > 0.0);
            let Some((u, q)) = factored.filter(|_| dev <= MAX_NON_ORTHONORMAL) else {
                return Err(fault(format!(
                    "`Rc_{v}` is not a rotation (|R R^T - I| up to {dev:.3}, det {:.3})",
                    r.determinant()
                )));
            };
            worst = worst.max(dev);
            let ku = kk * u;
            let k = ku * (1.0 / ku.z_axis.z);
            cameras.push(CalibratedCamera { k, r: q, t: u.inverse() * t });
        }
        if worst > 1e-6 {
            warnings.push(format!(
                "{}: rotations Rc_i are not orthonormal (|R R^T - I| up to {worst:.2e}); each was \
                 factored as U Q with U moved into the intrinsics (same projection)",
                path.display()
            ));
        }
        Ok(Self { cameras, max_non_orthonormal: worst, warnings })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rq_factors_a_stretched_rotation_exactly() {
        let q = DMat3::from_rotation_y(0.7) * DMat3::from_rotation_x(-0.3);
        let s = DMat3::from_diagonal(DVec3::new(1.003458, 1.0, 1.0));
        let (u, q2) = rq(s * q).unwrap();
        assert!((q2 - q).to_cols_array().iter().all(|e| e.abs() < 1e-12));
        assert!((u - s).to_cols_array().iter().all(|e| e.abs() < 1e-12));
        assert!(rq(DMat3::ZERO).is_none());
    }
}
