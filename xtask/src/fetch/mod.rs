//! `cargo xtask fetch-data NAME`: downloads the files of one data manifest into the data root,
//! verifies each against its sha256 (published, computed from our copies, or accepted earlier into
//! the local lock), moves it into place atomically, and unpacks archives that ask for it.
//!
//! Per file: a verified final file is kept; otherwise it is downloaded into `<file>.part`
//! (resuming an existing part), checked, and renamed. A file whose manifest says
//! `sha256 = "unknown"` is only accepted with `--allow-unverified`, which records its computed
//! hash in `<root>/fetch-lock.toml` so that later fetches verify against it. Failures of single
//! files are collected; the command fails at the end naming each.

mod checksum_ledger;
mod http;
mod manifest;
mod progress;
mod unpack;

use anyhow::{Context, Result, bail};
use checksum_ledger::{Lock, Locked};
use manifest::{Entry, Manifest};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Options of the command.
pub struct Options {
    /// Manifest name (`None` only with `list`).
    pub name: Option<String>,
    /// Data root (`--dest`, else the process's, `experiments::places`).
    pub dest: PathBuf,
    /// Entry names to fetch (all when empty).
    pub only: Vec<String>,
    /// Print the manifests and their entries instead of fetching.
    pub list: bool,
    /// Accept files without a published checksum, recording their hash in the lock.
    pub allow_unverified: bool,
    /// Manifest directory (default: the workspace's `data-manifests/`).
    pub manifests: Option<PathBuf>,
}

/// The workspace's manifest directory.
fn default_manifests() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join("data-manifests")
}

/// Runs the command.
pub fn run(opts: Options) -> Result<()> {
    let dir = opts.manifests.clone().unwrap_or_else(default_manifests);
    if opts.list {
        let all = match &opts.name {
            Some(n) => vec![manifest::find(&dir, n)?],
            None => manifest::load_all(&dir)?,
        };
        manifest::print_list(&all);
        return Ok(());
    }
    let Some(name) = &opts.name else {
        bail!("name a manifest (see `cargo xtask fetch-data --list`)");
    };
    let m = manifest::find(&dir, name)?;
    let root = opts.dest.clone();
    let entries = select(&m, &opts.only)?;
    std::fs::create_dir_all(&root).with_context(|| format!("creating {}", root.display()))?;
    let mut lock = Lock::load(&root)?;
    eprintln!(
        "{} ({}): {} file(s) into {}",
        m.dataset.name,
        m.dataset.title,
        entries.len(),
        root.display()
    );
    eprintln!("    licence: {}", m.dataset.licence);
    eprintln!("    cite: {}", m.dataset.citation);
    let mut failures = Vec::new();
    for (i, e) in entries.iter().enumerate() {
        eprintln!("[{}/{}] {}", i + 1, entries.len(), e.dest);
        let ctx = Ctx { m: &m, root: &root, allow_unverified: opts.allow_unverified };
        if let Err(err) = fetch_one(&ctx, e, &mut lock) {
            eprintln!("    FAILED: {err:#}");
            failures.push(format!("{}: {err:#}", e.name));
        }
    }
    if !failures.is_empty() {
        bail!(
            "{} of {} file(s) of `{}` failed:\n  {}",
            failures.len(),
            entries.len(),
            m.dataset.name,
            failures.join("\n  ")
        );
    }
    eprintln!(
        "done: {} file(s) of `{}` verified under {}",
        entries.len(),
        m.dataset.name,
        root.display()
    );
    Ok(())
}

fn select<'a>(m: &'a Manifest, only: &[String]) -> Result<Vec<&'a Entry>> {
    if only.is_empty() {
        return Ok(m.files.iter().collect());
    }
    only.iter()
        .map(|n| {
            m.files.iter().find(|e| &e.name == n).ok_or_else(|| {
                let names: Vec<&str> = m.files.iter().map(|e| e.name.as_str()).collect();
                anyhow::anyhow!(
                    "`{n}` is not an entry of {} (entries: {})",
                    m.path.display(),
                    names.join(", ")
                )
            })
        })
        .collect()
}

struct Ctx<'a> {
    m: &'a Manifest,
    root: &'a Path,
    allow_unverified: bool,
}

/// The checksum a file must have, and where it comes from.
enum Expected {
    /// Published in (or computed for) the manifest.
    Manifest(String),
    /// Accepted earlier into the local lock.
    Lock(String),
    /// Nobody knows it yet.
    Unknown,
}

fn fetch_one(ctx: &Ctx, e: &Entry, lock: &mut Lock) -> Result<()> {
    let path = ctx.root.join(&e.dest);
    let expected = match (e.known_sha256(), lock.files.get(&e.dest)) {
        (Some(s), _) => Expected::Manifest(s.to_string()),
        (None, Some(l)) => Expected::Lock(l.sha256.clone()),
        (None, None) => Expected::Unknown,
    };
    let sha256 = if path.is_file() {
        let (found, len) = progress::sha256_file(&path, &format!("verifying {}", e.name))?;
        match &expected {
            Expected::Manifest(s) | Expected::Lock(s) if *s == found => {
                let how = if matches!(expected, Expected::Lock(_)) { " (local lock)" } else { "" };
                eprintln!("    present, sha256 verified{how}: kept");
                Some(found)
            }
            Expected::Unknown => {
                accept_unverified(ctx, e, lock, &path, &found, len, "present")?;
                Some(found)
            }
            Expected::Manifest(s) | Expected::Lock(s) => {
                eprintln!("    present but its sha256 is {found}, expected {s}: downloading again");
                None
            }
        }
    } else {
        None
    };
    let sha256 = match sha256 {
        Some(s) => s,
        None => download(ctx, e, lock, &path, &expected)?,
    };
    if let Some(u) = &e.unpack {
        let into = ctx.root.join(&u.into);
        match unpack::unzip(&path, &sha256, &into)? {
            unpack::Unpacked::Extracted(n) => {
                eprintln!("    unpacked {n} file(s) into {}", into.display())
            }
            unpack::Unpacked::Kept => eprintln!("    already unpacked into {}", into.display()),
        }
    }
    Ok(())
}

