//! On-disk cache of eigenpairs, one file per mesh and solve, under a content key.
//!
//! * **Key**: xxh3-128 of a format version, the vertex positions and triangles (as f64 / u32
//!   little-endian bytes), `k` and every [`EigenSettings`] field. Any change to the mesh or the
//!   solve gives a new file name `lbo-<key as 32 hex digits>.bin`.
//! * **File**: the workspace's cache container (`stdx::cache_file`: magic `NBLBOEIG`, format
//!   version, key, then `n`, `k`, the `k` eigenvalues and the `n x k` eigenvectors column by
//!   column in postcard, and the payload's xxh3-64 checksum).
//! * Written to a temporary file in the same directory and renamed into place, so a reader
//!   never sees a half-written file. A file with a wrong magic, version, key, size or checksum
//!   is reported as [`CacheOutcome::Recomputed`] and overwritten.

use std::path::{Path, PathBuf};

use faer::Mat;
use xxhash_rust::xxh3::xxh3_128;

use super::assembly::LboMatrices;
use super::eigen::{EigenSettings, Eigenpairs, smallest_eigenpairs};
use crate::error::{Error, Result};

/// The first 8 bytes of every eigenpair cache file.
pub const MAGIC: &[u8; 8] = b"NBLBOEIG";
/// Bumped whenever the file layout or the meaning of the cached numbers changes.
/// Version 2: the faster block Lanczos (block 16, adaptive Ritz checks; rounding-level changes).
/// Version 3: the payload is `CachedPairs` (n, k, values, vectors) in the workspace's cache
/// container (postcard).
pub const FORMAT_VERSION: u32 = 3;

/// The payload of a cache file.
#[derive(serde::Serialize, serde::Deserialize)]
struct CachedPairs {
    /// Vertex count.
    n: u64,
    /// Eigenpair count.
    k: u64,
    /// Eigenvalues.
    values: Vec<f64>,
    /// Eigenvectors, column-major (`n` values per column).
    vectors: Vec<f64>,
}

/// What [`cached_eigenpairs`] did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CacheOutcome {
    /// A valid cache file was loaded.
    Loaded,
    /// No cache file existed; the pairs were computed and written.
    Computed,
    /// A cache file existed but was unusable (the reason is given); it was recomputed and
    /// overwritten.
    Recomputed(String),
}

/// The content key of a mesh, `k` and the solver settings.
pub fn cache_key(
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    k: usize,
    settings: &EigenSettings,
) -> u128 {
    let mut bytes = Vec::with_capacity(64 + vertices.len() * 24 + triangles.len() * 12);
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    bytes.extend_from_slice(&(vertices.len() as u64).to_le_bytes());
    for c in vertices.iter().flatten() {
        bytes.extend_from_slice(&c.to_le_bytes());
    }
    bytes.extend_from_slice(&(triangles.len() as u64).to_le_bytes());
    for i in triangles.iter().flatten() {
        bytes.extend_from_slice(&i.to_le_bytes());
    }
    bytes.extend_from_slice(&(k as u64).to_le_bytes());
    // `threads` only changes rounding and `memory_budget` whether a solve may start, so
    // neither is part of the key.
    let EigenSettings {
        block_size,
        tolerance,
        max_basis_factor,
        shift_factor,
        seed,
        slice_size,
        threads: _,
        memory_budget: _,
    } = *settings;
    bytes.extend_from_slice(&(block_size as u64).to_le_bytes());
    bytes.extend_from_slice(&(slice_size as u64).to_le_bytes());
    for x in [tolerance, max_basis_factor, shift_factor] {
        bytes.extend_from_slice(&x.to_le_bytes());
    }
    bytes.extend_from_slice(&seed.to_le_bytes());
    xxh3_128(&bytes)
}

/// The cache file for a key in `dir`.
pub fn cache_path(dir: &Path, key: u128) -> PathBuf {
    dir.join(format!("lbo-{key:032x}.bin"))
}

/// The `k` smallest eigenpairs of the mesh, from the cache in `dir` when a valid file is there,
/// otherwise computed with [`smallest_eigenpairs`] and written to it.
///
/// # Errors
/// Assembly and solver errors, and [`Error::LboCache`] when the cache file cannot be written.
pub fn cached_eigenpairs(
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    k: usize,
    settings: &EigenSettings,
    dir: &Path,
) -> Result<(Eigenpairs, CacheOutcome)> {
    let key = cache_key(vertices, triangles, k, settings);
    let path = cache_path(dir, key);
    let outcome = match std::fs::read(&path) {
        Ok(bytes) => match decode(&bytes, key, vertices.len(), k) {
            Ok(pairs) => return Ok((pairs, CacheOutcome::Loaded)),
            Err(reason) => CacheOutcome::Recomputed(reason),
        },
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => CacheOutcome::Computed,
        Err(e) => CacheOutcome::Recomputed(format!("unreadable: {e}")),
    };
    let matrices = LboMatrices::assemble(vertices, triangles)?;
    let (pairs, _report) = smallest_eigenpairs(&matrices, k, settings)?;
    stdx::fs::write_atomic(&path, &encode(&pairs, key)).map_err(|e| Error::LboCache {
        path: e.path,
        message: format!("cannot write: {}", e.source),
    })?;
    Ok((pairs, outcome))
}

