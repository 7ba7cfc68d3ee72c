//! Versioned, checksummed, content-keyed cache files: the one container of every on-disk cache
//! (ray-casting precompute, LBO eigenpairs, LBO feature tables).
//!
//! Layout: `magic` (8 bytes, names the cache) | format version `u32` LE | content key `u128` LE
//! | payload: the value in postcard (serde) | xxh3-64 of the payload `u64` LE.
//!
//! A cache is only ever trusted when every check passes; [`decode`] says which one failed, and
//! the caller recomputes and replaces the file. Bump the version whenever the payload's type or
//! the meaning of its numbers changes: old files are then simply recomputed.

use serde::Serialize;
use serde::de::DeserializeOwned;
use xxhash_rust::xxh3::xxh3_64;

const HEADER: usize = 8 + 4 + 16;

/// The complete file of `value` under this magic, version and key.
pub fn encode<T: Serialize>(magic: &[u8; 8], version: u32, key: u128, value: &T) -> Vec<u8> {
    let payload = postcard::to_stdvec(value).expect("in-memory postcard encoding cannot fail");
    seal(magic, version, key, &payload)
}

/// The payload bytes of a file (between the header and the checksum), if it is long enough.
pub fn payload(bytes: &[u8]) -> Option<&[u8]> {
    bytes.get(HEADER..bytes.len().checked_sub(8)?)
}

/// A file around raw payload bytes, with a valid checksum: what the robustness tests use to get
/// a corrupted payload past the checksum and into the decoder.
pub fn seal(magic: &[u8; 8], version: u32, key: u128, payload: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(HEADER + payload.len() + 8);
    out.extend_from_slice(magic);
    out.extend_from_slice(&version.to_le_bytes());
    out.extend_from_slice(&key.to_le_bytes());
    out.extend_from_slice(payload);
    out.extend_from_slice(&xxh3_64(payload).to_le_bytes());
    out
}

/// Checks and decodes a file written by [`encode`] with the same magic, version and key; the
/// error says which check failed.
pub fn decode<T: DeserializeOwned>(
    bytes: &[u8],
    magic: &[u8; 8],
    version: u32,
    key: u128,
) -> Result<T, String> {
    if bytes.len() < HEADER + 8 || &bytes[..8] != magic {
        return Err("not a cache file of this kind (magic or size)".into());
    }
    let stored_version = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes"));
    if stored_version != version {
        return Err(format!("format version {stored_version}, expected {version}"));
    }
    if u128::from_le_bytes(bytes[12..28].try_into().expect("16 bytes")) != key {
        return Err("content key mismatch".into());
    }
    let (payload, checksum) = bytes[HEADER..].split_at(bytes.len() - HEADER - 8);
    if xxh3_64(payload) != u64::from_le_bytes(checksum.try_into().expect("8 bytes")) {
        return Err("checksum mismatch (truncated or corrupted)".into());
    }
    let (value, rest) =
        postcard::take_from_bytes(payload).map_err(|e| format!("payload does not decode: {e}"))?;
    if !rest.is_empty() {
        return Err(format!("{} trailing bytes after the payload", rest.len()));
    }
    Ok(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    const MAGIC: &[u8; 8] = b"TESTCACH";

    #[test]
    fn round_trip_and_every_kind_of_damage_is_detected() {
        let value: (Vec<f32>, Vec<u64>, String) =
            (vec![1.5, -0.0, f32::MIN_POSITIVE], vec![0, u64::MAX, 7], "mesh".into());
        let bytes = encode(MAGIC, 3, 42, &value);
        assert_eq!(decode::<(Vec<f32>, Vec<u64>, String)>(&bytes, MAGIC, 3, 42), Ok(value));
        let err = |b: &[u8], version, key| {
            decode::<(Vec<f32>, Vec<u64>, String)>(b, MAGIC, version, key).unwrap_err()
        };
        assert!(err(&bytes, 3, 43).contains("key"));
        assert!(err(&bytes, 4, 42).contains("version 3, expected 4"));
        assert!(err(&bytes[..bytes.len() - 3], 3, 42).contains("checksum"));
        assert!(err(&bytes[..10], 3, 42).contains("magic"));
        let mut flipped = bytes.clone();
        flipped[HEADER + 5] ^= 0x10;
        assert!(err(&flipped, 3, 42).contains("checksum"));
        let mut magic = bytes.clone();
        magic[0] = b'X';
        assert!(err(&magic, 3, 42).contains("magic"));
        // A payload of another type with a valid checksum still fails to decode.
        let other = encode(MAGIC, 3, 42, &1u8);
        assert!(err(&other, 3, 42).contains("decode"));
    }
}
