//! Folder locks: a process that works in a run directory or a sweep's output holds an exclusive
//! advisory lock on its `.lock` file ([`DirLock`]), so a second process on the same folder
//! refuses with a message naming the folder and the process that holds it instead of
//! interleaving its writes. The lock is the operating system's (`flock` on Unix, through
//! `std::fs::File::try_lock`): it goes away with the process, even one killed with SIGKILL, so
//! no stale lock ever needs clearing by hand. Taking a lock also removes the temporary files a
//! killed writer left in the folder ([`crate::fs::remove_temporaries`]).

use crate::fs::{Error, remove_temporaries_except};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The name of the lock file inside a locked folder.
pub const LOCK_FILE: &str = ".lock";

/// An exclusive lock on a folder, released when dropped (or when the process ends).
#[derive(Debug)]
pub struct DirLock {
    dir: PathBuf,
    _file: std::fs::File,
    /// Temporary files of a killed writer removed when the lock was taken.
    pub removed_temporaries: usize,
}

impl DirLock {
    /// Locks `dir` (created if missing) for this process, then removes the temporaries left in
    /// it. When another process holds the lock, the error names `dir`, that process's id and
    /// what it was doing (`what` of the holder, e.g. "training").
    pub fn acquire(dir: &Path, what: &str) -> Result<Self, Error> {
        std::fs::create_dir_all(dir).map_err(|e| Error::new(dir, e))?;
        let path = dir.join(LOCK_FILE);
        let mut file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&path)
            .map_err(|e| Error::new(&path, e))?;
        match file.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => {
                let holder = std::fs::read_to_string(&path).unwrap_or_default();
                let holder = holder.trim();
                let holder = if holder.is_empty() { "another process" } else { holder };
                return Err(Error::new(
                    dir,
                    std::io::Error::new(
                        std::io::ErrorKind::WouldBlock,
                        format!(
                            "in use by {holder}; wait for it to finish or stop it (its work is \
                             resumed by the next run)"
                        ),
                    ),
                ));
            }
            Err(std::fs::TryLockError::Error(e)) => return Err(Error::new(&path, e)),
        }
        let note = format!("process {} on {} ({what})", std::process::id(), host_name());
        file.set_len(0)
            .and_then(|()| file.write_all(note.as_bytes()))
            .map_err(|e| Error::new(&path, e))?;
        let removed_temporaries = remove_temporaries_except(dir, &held_by_another)?;
        Ok(Self { dir: dir.to_path_buf(), _file: file, removed_temporaries })
    }

    /// The locked folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }
}

/// The holder's note (`process <pid> on <host> (<what>)`) when another open lock holds `dir`'s
/// lock, `None` when nobody does (or `dir` has no lock file). Reads only: the lock, when free,
/// is taken and released at once, and no temporary is removed.
///
/// Across hosts this is as good as the file system's locks: local disks and NFS (v4, or v3
/// with its lock manager; Linux maps `flock` onto NFS byte-range locks) hold them; Lustre needs
/// its `flock` mount option.
pub fn holder(dir: &Path) -> Option<String> {
    let path = dir.join(LOCK_FILE);
    let file = std::fs::OpenOptions::new().read(true).write(true).open(&path).ok()?;
    match file.try_lock() {
        Err(std::fs::TryLockError::WouldBlock) => {
            let note = std::fs::read_to_string(&path).unwrap_or_default();
            let note = note.trim();
            Some(if note.is_empty() { "another process".into() } else { note.into() })
        }
        _ => None,
    }
}

/// This machine's host name (Linux's `/proc`, else `$HOSTNAME`, else `unknown host`): locks
/// name it, so that a holder on another node of a cluster is found.
pub fn host_name() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .ok()
        .or_else(|| std::env::var("HOSTNAME").ok())
        .map(|h| h.trim().to_string())
        .filter(|h| !h.is_empty())
        .unwrap_or_else(|| "unknown host".into())
}

/// Whether `dir` holds a lock file that another open lock holds (a folder a live process works
/// in: its temporaries are its own).
fn held_by_another(dir: &Path) -> bool {
    let path = dir.join(LOCK_FILE);
    let Ok(file) = std::fs::OpenOptions::new().read(true).write(true).open(&path) else {
        return false;
    };
    matches!(file.try_lock(), Err(std::fs::TryLockError::WouldBlock))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_lock_is_refused_with_the_holder_and_released_on_drop() {
        let d = std::env::temp_dir().join(format!("stdx-lock-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(d.join("sub")).unwrap();
        std::fs::write(d.join(".weights.bpk.tmp-abc"), b"half").unwrap();
        std::fs::create_dir(d.join("sub/.step-1.partial-xyz")).unwrap();
        std::fs::write(d.join("sub/kept.json"), b"{}").unwrap();
        let lock = DirLock::acquire(&d, "training").unwrap();
        assert_eq!(lock.removed_temporaries, 2);
        assert!(d.join("sub/kept.json").is_file());
        let err = DirLock::acquire(&d, "evaluating").unwrap_err().to_string();
        assert!(err.contains(&d.display().to_string()), "{err}");
        let note = format!("process {} on {} (training)", std::process::id(), host_name());
        assert!(err.contains(&note), "{err}");
        assert_eq!(holder(&d).as_deref(), Some(note.as_str()));
        assert_eq!(holder(&d.join("sub")), None, "no lock file there yet");
        // A sub-folder locked by another holder keeps its temporaries.
        let inner = DirLock::acquire(&d.join("sub"), "training").unwrap();
        std::fs::write(d.join("sub/.curve.csv.tmp-1"), b"live").unwrap();
        drop(lock);
        let outer = DirLock::acquire(&d, "sweeping").unwrap();
        assert_eq!(outer.removed_temporaries, 0);
        assert!(d.join("sub/.curve.csv.tmp-1").is_file());
        drop((outer, inner));
        let again = DirLock::acquire(&d, "evaluating").unwrap();
        assert_eq!(again.removed_temporaries, 1, "the sub-folder is free now");
        drop(again);
        assert_eq!(holder(&d), None, "released");
        assert!(DirLock::acquire(&d, "again").is_ok(), "holder() leaves the lock free");
        std::fs::remove_dir_all(&d).unwrap();
    }
}
