//! Data manifests (`data-manifests/<name>.toml`): what a dataset is made of and where each file
//! comes from, parsed strictly (unknown keys are errors) and validated (checksums, safe relative
//! destinations, unique names), every error naming the manifest file and the key.
//!
//! Schema (see `data-manifests/README.md` for the prose version):
//!
//! ```toml
//! [dataset]
//! name = "meshes"             # must equal the file stem
//! title = "..."               # one line
//! page = "https://..."        # the dataset's official page
//! licence = "..."             # default for every file
//! citation = "..."            # default for every file
//! notes = "..."               # optional
//!
//! [[file]]
//! name = "spot"               # unique in the manifest; what --only selects
//! url = "https://..."         # optional: without it the file is fetched by hand from `page`
//! sha256 = "0738b5..."        # 64 hex digits, or "unknown" (never invented)
//! sha256_prefix = "7be5be79"  # optional, with "unknown": a prefix the source publishes
//! size = 330624               # optional, bytes
//! dest = "meshes/spot.obj"    # relative path under the data root
//! unpack = { format = "zip", into = "diligent-mv" }  # optional
//! ```
//! Per-file `page`, `licence`, `citation` and `note` override or add to the dataset's.

use anyhow::{Context, Result, bail};
use serde::Deserialize;
use std::collections::BTreeSet;
use std::path::{Component, Path, PathBuf};

/// The placeholder for a checksum nobody could compute or find published.
pub const UNKNOWN: &str = "unknown";

/// One manifest file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// What the dataset is.
    pub dataset: Dataset,
    /// Its files.
    #[serde(rename = "file", default)]
    pub files: Vec<Entry>,
    /// The manifest's path (set by [`load`]).
    #[serde(skip)]
    pub path: PathBuf,
}

/// The `[dataset]` table.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Dataset {
    /// Name, equal to the manifest's file stem.
    pub name: String,
    /// One-line title.
    pub title: String,
    /// The dataset's official page.
    pub page: String,
    /// Licence or terms of use (default for every file).
    pub licence: String,
    /// How to cite it (default for every file).
    pub citation: String,
    /// Free-form notes.
    #[serde(default)]
    pub notes: Option<String>,
}

/// One `[[file]]` entry.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Entry {
    /// Unique name within the manifest.
    pub name: String,
    /// Direct download URL; `None` means the file is fetched by hand from the page.
    #[serde(default)]
    pub url: Option<String>,
    /// Page to fetch it from by hand, when it differs from the dataset's.
    #[serde(default)]
    pub page: Option<String>,
    /// Lower-case hex sha256, or [`UNKNOWN`].
    pub sha256: String,
    /// A published prefix of the sha256 (only with an unknown full checksum).
    #[serde(default)]
    pub sha256_prefix: Option<String>,
    /// Size in bytes, when known.
    #[serde(default)]
    pub size: Option<u64>,
    /// Where the file lands, relative to the data root.
    pub dest: String,
    /// Licence, when it differs from the dataset's.
    #[serde(default)]
    pub licence: Option<String>,
    /// Citation, when it differs from the dataset's.
    #[serde(default)]
    pub citation: Option<String>,
    /// Free-form note.
    #[serde(default)]
    pub note: Option<String>,
    /// Optional unpack step once the file is verified.
    #[serde(default)]
    pub unpack: Option<Unpack>,
}

/// An unpack step.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Unpack {
    /// Archive format; only "zip".
    pub format: String,
    /// Directory (relative to the data root) that receives the archive's contents.
    pub into: String,
}

impl Entry {
    /// The full expected sha256, if published or computed.
    pub fn known_sha256(&self) -> Option<&str> {
        (self.sha256 != UNKNOWN).then_some(self.sha256.as_str())
    }
}

impl Manifest {
    /// The licence of `entry` (its own or the dataset's).
    pub fn licence<'a>(&'a self, entry: &'a Entry) -> &'a str {
        entry.licence.as_deref().unwrap_or(&self.dataset.licence)
    }

    /// The page to fetch `entry` from by hand (its own or the dataset's).
    pub fn page<'a>(&'a self, entry: &'a Entry) -> &'a str {
        entry.page.as_deref().unwrap_or(&self.dataset.page)
    }
}

/// Reads and validates `path`.
pub fn load(path: &Path) -> Result<Manifest> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("reading manifest {}", path.display()))?;
    let mut m: Manifest =
        toml::from_str(&text).with_context(|| format!("manifest {} is invalid", path.display()))?;
    m.path = path.to_path_buf();
    validate(&m).with_context(|| format!("manifest {} is invalid", path.display()))?;
    Ok(m)
}

/// Every manifest (`*.toml`) in `dir`, sorted by name.
pub fn load_all(dir: &Path) -> Result<Vec<Manifest>> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("reading the manifest directory {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    paths.sort();
    paths.iter().map(|p| load(p)).collect()
}

/// The manifest called `name` in `dir`, with the available names when there is none.
pub fn find(dir: &Path, name: &str) -> Result<Manifest> {
    let path = dir.join(format!("{name}.toml"));
    if !path.is_file() {
        let names: Vec<String> = load_all(dir)?.into_iter().map(|m| m.dataset.name).collect();
        bail!("no manifest named `{name}` in {} (available: {})", dir.display(), names.join(", "));
    }
    load(&path)
}

