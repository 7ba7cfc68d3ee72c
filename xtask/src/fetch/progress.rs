//! Progress bars of `fetch-data` (bytes, rate, ETA on a terminal; hidden otherwise) and the
//! sha256 of a file read with one.

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use sha2::{Digest, Sha256};
use std::io::Read;
use std::path::Path;

const WITH_TOTAL: &str = "{msg:24!} [{bar:30}] {bytes}/{total_bytes} {bytes_per_sec} eta {eta}";
const WITHOUT_TOTAL: &str = "{msg:24!} {spinner} {bytes} {bytes_per_sec}";

/// A byte-counting bar labelled `label`; `total` may be unknown. Indicatif hides it when stderr
/// is not a terminal, so logs and tests see only the summary lines.
pub fn bytes_bar(label: &str, total: Option<u64>) -> ProgressBar {
    let pb = match total {
        Some(t) => ProgressBar::new(t),
        None => ProgressBar::no_length(),
    };
    let template = if total.is_some() { WITH_TOTAL } else { WITHOUT_TOTAL };
    if let Ok(style) = ProgressStyle::with_template(template) {
        pb.set_style(style.progress_chars("=> "));
    }
    pb.set_message(label.to_string());
    pb
}

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
    let pb = bytes_bar(label, Some(total));
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

#[cfg(test)]
mod tests {
    #[test]
    fn templates_parse() {
        for t in [super::WITH_TOTAL, super::WITHOUT_TOTAL] {
            assert!(indicatif::ProgressStyle::with_template(t).is_ok(), "{t}");
        }
    }
}