/// Serialises pairs into the cache layout.
fn encode(pairs: &Eigenpairs, key: u128) -> Vec<u8> {
    let (n, k) = (pairs.vertex_count(), pairs.len());
    let vectors = (0..k).flat_map(|j| pairs.vectors.col_as_slice(j).iter().copied()).collect();
    let payload = CachedPairs { n: n as u64, k: k as u64, values: pairs.values.clone(), vectors };
    stdx::cache_file::encode(MAGIC, FORMAT_VERSION, key, &payload)
}

/// Parses and checks the bytes of a cache file for `key`, `n` vertices and `k` pairs (what
/// [`cached_eigenpairs`] does before it trusts a file); the error says why it is unusable.
/// Public for tools that inspect caches and for the fuzz targets.
pub fn decode(
    bytes: &[u8],
    key: u128,
    n: usize,
    k: usize,
) -> std::result::Result<Eigenpairs, String> {
    let p: CachedPairs = stdx::cache_file::decode(bytes, MAGIC, FORMAT_VERSION, key)?;
    if (p.n, p.k) != (n as u64, k as u64) {
        return Err(format!("sizes {} x {}, expected {n} x {k}", p.n, p.k));
    }
    if p.values.len() != k || p.vectors.len() != n * k {
        return Err("inconsistent array lengths".into());
    }
    let vectors = Mat::<f64>::from_fn(n, k, |i, j| p.vectors[j * n + i]);
    Ok(Eigenpairs { values: p.values, vectors })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pairs() -> Eigenpairs {
        Eigenpairs {
            values: vec![0.0, 1.5, 2.25],
            vectors: Mat::from_fn(4, 3, |i, j| (i * 3 + j) as f64 * 0.1 - 0.4),
        }
    }

    #[test]
    fn round_trip_and_every_kind_of_damage_is_detected() {
        let p = pairs();
        let bytes = encode(&p, 42);
        let back = decode(&bytes, 42, 4, 3).unwrap();
        assert_eq!(back.values, p.values);
        assert_eq!(back.vectors, p.vectors);
        assert!(decode(&bytes, 43, 4, 3).unwrap_err().contains("key"));
        assert!(decode(&bytes, 42, 5, 3).unwrap_err().contains("sizes"));
        assert!(decode(&bytes[..bytes.len() - 3], 42, 4, 3).unwrap_err().contains("truncated"));
        let mut flipped = bytes.clone();
        flipped[28 + 17] ^= 0x10;
        assert!(decode(&flipped, 42, 4, 3).unwrap_err().contains("checksum"));
        let mut magic = bytes.clone();
        magic[0] = b'X';
        assert!(decode(&magic, 42, 4, 3).unwrap_err().contains("magic"));
        let mut version = bytes;
        version[8] = 99;
        assert!(decode(&version, 42, 4, 3).unwrap_err().contains("version"));
    }

    /// Corrupted payloads sealed with a valid checksum (what a bug in a writer, not a damaged
    /// disk, would produce) reach the decoder: an error or a value, never a panic, and no
    /// allocation beyond the cap (a length of 2^40 elements is an error).
    #[test]
    fn corrupted_payloads_past_the_checksum_give_errors_not_panics() {
        let bytes = encode(&pairs(), 42);
        let seed = stdx::cache_file::payload(&bytes).unwrap().to_vec();
        let ran = test_support::corrupt::fuzz_loader("lbo-cache", &[seed], 3000, |b| {
            let _ = decode(&stdx::cache_file::seal(MAGIC, FORMAT_VERSION, 42, b), 42, 4, 3);
        });
        assert!(ran >= 3000);
    }

    #[test]
    fn key_depends_on_mesh_k_and_settings() {
        let v = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let t = [[0, 1, 2]];
        let s = EigenSettings::default();
        let key = cache_key(&v, &t, 3, &s);
        assert_eq!(key, cache_key(&v, &t, 3, &s));
        assert_ne!(key, cache_key(&v, &t, 2, &s));
        assert_ne!(key, cache_key(&v, &[[0, 2, 1]], 3, &s));
        let mut moved = v;
        moved[2][2] = 1e-9;
        assert_ne!(key, cache_key(&moved, &t, 3, &s));
        assert_ne!(key, cache_key(&v, &t, 3, &EigenSettings { tolerance: 1e-7, ..s }));
    }
}