fn validate(m: &Manifest) -> Result<()> {
    let stem = m.path.file_stem().and_then(|s| s.to_str()).unwrap_or_default();
    if m.dataset.name != stem {
        bail!("key `dataset.name`: `{}` must equal the file name `{stem}`", m.dataset.name);
    }
    if m.files.is_empty() {
        bail!("no `[[file]]` entries");
    }
    let mut names = BTreeSet::new();
    let mut dests = BTreeSet::new();
    for e in &m.files {
        let at = |key: &str| format!("file `{}`: key `{key}`", e.name);
        if e.name.is_empty() || !names.insert(e.name.as_str()) {
            bail!("{}: empty or duplicate name", at("name"));
        }
        if e.sha256 != UNKNOWN && !is_hex(&e.sha256, 64) {
            bail!("{}: must be 64 lower-case hex digits or \"unknown\"", at("sha256"));
        }
        if let Some(p) = &e.sha256_prefix {
            if e.sha256 != UNKNOWN {
                bail!("{}: only allowed with sha256 = \"unknown\"", at("sha256_prefix"));
            }
            if p.is_empty() || p.len() > 64 || !is_hex(p, p.len()) {
                bail!("{}: must be 1 to 64 lower-case hex digits", at("sha256_prefix"));
            }
        }
        match &e.url {
            Some(u) if !(u.starts_with("https://") || u.starts_with("http://")) => {
                bail!("{}: `{u}` is not an http(s) URL", at("url"))
            }
            _ => {}
        }
        check_relative(&e.dest).with_context(|| at("dest"))?;
        if !dests.insert(e.dest.as_str()) {
            bail!("{}: `{}` is used twice", at("dest"), e.dest);
        }
        if let Some(u) = &e.unpack {
            if u.format != "zip" {
                bail!("{}: unsupported format `{}` (only \"zip\")", at("unpack.format"), u.format);
            }
            check_relative(&u.into).with_context(|| at("unpack.into"))?;
            if Path::new(&e.dest).starts_with(&u.into) {
                bail!(
                    "{}: `{}` must not contain the archive `{}`",
                    at("unpack.into"),
                    u.into,
                    e.dest
                );
            }
        }
    }
    Ok(())
}

fn is_hex(s: &str, len: usize) -> bool {
    s.len() == len && s.bytes().all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b))
}

/// Errors unless `p` is a non-empty relative path without `..`, so it stays under the data root.
pub fn check_relative(p: &str) -> Result<()> {
    let path = Path::new(p);
    let ok = !p.is_empty()
        && path.components().all(|c| matches!(c, Component::Normal(_) | Component::CurDir));
    if !ok {
        bail!("`{p}` must be a relative path inside the data root (no `..`, not absolute)");
    }
    Ok(())
}

/// Prints every manifest and its entries (for `--list`).
pub fn print_list(manifests: &[Manifest]) {
    for m in manifests {
        let d = &m.dataset;
        let total: u64 = m.files.iter().filter_map(|e| e.size).sum();
        let unknown = m.files.iter().filter(|e| e.known_sha256().is_none()).count();
        let manual = m.files.iter().filter(|e| e.url.is_none()).count();
        println!("{} - {} ({} file(s), {:.1} MB known)", d.name, d.title, m.files.len(), mb(total));
        println!("    page: {}", d.page);
        println!("    licence: {}", d.licence);
        println!("    cite: {}", d.citation);
        if let Some(n) = &d.notes {
            println!("    notes: {}", n.trim());
        }
        if unknown > 0 {
            println!("    {unknown} file(s) without a published sha256 (see --allow-unverified)");
        }
        if manual > 0 {
            println!("    {manual} file(s) without a direct URL: download by hand from the page");
        }
        for e in &m.files {
            let sha =
                e.known_sha256().map_or("sha256 unknown".to_string(), |s| s[..12].to_string());
            let size = e.size.map_or("size unknown".to_string(), |s| format!("{s} B"));
            let how = if e.url.is_some() { "" } else { ", by hand" };
            let unpack = e.unpack.as_ref().map_or(String::new(), |u| format!(" -> {}/", u.into));
            println!("      {:<28} {}{unpack}  [{sha}, {size}{how}]", e.name, e.dest);
            for (key, v) in [("licence", &e.licence), ("cite", &e.citation), ("note", &e.note)] {
                if let Some(v) = v {
                    println!("        {key}: {}", v.trim());
                }
            }
        }
    }
}

