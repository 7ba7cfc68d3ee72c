//! The optional unpack step: extracts a verified zip archive into a directory under the data
//! root, atomically (a temporary sibling directory, then a rename) and only once: a marker file
//! records the archive's sha256, so a later fetch skips it. Entry names that would leave the
//! target directory (`..`, absolute paths) are refused.

use anyhow::{Context, Result, bail};
use std::path::Path;

/// Name of the marker file written inside an unpacked directory.
pub const MARKER: &str = ".unpacked-from";

/// What [`unzip`] did.
#[derive(Debug, PartialEq, Eq)]
pub enum Unpacked {
    /// Extracted this many files.
    Extracted(usize),
    /// The directory already holds this archive's contents.
    Kept,
}

/// Extracts `archive` (whose sha256 is `sha256`) into `into`.
pub fn unzip(archive: &Path, sha256: &str, into: &Path) -> Result<Unpacked> {
    let marker_text = format!("sha256 = \"{sha256}\"\n");
    if into.exists() {
        match std::fs::read_to_string(into.join(MARKER)) {
            Ok(t) if t == marker_text => return Ok(Unpacked::Kept),
            Ok(_) => std::fs::remove_dir_all(into)
                .with_context(|| format!("removing the outdated {}", into.display()))?,
            Err(_) => bail!(
                "{} exists but was not unpacked by fetch-data; move it away to unpack {} there",
                into.display(),
                archive.display()
            ),
        }
    }
    let tmp = into.with_extension("unpacking");
    if tmp.exists() {
        std::fs::remove_dir_all(&tmp).with_context(|| format!("removing {}", tmp.display()))?;
    }
    std::fs::create_dir_all(&tmp).with_context(|| format!("creating {}", tmp.display()))?;
    let count = match extract(archive, &tmp) {
        Ok(n) => n,
        Err(e) => {
            let _ = std::fs::remove_dir_all(&tmp);
            return Err(e);
        }
    };
    std::fs::write(tmp.join(MARKER), marker_text)
        .with_context(|| format!("writing {}", tmp.join(MARKER).display()))?;
    std::fs::rename(&tmp, into)
        .with_context(|| format!("renaming {} to {}", tmp.display(), into.display()))?;
    Ok(Unpacked::Extracted(count))
}

fn extract(archive: &Path, to: &Path) -> Result<usize> {
    let bad = || format!("unpacking {}", archive.display());
    let file = std::fs::File::open(archive).with_context(bad)?;
    let mut zip = zip::ZipArchive::new(std::io::BufReader::new(file)).with_context(bad)?;
    let total: u64 = (0..zip.len()).filter_map(|i| zip.by_index(i).ok().map(|f| f.size())).sum();
    let name = archive.file_name().map_or("archive".into(), |n| n.to_string_lossy());
    let pb = stdx::progress::bytes(&format!("unpacking {name}"), Some(total));
    let mut files = 0;
    for i in 0..zip.len() {
        let mut entry = zip.by_index(i).with_context(bad)?;
        let Some(rel) = entry.enclosed_name().map(Path::to_path_buf) else {
            bail!("{}: entry `{}` would land outside the target directory", bad(), entry.name());
        };
        let out = to.join(&rel);
        if entry.is_dir() {
            std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
            continue;
        }
        if let Some(dir) = out.parent() {
            std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        }
        let mut w =
            std::fs::File::create(&out).with_context(|| format!("creating {}", out.display()))?;
        let n = std::io::copy(&mut entry, &mut w)
            .with_context(|| format!("{}: extracting `{}`", bad(), rel.display()))?;
        pb.inc(n);
        files += 1;
    }
    pb.finish_and_clear();
    Ok(files)
}
