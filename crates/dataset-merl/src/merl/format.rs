//! Reading, validating and writing MERL binaries.
//!
//! Layout (little-endian): three `i32` dimensions (90, 90, 180), then 3 x 1,458,000 `f64`,
//! channel-planar (all red, then green, then blue); inside a channel the flat index is
//! `i_p + 180 (i_d + 90 i_h)`. Stored values are raw: the BRDF in 1/sr is the raw value times
//! the channel scale (1/1500, 1.15/1500, 1.66/1500). Negative entries mark unmeasured bins.

use crate::error::{Error, Result};
use std::path::Path;

/// Bins in theta_h.
pub const N_THETA_H: usize = 90;
/// Bins in theta_d.
pub const N_THETA_D: usize = 90;
/// Bins in phi_d (over [0, pi)).
pub const N_PHI_D: usize = 180;
/// Entries per channel.
pub const TABLE_LEN: usize = N_THETA_H * N_THETA_D * N_PHI_D;
/// Size of a MERL file in bytes: 12 + 3 x 1,458,000 x 8 = 34,992,012.
pub const FILE_BYTES: usize = 12 + 3 * TABLE_LEN * 8;
/// Factors from raw stored values to the BRDF in 1/sr, per channel.
pub const CHANNEL_SCALES: [f64; 3] = [1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0];

/// A MERL BRDF table: raw values exactly as stored in the file.
#[derive(Clone)]
pub struct MerlBrdf {
    /// Raw values, channel-planar, length 3 x [`TABLE_LEN`].
    raw: Vec<f64>,
}

impl std::fmt::Debug for MerlBrdf {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MerlBrdf").field("invalid_entries", &self.invalid_entries()).finish()
    }
}

impl MerlBrdf {
    /// A table from raw channel-planar values.
    ///
    /// # Errors
    /// If the length is not 3 x [`TABLE_LEN`] or a value is NaN or infinite.
    pub fn from_raw(raw: Vec<f64>, origin: &str) -> Result<Self> {
        if raw.len() != 3 * TABLE_LEN {
            return Err(Error::MerlFormat {
                origin: origin.into(),
                fault: format!("{} values, expected {}", raw.len(), 3 * TABLE_LEN),
            });
        }
        if let Some(i) = raw.iter().position(|x| !x.is_finite()) {
            return Err(Error::MerlFormat {
                origin: origin.into(),
                fault: format!(
                    "value {} at channel {} entry {} is not finite",
                    raw[i],
                    i / TABLE_LEN,
                    i % TABLE_LEN
                ),
            });
        }
        Ok(Self { raw })
    }

    /// Tabulates a BRDF given in 1/sr (already including the channel scales) at the lower
    /// edges of every bin ([`crate::merl::bin_lower_edges`]); `f(theta_h, theta_d, phi_d)`.
    /// Non-finite values are an error; negative values are stored as they are (invalid).
    pub fn tabulate(origin: &str, f: impl Fn(f64, f64, f64) -> [f64; 3] + Sync) -> Result<Self> {
        use rayon::prelude::*;
        let values: Vec<[f64; 3]> = (0..TABLE_LEN)
            .into_par_iter()
            .map(|i| {
                let (ih, id, ip) =
                    (i / (N_THETA_D * N_PHI_D), (i / N_PHI_D) % N_THETA_D, i % N_PHI_D);
                let (th, td, pd) = crate::merl::lookup::bin_lower_edges(ih, id, ip);
                f(th, td, pd)
            })
            .collect();
        Self::from_bin_values(&values, origin)
    }

    /// The table of BRDF values (1/sr, already including the channel scales) given in bin
    /// order: index `ip + 180 (id + 90 ih)`, the order of the file. Non-finite values are an
    /// error; negative values are stored as they are (invalid).
    pub fn from_bin_values(values: &[[f64; 3]], origin: &str) -> Result<Self> {
        if values.len() != TABLE_LEN {
            return Err(Error::MerlFormat {
                origin: origin.into(),
                fault: format!("{} values, a MERL table has {TABLE_LEN}", values.len()),
            });
        }
        let mut raw = vec![0.0; 3 * TABLE_LEN];
        for (i, v) in values.iter().enumerate() {
            for c in 0..3 {
                raw[i + c * TABLE_LEN] = v[c] / CHANNEL_SCALES[c];
            }
        }
        Self::from_raw(raw, origin)
    }

    /// Parses the bytes of a MERL file; `origin` names them in errors.
    pub fn from_bytes(bytes: &[u8], origin: &str) -> Result<Self> {
        let fault = |fault: String| Error::MerlFormat { origin: origin.into(), fault };
        if bytes.len() < 12 {
            return Err(fault(format!(
                "truncated: {} bytes, no complete 12-byte header",
                bytes.len()
            )));
        }
        let dim = |k: usize| i32::from_le_bytes(bytes[4 * k..4 * k + 4].try_into().unwrap());
        let dims = [dim(0), dim(1), dim(2)];
        if dims != [90, 90, 180] {
            // i128: three i32 factors cannot overflow it (2^24 each overflowed an i64).
            let n = dims.iter().map(|&d| i128::from(d)).product::<i128>();
            return Err(fault(format!(
                "dimensions {dims:?} (product {n}); MERL tables are [90, 90, 180]"
            )));
        }
        if bytes.len() != FILE_BYTES {
            let what = if bytes.len() < FILE_BYTES { "truncated" } else { "trailing data" };
            return Err(fault(format!("{what}: {} bytes, expected {FILE_BYTES}", bytes.len())));
        }
        let raw: Vec<f64> = bytes[12..]
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect();
        Self::from_raw(raw, origin)
    }

    /// Reads a MERL file.
    pub fn read(path: &Path) -> Result<Self> {
        let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
        Self::from_bytes(&bytes, &path.display().to_string())
    }

    /// The file's bytes.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(FILE_BYTES);
        for d in [90i32, 90, 180] {
            out.extend_from_slice(&d.to_le_bytes());
        }
        for x in &self.raw {
            out.extend_from_slice(&x.to_le_bytes());
        }
        out
    }

    /// Writes the file atomically (temporary file in the same directory, then rename).
    pub fn write(&self, path: &Path) -> Result<()> {
        Ok(stdx::fs::write_atomic(path, &self.to_bytes())?)
    }

    /// Raw stored values, channel-planar.
    pub fn raw(&self) -> &[f64] {
        &self.raw
    }

    /// The BRDF (1/sr) of one bin, or `None` if any channel is negative (unmeasured).
    #[inline]
    pub fn bin(&self, ih: usize, id: usize, ip: usize) -> Option<[f64; 3]> {
        let i = ip + N_PHI_D * (id + N_THETA_D * ih);
        let v = [self.raw[i], self.raw[i + TABLE_LEN], self.raw[i + 2 * TABLE_LEN]];
        if v.iter().any(|&x| x < 0.0) {
            None
        } else {
            Some([0, 1, 2].map(|c| v[c] * CHANNEL_SCALES[c]))
        }
    }

    /// Number of bins with at least one negative (invalid) channel.
    pub fn invalid_entries(&self) -> usize {
        (0..TABLE_LEN).filter(|&i| (0..3).any(|c| self.raw[i + c * TABLE_LEN] < 0.0)).count()
    }
}
