//! Atomic, durable writes: a file ([`write_atomic`], [`write_atomic_with`]) or a whole directory
//! ([`write_dir_atomic`]) is assembled under a temporary name beside its destination, flushed to
//! disk (every file, and every folder of a directory), renamed into place, and then the folder
//! holding it is flushed too, so a reader, a run killed half-way or a power cut never sees a
//! half-written one. The temporary files come from `tempfile` (unique names, removed on every
//! error path) and get the permissions an ordinary `File::create` would (the umask applies).
//!
//! Every temporary name starts with `.` and contains `.tmp-` or `.partial-`
//! ([`is_temporary`]); a process killed between creating one and renaming it leaves it behind,
//! and the next process that takes the folder's lock ([`crate::lock`]) removes it
//! ([`remove_temporaries`]).
//!
//! Every error names the path it concerns ([`Error`]); each crate converts it into its own error
//! type with a `From` impl.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// An I/O error and the path it happened on.
#[derive(Debug)]
pub struct Error {
    /// The file or directory.
    pub path: PathBuf,
    /// What went wrong.
    pub source: std::io::Error,
}

impl Error {
    /// An error on `path`.
    pub fn new(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Self { path: path.into(), source }
    }
}

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.path.display(), self.source)
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        Some(&self.source)
    }
}

/// The directory `path` lives in (`.` for a bare file name).
fn parent_dir(path: &Path) -> &Path {
    path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."))
}

/// The final component of `path` as text, for temporary names.
fn file_name(path: &Path, fallback: &str) -> String {
    path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| fallback.into())
}

/// A `tempfile` builder whose files and directories get ordinary permissions (0o666 / 0o777
/// before the umask, as `File::create` and `create_dir` give) instead of tempfile's private 0o600.
fn builder<'a>(prefix: &'a str, dir: bool) -> tempfile::Builder<'a, 'static> {
    let mut b = tempfile::Builder::new();
    b.prefix(prefix);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        b.permissions(std::fs::Permissions::from_mode(if dir { 0o777 } else { 0o666 }));
    }
    #[cfg(not(unix))]
    let _ = dir;
    b
}

/// Whether a file name is one of this module's temporary names (a leftover of a killed
/// process once nobody holds the folder's lock).
pub fn is_temporary(name: &str) -> bool {
    name.starts_with('.') && (name.contains(".tmp-") || name.contains(".partial-"))
}

/// Flushes a directory's entries (a rename or a new file in it) to disk.
pub fn sync_dir(dir: &Path) -> Result<(), Error> {
    #[cfg(unix)]
    std::fs::File::open(dir).and_then(|f| f.sync_all()).map_err(|e| Error::new(dir, e))?;
    #[cfg(not(unix))]
    let _ = dir;
    Ok(())
}

/// Flushes every file and folder under `dir` (and `dir` itself) to disk.
fn sync_tree(dir: &Path) -> Result<(), Error> {
    for entry in std::fs::read_dir(dir).map_err(|e| Error::new(dir, e))? {
        let entry = entry.map_err(|e| Error::new(dir, e))?;
        let path = entry.path();
        let kind = entry.file_type().map_err(|e| Error::new(&path, e))?;
        if kind.is_dir() {
            sync_tree(&path)?;
        } else if kind.is_file() {
            std::fs::File::open(&path)
                .and_then(|f| f.sync_all())
                .map_err(|e| Error::new(&path, e))?;
        }
    }
    sync_dir(dir)
}

/// Removes the temporary files and folders ([`is_temporary`]) under `root`, at any depth
/// (symbolic links are not followed); returns how many were removed. Call it only while holding
/// `root`'s lock: a temporary of a live writer would be pulled from under it.
pub fn remove_temporaries(root: &Path) -> Result<usize, Error> {
    remove_temporaries_except(root, &|_| false)
}

