//! The LPIPS weight file: format, location, checksum verification and (feature `fetch`) download.
//!
//! **Format** (little-endian): the 8 bytes `LPIPSW1\0`, a `u32` tensor count, then per tensor a
//! `u32` name length, the UTF-8 name, a `u32` rank, `u32` dimensions and the `f32` values in
//! row-major order. Tensors: `conv{1..5}.weight` (out, in, kh, kw), `conv{1..5}.bias` (out) from
//! torchvision's AlexNet `features` (indices 0, 3, 6, 8, 10) and `lin{0..4}.weight` (1, C, 1, 1)
//! from LPIPS v0.1 `alex.pth` (`lin{k}.model.1.weight`).
//!
//! **Sources** (converted offline by `crates/metrics/devtools/convert_lpips.py`, needs PyTorch):
//! * [`ALEXNET_URL`]: torchvision's ImageNet AlexNet;
//! * [`LIN_URL`]: the LPIPS v0.1 linear layers.
//!
//! **Location**: [`default_path`] of a data root, `<data>/lpips/alex_v0.1.lpipsw` (where
//! `cargo xtask fetch-data lpips` leaves it); the command line may name another file.

use crate::error::{Error, Result};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// torchvision's AlexNet weights (PyTorch pickle).
pub const ALEXNET_URL: &str = "https://download.pytorch.org/models/alexnet-owt-7be5be79.pth";
/// LPIPS v0.1 linear layers for AlexNet (PyTorch pickle).
pub const LIN_URL: &str =
    "https://github.com/richzhang/PerceptualSimilarity/raw/master/lpips/weights/v0.1/alex.pth";

const MAGIC: &[u8; 8] = b"LPIPSW1\0";

/// A named tensor: shape and row-major values.
pub type Tensors = BTreeMap<String, (Vec<usize>, Vec<f32>)>;

/// The weight file's place under a data root (see the module doc).
pub fn default_path(data_root: &Path) -> PathBuf {
    data_root.join("lpips").join("alex_v0.1.lpipsw")
}

/// Reads a weight file.
pub fn read(path: &Path) -> Result<Tensors> {
    let bytes = std::fs::read(path).map_err(|source| Error::Io { path: path.into(), source })?;
    let bad = |reason: &str| Error::WeightFormat { path: path.into(), reason: reason.into() };
    let mut pos = 0usize;
    // Sizes come from the file: every sum and product is checked, so a header claiming 2^40
    // elements is "truncated" or an overflow error, never a panic or an allocation.
    let mut take = |n: usize| -> Result<&[u8]> {
        let end = pos.checked_add(n).ok_or_else(|| bad("a size overflows"))?;
        let s = bytes.get(pos..end).ok_or_else(|| bad("truncated"))?;
        pos = end;
        Ok(s)
    };
    if take(8)? != MAGIC {
        return Err(bad("missing LPIPSW1 magic"));
    }
    let u32_at = |s: &[u8]| u32::from_le_bytes([s[0], s[1], s[2], s[3]]) as usize;
    let count = u32_at(take(4)?);
    let mut out = Tensors::new();
    for _ in 0..count {
        let n = u32_at(take(4)?);
        let name = String::from_utf8(take(n)?.to_vec()).map_err(|_| bad("name is not UTF-8"))?;
        let rank = u32_at(take(4)?);
        let dims: Vec<usize> = (0..rank).map(|_| take(4).map(u32_at)).collect::<Result<_>>()?;
        let bytes_len = dims
            .iter()
            .try_fold(4usize, |acc, &d| acc.checked_mul(d))
            .ok_or_else(|| bad("tensor dimensions overflow"))?;
        let data = take(bytes_len)?
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        out.insert(name, (dims, data));
    }
    Ok(out)
}

/// Writes a weight file (atomically: temporary file, then rename).
pub fn write(path: &Path, tensors: &Tensors) -> Result<()> {
    let mut buf = MAGIC.to_vec();
    buf.extend_from_slice(&(tensors.len() as u32).to_le_bytes());
    for (name, (dims, data)) in tensors {
        buf.extend_from_slice(&(name.len() as u32).to_le_bytes());
        buf.extend_from_slice(name.as_bytes());
        buf.extend_from_slice(&(dims.len() as u32).to_le_bytes());
        for d in dims {
            buf.extend_from_slice(&(*d as u32).to_le_bytes());
        }
        for v in data {
            buf.extend_from_slice(&v.to_le_bytes());
        }
    }
    Ok(stdx::fs::write_atomic(path, &buf)?)
}

