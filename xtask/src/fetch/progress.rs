//! The sha256 of a file read with a byte-counting progress bar (`stdx::progress::bytes`).

use anyhow::{Context, Result};
use sha2::{Digest, Sha256};
use std::io::Read;
use std::path::Path;

/// Lower-case hex of a digest.
pub fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// Feeds the first `len` bytes of `path` (all of it when `None`) into `hasher`, with a bar.
pub fn hash_into(hasher: &mut Sha256, path: &Path, len: Option<u64>, label: &str) -> Result<u64> {
    let file = std::fs::File::open(path).with_context(|| format!("opening {}", path.display()))?;
    let total = match len {
        Some(l) => l,
        None => file.metadata().with_context(|| format!("reading {}", path.display()))?.len(),
    };
    let pb = stdx::progress::bytes(label, Some(total));
    let mut reader = file.take(total);
    let mut buf = vec![0u8; 1 << 16];
    let mut done = 0u64;
    loop {
        let n = reader.read(&mut buf).with_context(|| format!("reading {}", path.display()))?;
        if n == 0 {
            break;
        }
        hasher.update(&buf[..n]);
        done += n as u64;
        pb.inc(n as u64);
    }
    pb.finish_and_clear();
    Ok(done)
}

/// The sha256 (hex) and length of the whole file at `path`.
pub fn sha256_file(path: &Path, label: &str) -> Result<(String, u64)> {
    let mut h = Sha256::new();
    let len = hash_into(&mut h, path, None, label)?;
    Ok((hex(&h.finalize()), len))
}