/// [`remove_temporaries`], leaving alone the folders (and all below them) for which `skip` is
/// true (the folders another live process holds the lock of).
pub fn remove_temporaries_except(
    root: &Path,
    skip: &dyn Fn(&Path) -> bool,
) -> Result<usize, Error> {
    let entries = match std::fs::read_dir(root) {
        Ok(e) => e,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(0),
        Err(e) => return Err(Error::new(root, e)),
    };
    let mut removed = 0;
    for entry in entries {
        let entry = entry.map_err(|e| Error::new(root, e))?;
        let path = entry.path();
        let kind = entry.file_type().map_err(|e| Error::new(&path, e))?;
        if is_temporary(&entry.file_name().to_string_lossy()) {
            let r = if kind.is_dir() {
                std::fs::remove_dir_all(&path)
            } else {
                std::fs::remove_file(&path)
            };
            r.map_err(|e| Error::new(&path, e))?;
            removed += 1;
        } else if kind.is_dir() && !skip(&path) {
            removed += remove_temporaries_except(&path, skip)?;
        }
    }
    Ok(removed)
}

/// Writes `bytes` to `path` atomically and durably, creating the parent directory if needed.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), Error> {
    let dir = parent_dir(path);
    std::fs::create_dir_all(dir).map_err(|e| Error::new(dir, e))?;
    let prefix = format!(".{}.tmp-", file_name(path, "file"));
    let mut file = builder(&prefix, false).tempfile_in(dir).map_err(|e| Error::new(dir, e))?;
    file.write_all(bytes)
        .and_then(|()| file.as_file().sync_all())
        .map_err(|e| Error::new(file.path(), e))?;
    file.persist(path).map_err(|e| Error::new(path, e.error))?;
    sync_dir(dir)
}