/// Downloads `e` into `<path>.part`, checks it, renames it onto `path`; returns its sha256.
fn download(
    ctx: &Ctx,
    e: &Entry,
    lock: &mut Lock,
    path: &Path,
    expected: &Expected,
) -> Result<String> {
    let Some(url) = &e.url else {
        bail!(
            "no direct download URL: download it by hand from {} (accept its terms: {}), save it \
             as {}, then run this again",
            ctx.m.page(e),
            ctx.m.licence(e),
            path.display()
        );
    };
    let part = part_path(path);
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let started = Instant::now();
    let mut got = http::download(url, &part, e.size, &e.name)?;
    let want = match expected {
        Expected::Manifest(s) | Expected::Lock(s) => Some(s.as_str()),
        Expected::Unknown => None,
    };
    if want.is_some_and(|w| w != got.sha256) && got.resumed_from > 0 {
        // The kept prefix may have been the corrupt part: one fresh download settles it.
        eprintln!("    checksum mismatch after resuming; downloading it whole again");
        std::fs::remove_file(&part).with_context(|| format!("removing {}", part.display()))?;
        got = http::download(url, &part, e.size, &e.name)?;
    }
    let secs = started.elapsed().as_secs_f64().max(1e-3);
    let fresh = got.len - got.resumed_from;
    eprintln!(
        "    downloaded {:.2} MB in {secs:.1} s ({:.2} MB/s){}",
        got.len as f64 / 1e6,
        fresh as f64 / 1e6 / secs,
        if got.resumed_from > 0 {
            format!(", resumed at byte {}", got.resumed_from)
        } else {
            String::new()
        }
    );
    check_download(ctx, e, lock, (url, &part, path), expected, &got)?;
    std::fs::rename(&part, path)
        .with_context(|| format!("renaming {} to {}", part.display(), path.display()))?;
    Ok(got.sha256)
}

/// Checks a finished download against the manifest's size and the expected sha256 (or its
/// published prefix, or the user's acceptance of an unverified file); a failed check discards
/// the part file.
fn check_download(
    ctx: &Ctx,
    e: &Entry,
    lock: &mut Lock,
    (url, part, path): (&str, &Path, &Path),
    expected: &Expected,
    got: &http::Fetched,
) -> Result<()> {
    let want = match expected {
        Expected::Manifest(s) | Expected::Lock(s) => Some(s.as_str()),
        Expected::Unknown => None,
    };
    if let Some(size) = e.size
        && size != got.len
    {
        discard(part);
        bail!("{url}: got {} bytes, the manifest says {size}; the download was discarded", got.len);
    }
    match (want, expected) {
        (Some(w), _) if w != got.sha256 => {
            discard(part);
            let from = if matches!(expected, Expected::Lock(_)) {
                "the local lock"
            } else {
                "the manifest"
            };
            bail!(
                "sha256 mismatch for {} from {url}: expected {w} ({from}), got {}; the download \
                 was discarded",
                path.display(),
                got.sha256
            );
        }
        (Some(_), Expected::Lock(_)) => eprintln!("    sha256 verified (local lock)"),
        (Some(_), _) => eprintln!("    sha256 verified"),
        (None, _) => {
            if let Some(p) = &e.sha256_prefix
                && !got.sha256.starts_with(p.as_str())
            {
                discard(part);
                bail!(
                    "sha256 of {url} is {}, which does not start with the published prefix {p}; \
                     the download was discarded",
                    got.sha256
                );
            }
            accept_unverified(ctx, e, lock, part, &got.sha256, got.len, "downloaded")?;
        }
    }
    Ok(())
}

/// Accepts a file without a known checksum when the user said so, recording it in the lock.
fn accept_unverified(
    ctx: &Ctx,
    e: &Entry,
    lock: &mut Lock,
    file: &Path,
    sha256: &str,
    len: u64,
    what: &str,
) -> Result<()> {
    let prefix = e
        .sha256_prefix
        .as_deref()
        .map_or(String::new(), |p| format!(" (matches the published prefix {p})"));
    if !ctx.allow_unverified {
        bail!(
            "no published sha256 for {}: the {what} file {} has sha256 {sha256}{prefix}, {len} \
             bytes; check it against the source, then run again with --allow-unverified to accept \
             it and record it in {}",
            e.dest,
            file.display(),
            lock.path().display()
        );
    }
    let url = e.url.clone().unwrap_or_default();
    lock.record(
        &e.dest,
        Locked { dataset: ctx.m.dataset.name.clone(), url, sha256: sha256.into(), size: len },
    )?;
    eprintln!(
        "    UNVERIFIED (no published checksum), accepted: sha256 {sha256}{prefix}, recorded in {}",
        lock.path().display()
    );
    Ok(())
}

fn part_path(path: &Path) -> PathBuf {
    let mut s = path.as_os_str().to_os_string();
    s.push(".part");
    PathBuf::from(s)
}

fn discard(part: &Path) {
    if let Err(err) = std::fs::remove_file(part) {
        eprintln!("    could not remove {}: {err}", part.display());
    }
}