fn mb(bytes: u64) -> f64 {
    bytes as f64 / 1e6
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
        std::fs::create_dir_all(dir).unwrap();
        let p = dir.join(format!("{name}.toml"));
        std::fs::write(&p, text).unwrap();
        p
    }

    fn tmp(tag: &str) -> PathBuf {
        std::env::temp_dir().join(format!("xtask-manifest-{tag}-{}", std::process::id()))
    }

    const HEAD: &str = "[dataset]\nname = \"t\"\ntitle = \"T\"\npage = \"https://example.invalid\"\n\
                        licence = \"CC0\"\ncitation = \"nobody\"\n";

    fn entry(extra: &str) -> String {
        format!(
            "{HEAD}[[file]]\nname = \"a\"\nurl = \"http://127.0.0.1/a\"\nsha256 = \"unknown\"\n\
             dest = \"t/a.bin\"\n{extra}"
        )
    }

    /// Every shipped data manifest, corrupted (test_support::corrupt): an error or a value,
    /// never a panic (issue 19).
    #[test]
    fn corrupted_manifests_give_errors_not_panics() {
        let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data-manifests");
        let seeds: Vec<Vec<u8>> = std::fs::read_dir(&shipped)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .map(|p| std::fs::read(p).unwrap())
            .collect();
        assert!(seeds.len() >= 5, "the shipped manifests");
        let d = tmp("fuzz");
        std::fs::create_dir_all(&d).unwrap();
        let path = d.join("corrupted.toml");
        let ran = test_support::corrupt::fuzz_loader("data-manifest", &seeds, 3000, |b| {
            std::fs::write(&path, b).unwrap();
            let _ = load(&path);
        });
        assert!(ran >= 3000);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn unknown_key_names_file_and_key() {
        let dir = tmp("unknown-key");
        let p = write(&dir, "t", &entry("colour = \"red\"\n"));
        let e = format!("{:#}", load(&p).unwrap_err());
        assert!(e.contains("t.toml") && e.contains("colour"), "{e}");
        let p = write(&dir, "t", &format!("{HEAD}homepage = \"x\"\n"));
        let e = format!("{:#}", load(&p).unwrap_err());
        assert!(e.contains("t.toml") && e.contains("homepage"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn semantic_errors_name_the_key() {
        let dir = tmp("semantic");
        for (extra, key) in [
            ("", ""),
            ("sha256_prefix = \"XYZ\"\n", "sha256_prefix"),
            ("unpack = { format = \"tar\", into = \"x\" }\n", "unpack.format"),
            ("unpack = { format = \"zip\", into = \"../x\" }\n", "unpack.into"),
        ] {
            let p = write(&dir, "t", &entry(extra));
            let r = load(&p);
            if key.is_empty() {
                r.unwrap();
            } else {
                let e = format!("{:#}", r.unwrap_err());
                assert!(e.contains(key) && e.contains("t.toml"), "{e}");
            }
        }
        let bad_dest = entry("").replace("t/a.bin", "/etc/passwd");
        let e = format!("{:#}", load(&write(&dir, "t", &bad_dest)).unwrap_err());
        assert!(e.contains("`dest`"), "{e}");
        let bad_sha = entry("").replace("\"unknown\"", "\"abc\"");
        let e = format!("{:#}", load(&write(&dir, "t", &bad_sha)).unwrap_err());
        assert!(e.contains("`sha256`"), "{e}");
        let e = format!("{:#}", load(&write(&dir, "other", &entry(""))).unwrap_err());
        assert!(e.contains("dataset.name"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The shipped manifests parse and validate; the mesh checksums match the shared copies they
    /// were computed from and the embedded Spot.
    #[test]
    fn shipped_manifests_are_valid() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data-manifests");
        let all = load_all(&dir).unwrap();
        let names: Vec<&str> = all.iter().map(|m| m.dataset.name.as_str()).collect();
        assert_eq!(names, ["diligent-mv", "diligent", "lpips", "merl", "meshes", "nbrdf"]);
        let meshes = all.iter().find(|m| m.dataset.name == "meshes").unwrap();
        assert_eq!(meshes.files.len(), 14);
        assert!(meshes.files.iter().all(|e| e.known_sha256().is_some() && e.size.is_some()));
        let merl = all.iter().find(|m| m.dataset.name == "merl").unwrap();
        assert_eq!(merl.files.len(), 100);
        let sha = |p: &Path| {
            use sha2::Digest;
            super::super::progress::hex(&sha2::Sha256::digest(std::fs::read(p).unwrap()))
        };
        let spot = meshes.files.iter().find(|e| e.name == "spot").unwrap();
        assert_eq!(Some(sha(&dir.join("embedded/spot/spot.obj")).as_str()), spot.known_sha256());
        let data = std::env::var_os("NEURAL_BRDF_DATA").map_or_else(
            || Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data"),
            PathBuf::from,
        );
        if !data.join("meshes").is_dir() {
            assert!(std::env::var("CI").is_err(), "shared data missing at {}", data.display());
            eprintln!("skipping the shared-copy check: {} not found", data.display());
            return;
        }
        for e in &meshes.files {
            let p = data.join(&e.dest);
            assert_eq!(Some(sha(&p).as_str()), e.known_sha256(), "{}", p.display());
            assert_eq!(Some(std::fs::metadata(&p).unwrap().len()), e.size, "{}", p.display());
        }
    }

    #[test]
    fn relative_paths() {
        assert!(check_relative("meshes/spot.obj").is_ok());
        for bad in ["", "/abs", "a/../../b", ".."] {
            assert!(check_relative(bad).is_err(), "{bad}");
        }
    }
}