/// Writes `path` atomically through a writer that wants a path of its own (burn's record
/// files): `write` fills a temporary sibling that keeps `path`'s file name as its suffix (so its
/// extension too), which is then flushed and renamed over `path`. On any error the temporary
/// file is removed and `path` is left as it was.
pub fn write_atomic_with<E: From<Error>>(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), E>,
) -> Result<(), E> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let dir = parent_dir(path);
    std::fs::create_dir_all(dir).map_err(|e| Error::new(dir, e))?;
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let tmp = dir.join(format!(".tmp-{}-{n}-{}", std::process::id(), file_name(path, "file")));
    let result = write(&tmp).and_then(|()| {
        std::fs::File::open(&tmp).and_then(|f| f.sync_all()).map_err(|e| Error::new(&tmp, e))?;
        std::fs::rename(&tmp, path).map_err(|e| Error::new(path, e))?;
        sync_dir(dir).map_err(E::from)
    });
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Builds the directory `out` atomically: `build` fills a fresh temporary sibling of `out`
/// (with `subdirs` created), which is flushed to disk whole and then replaces `out`. On an error
/// the temporary directory is removed and `out` is left as it was. (Replacing an existing `out`
/// takes two renames' time during which neither is in place; a reader treats a missing `out` as
/// not yet written.)
pub fn write_dir_atomic<T, E: From<Error>>(
    out: &Path,
    subdirs: &[&str],
    build: impl FnOnce(&Path) -> Result<T, E>,
) -> Result<T, E> {
    let parent = parent_dir(out);
    std::fs::create_dir_all(parent).map_err(|e| Error::new(parent, e))?;
    let prefix = format!(".{}.partial-", file_name(out, "dir"));
    let tmp = builder(&prefix, true).tempdir_in(parent).map_err(|e| Error::new(parent, e))?;
    for sub in subdirs {
        let d = tmp.path().join(sub);
        std::fs::create_dir_all(&d).map_err(|e| Error::new(&d, e))?;
    }
    // On an error `tmp` is dropped here, which removes it.
    let value = build(tmp.path())?;
    sync_tree(tmp.path())?;
    let tmp = tmp.keep();
    // The old directory is first renamed aside under a temporary name (one atomic step), so a
    // kill at any moment leaves either the old or the new one whole at `out`, or neither (and
    // the old one under a temporary name, removed by the next `remove_temporaries`), never a
    // half-deleted one.
    let aside = parent.join(format!(
        "{prefix}old-{}",
        tmp.file_name()
            .map_or_else(|| std::process::id().to_string(), |n| n.to_string_lossy().into_owned(),)
    ));
    let replace = || -> Result<bool, Error> {
        let had_old = out.exists();
        if had_old {
            std::fs::rename(out, &aside).map_err(|e| Error::new(out, e))?;
        }
        std::fs::rename(&tmp, out).map_err(|e| Error::new(out, e))?;
        Ok(had_old)
    };
    match replace() {
        Ok(had_old) => {
            sync_dir(parent)?;
            if had_old {
                std::fs::remove_dir_all(&aside).map_err(|e| Error::new(&aside, e))?;
            }
        }
        Err(e) => {
            let _ = std::fs::remove_dir_all(&tmp);
            if aside.exists() && !out.exists() {
                let _ = std::fs::rename(&aside, out);
            }
            return Err(e.into());
        }
    }
    Ok(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("stdx-fs-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        d
    }

    fn entries(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn a_file_is_replaced_whole_and_no_temporary_is_left() {
        let d = scratch("file");
        let p = d.join("sub/out.json");
        write_atomic(&p, b"first").unwrap();
        write_atomic(&p, b"second").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"second");
        assert_eq!(entries(&d.join("sub")), ["out.json"]);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn files_get_the_permissions_of_an_ordinary_create() {
        use std::os::unix::fs::PermissionsExt;
        let d = scratch("mode");
        write_atomic(&d.join("atomic"), b"x").unwrap();
        std::fs::File::create(d.join("plain")).unwrap();
        let mode = |n: &str| std::fs::metadata(d.join(n)).unwrap().permissions().mode();
        assert_eq!(mode("atomic"), mode("plain"));
        write_dir_atomic::<_, Error>(&d.join("dir"), &[], |_| Ok(())).unwrap();
        std::fs::create_dir(d.join("plain-dir")).unwrap();
        assert_eq!(mode("dir"), mode("plain-dir"));
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_failing_writer_leaves_the_old_file_and_no_temporary() {
        let d = scratch("with");
        let p = d.join("weights.bpk");
        write_atomic_with::<Error>(&p, |tmp| {
            assert!(tmp.to_string_lossy().ends_with("weights.bpk"), "keeps the extension");
            std::fs::write(tmp, b"old").map_err(|e| Error::new(tmp, e))
        })
        .unwrap();
        let failed = write_atomic_with::<Error>(&p, |tmp| {
            std::fs::write(tmp, b"half").unwrap();
            Err(Error::new(tmp, std::io::Error::other("writer failed")))
        });
        assert!(failed.is_err());
        assert_eq!(std::fs::read(&p).unwrap(), b"old");
        assert_eq!(entries(&d), ["weights.bpk"]);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_failing_directory_build_leaves_the_old_directory_and_no_temporary() {
        let d = scratch("dir");
        let out = d.join("scene");
        write_dir_atomic::<_, Error>(&out, &["images"], |tmp| {
            assert!(tmp.join("images").is_dir());
            std::fs::write(tmp.join("manifest.json"), b"v1").map_err(|e| Error::new(tmp, e))
        })
        .unwrap();
        let failed = write_dir_atomic::<(), Error>(&out, &["images"], |tmp| {
            std::fs::write(tmp.join("manifest.json"), b"v2").unwrap();
            Err(Error::new(tmp, std::io::Error::other("build failed")))
        });
        assert!(failed.is_err());
        assert_eq!(std::fs::read(out.join("manifest.json")).unwrap(), b"v1");
        assert_eq!(entries(&d), ["scene"]);
        let value = write_dir_atomic::<_, Error>(&out, &[], |_| Ok(7)).unwrap();
        assert_eq!(value, 7);
        assert!(!out.join("manifest.json").exists(), "the new directory replaced the old one");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn errors_name_the_path() {
        let d = scratch("err");
        std::fs::create_dir_all(&d).unwrap();
        std::fs::write(d.join("a-file"), b"").unwrap();
        let e = write_atomic(&d.join("a-file/below"), b"x").unwrap_err();
        assert!(e.to_string().contains("a-file"), "{e}");
        std::fs::remove_dir_all(&d).unwrap();
    }
}
