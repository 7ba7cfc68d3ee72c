//! The local lock file (`<data root>/fetch-lock.toml`): checksums the user accepted with
//! `--allow-unverified` for files whose manifest says `sha256 = "unknown"`. Later fetches verify
//! against it. It is local knowledge, never a published checksum; written atomically.

use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// File name of the lock, directly under the data root.
pub const FILE_NAME: &str = "fetch-lock.toml";

/// One accepted file.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Locked {
    /// Manifest (dataset) name.
    pub dataset: String,
    /// Where it was downloaded from (empty for a file placed by hand).
    pub url: String,
    /// Its sha256 as computed when it was accepted.
    pub sha256: String,
    /// Its size in bytes.
    pub size: u64,
}

/// The lock: accepted files keyed by their destination relative to the data root.
#[derive(Debug, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Lock {
    /// Accepted files.
    #[serde(default)]
    pub files: BTreeMap<String, Locked>,
    #[serde(skip)]
    path: PathBuf,
}

impl Lock {
    /// Reads the lock under `root` (empty when there is none).
    pub fn load(root: &Path) -> Result<Self> {
        let path = root.join(FILE_NAME);
        let mut lock = match std::fs::read_to_string(&path) {
            Ok(text) => toml::from_str(&text)
                .with_context(|| format!("lock file {} is invalid", path.display()))?,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Lock::default(),
            Err(e) => return Err(e).with_context(|| format!("reading {}", path.display())),
        };
        lock.path = path;
        Ok(lock)
    }

    /// The lock file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Records `entry` under `dest` and writes the lock atomically.
    pub fn record(&mut self, dest: &str, entry: Locked) -> Result<()> {
        self.files.insert(dest.to_string(), entry);
        let text = format!(
            "# Checksums accepted with `cargo xtask fetch-data --allow-unverified` for files whose\n\
             # manifest publishes none. Local knowledge: delete an entry to re-decide.\n{}",
            toml::to_string(self).context("serialising the lock file")?
        );
        Ok(stdx::fs::write_atomic(&self.path, text.as_bytes())?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip() {
        let dir = std::env::temp_dir().join(format!("xtask-lock-{}", std::process::id()));
        let mut lock = Lock::load(&dir).unwrap();
        assert!(lock.files.is_empty());
        let e = Locked { dataset: "d".into(), url: "u".into(), sha256: "ab".into(), size: 3 };
        lock.record("x/y.bin", e.clone()).unwrap();
        let back = Lock::load(&dir).unwrap();
        assert_eq!(back.files.get("x/y.bin"), Some(&e));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