/// Lower-case hex sha256 of a file.
pub fn sha256_hex(path: &Path) -> Result<String> {
    let bytes = std::fs::read(path).map_err(|source| Error::Io { path: path.into(), source })?;
    Ok(Sha256::digest(&bytes).iter().map(|b| format!("{b:02x}")).collect())
}

/// Errors unless the file's sha256 equals `expected_hex` (case-insensitive).
pub fn verify_sha256(path: &Path, expected_hex: &str) -> Result<()> {
    let found = sha256_hex(path)?;
    if found.eq_ignore_ascii_case(expected_hex.trim()) {
        Ok(())
    } else {
        Err(Error::Checksum { path: path.into(), expected: expected_hex.into(), found })
    }
}

/// Downloads `url` to `dest` and verifies its sha256; the file is only moved into place when the
/// checksum matches. Needs the `fetch` feature (and internet); otherwise an [`Error::Download`].
pub fn fetch(url: &str, dest: &Path, expected_sha256: &str) -> Result<()> {
    let tmp = dest.with_extension("download");
    download(url, &tmp)?;
    if let Err(e) = verify_sha256(&tmp, expected_sha256) {
        let _ = std::fs::remove_file(&tmp);
        return Err(e);
    }
    std::fs::rename(&tmp, dest).map_err(|source| Error::Io { path: dest.into(), source })
}

#[cfg(feature = "fetch")]
fn download(url: &str, to: &Path) -> Result<()> {
    let fail = |reason: String| Error::Download { url: url.into(), reason };
    let resp = ureq::get(url).call().map_err(|e| fail(e.to_string()))?;
    let mut file =
        std::fs::File::create(to).map_err(|source| Error::Io { path: to.into(), source })?;
    std::io::copy(&mut resp.into_reader(), &mut file).map_err(|e| fail(e.to_string()))?;
    Ok(())
}

#[cfg(not(feature = "fetch"))]
fn download(url: &str, _to: &Path) -> Result<()> {
    Err(Error::Download { url: url.into(), reason: "built without the `fetch` feature".into() })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_checksum() {
        let dir = std::env::temp_dir().join(format!("metrics-lpips-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("w.lpipsw");
        let mut t = Tensors::new();
        t.insert("lin0.weight".into(), (vec![1, 2, 1, 1], vec![0.5, 1.5]));
        write(&path, &t).unwrap();
        assert_eq!(read(&path).unwrap(), t);
        // sha256 of the exact bytes, computed independently.
        let mut bytes = b"LPIPSW1\0".to_vec();
        bytes.extend_from_slice(&1u32.to_le_bytes());
        bytes.extend_from_slice(&11u32.to_le_bytes());
        bytes.extend_from_slice(b"lin0.weight");
        bytes.extend_from_slice(&4u32.to_le_bytes());
        for d in [1u32, 2, 1, 1] {
            bytes.extend_from_slice(&d.to_le_bytes());
        }
        bytes.extend_from_slice(&0.5f32.to_le_bytes());
        bytes.extend_from_slice(&1.5f32.to_le_bytes());
        let want: String = Sha256::digest(&bytes).iter().map(|b| format!("{b:02x}")).collect();
        verify_sha256(&path, &want.to_uppercase()).unwrap();
        let e = verify_sha256(&path, &"0".repeat(64)).unwrap_err();
        assert!(matches!(e, Error::Checksum { .. }) && e.to_string().contains("w.lpipsw"));
        std::fs::write(&path, b"garbage!").unwrap();
        assert!(matches!(read(&path), Err(Error::WeightFormat { .. })));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[cfg(not(feature = "fetch"))]
    #[test]
    fn fetch_without_feature_is_a_clear_error() {
        let dest = std::env::temp_dir().join("metrics-never-written.lpipsw");
        assert!(matches!(fetch(LIN_URL, &dest, "00"), Err(Error::Download { .. })));
        assert!(!dest.exists());
    }
}
