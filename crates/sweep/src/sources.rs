//! Where a profile's scenes come from: mesh sources (`embedded:NAME`, shipped inside the
//! binary; `data:PATH`, under the data root; or a path) and real captures (`diligent:NAME`,
//! `diligent-mv:NAME`, `data:PATH` or a path), each resolved to a file or directory with an
//! error that says what is missing and where to get it.
//!
//! The embedded meshes (Spot, CC0, with its notice) are compiled into the binary, so a
//! profile that uses them runs from any directory, without the source tree: the first use
//! writes the mesh to a content-named folder of the system's temporary directory
//! (`neural-brdfs-embedded-<xxh3 of the OBJ>/`, atomically, beside its `NOTICE.md`), whose path
//! is the same in every process and checkout on the machine.

use experiments::{Error, Result};
use std::path::{Path, PathBuf};

/// The meshes shipped inside the binary: (name, OBJ bytes, notice).
const EMBEDDED: [(&str, &[u8], &str); 1] = [(
    "spot",
    include_bytes!("../../../data-manifests/embedded/spot/spot.obj"),
    include_str!("../../../data-manifests/embedded/spot/NOTICE.md"),
)];

/// The names of the embedded meshes.
pub fn embedded_meshes() -> Vec<&'static str> {
    EMBEDDED.iter().map(|e| e.0).collect()
}

/// The file of the embedded mesh `name`, written from the binary on first use (and again if it
/// was removed or altered).
pub fn embedded_mesh(name: &str) -> Result<PathBuf> {
    let Some((_, obj, notice)) = EMBEDDED.iter().find(|e| e.0 == name) else {
        return Err(Error::config(
            "data.meshes",
            format!(
                "embedded:{name} is not shipped (embedded meshes: {})",
                embedded_meshes().join(", ")
            ),
        ));
    };
    let hash = xxhash_rust::xxh3::xxh3_64(obj);
    let dir = std::env::temp_dir().join(format!("neural-brdfs-embedded-{hash:016x}"));
    let path = dir.join(format!("{name}.obj"));
    if std::fs::read(&path).ok().as_deref() != Some(*obj) {
        std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
        stdx::fs::write_atomic(&dir.join("NOTICE.md"), notice.as_bytes())?;
        stdx::fs::write_atomic(&path, obj)?;
    }
    Ok(path)
}

/// Resolves a mesh source: `embedded:NAME` -> the mesh shipped inside the binary
/// ([`embedded_mesh`]), `data:PATH` -> `<data root>/PATH`, anything else a path.
pub fn resolve_mesh(source: &str, data_root: &Path) -> Result<PathBuf> {
    if let Some(name) = source.strip_prefix("embedded:") {
        return embedded_mesh(name);
    }
    let path = match source.strip_prefix("data:") {
        Some(rel) => data_root.join(rel),
        None => PathBuf::from(source),
    };
    if !path.is_file() {
        let hint = if source.starts_with("data:") {
            " (fetch it with `cargo xtask fetch-data meshes`, or set NEURAL_BRDF_DATA)"
        } else {
            ""
        };
        return Err(Error::format(&path, format!("mesh {source} not found{hint}")));
    }
    Ok(path)
}

/// A short name of a mesh source (its file stem).
pub fn mesh_name(source: &str) -> String {
    let s = source.rsplit(':').next().unwrap_or(source);
    Path::new(s).file_stem().and_then(|n| n.to_str()).unwrap_or(s).to_string()
}

/// A real capture of a profile: `diligent:NAME` (a single-view DiLiGenT object, so far the
/// ball), `diligent-mv:NAME` (a DiLiGenT-MV object: bear, buddha, cow, pot2, reading), or
/// `data:PATH` / a path to a capture directory of either layout.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum CaptureSource {
    /// A single-view DiLiGenT object.
    Diligent(String),
    /// A DiLiGenT-MV object.
    DiligentMv(String),
    /// A capture directory: under the data root (`data:`), or a path.
    Path {
        /// The path as written, without `data:`.
        path: String,
        /// Whether it is relative to the data root.
        under_root: bool,
    },
}

impl CaptureSource {
    /// Parses a profile's capture entry.
    pub fn parse(s: &str) -> std::result::Result<Self, String> {
        let name = |n: &str| -> std::result::Result<String, String> {
            if n.is_empty() || !n.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
                Err(format!("{s:?}: {n:?} is not an object name"))
            } else {
                Ok(n.to_string())
            }
        };
        if let Some(n) = s.strip_prefix("diligent-mv:") {
            Ok(CaptureSource::DiligentMv(name(n)?))
        } else if let Some(n) = s.strip_prefix("diligent:") {
            Ok(CaptureSource::Diligent(name(n)?))
        } else if let Some(p) = s.strip_prefix("data:") {
            Ok(CaptureSource::Path { path: p.to_string(), under_root: true })
        } else if s.is_empty() {
            Err("an empty capture entry".into())
        } else {
            Ok(CaptureSource::Path { path: s.to_string(), under_root: false })
        }
    }

    /// The object's name (the scene's name in the sweep).
    pub fn object(&self) -> String {
        match self {
            CaptureSource::Diligent(n) | CaptureSource::DiligentMv(n) => n.clone(),
            CaptureSource::Path { path, .. } => {
                let p = Path::new(path.trim_end_matches('/'));
                let n = p.file_name().and_then(|n| n.to_str()).unwrap_or("capture");
                n.strip_suffix("PNG").unwrap_or(n).to_string()
            }
        }
    }

    /// The directories it may be in, in the order they are tried: a benchmark's layout as the
    /// shared data has it and as `cargo xtask fetch-data` unpacks its zip.
    pub fn candidates(&self, data_root: &Path) -> Vec<PathBuf> {
        match self {
            CaptureSource::Diligent(n) => vec![
                data_root.join(format!("diligent/pmsData/{n}PNG")),
                data_root.join(format!("diligent/DiLiGenT/pmsData/{n}PNG")),
            ],
            CaptureSource::DiligentMv(n) => vec![
                data_root.join(format!("diligent-mv/mvpmsData/{n}PNG")),
                data_root.join(format!("diligent-mv/DiLiGenT-MV/mvpmsData/{n}PNG")),
            ],
            CaptureSource::Path { path, under_root: true } => vec![data_root.join(path)],
            CaptureSource::Path { path, under_root: false } => vec![PathBuf::from(path)],
        }
    }

    /// The capture's directory under `data_root`, or an error naming every place looked in
    /// and how to get the data.
    pub fn find(&self, data_root: &Path) -> Result<PathBuf> {
        let candidates = self.candidates(data_root);
        if let Some(dir) = candidates.iter().find(|d| d.is_dir()) {
            return Ok(dir.clone());
        }
        let how = match self {
            CaptureSource::Diligent(_) => {
                "get DiLiGenT with `cargo xtask fetch-data diligent` (a zip downloaded by hand: \
                 data-manifests/diligent.toml says from where), or point NEURAL_BRDF_DATA (or \
                 --data) at a data root that has it"
            }
            CaptureSource::DiligentMv(_) => {
                "get DiLiGenT-MV with `cargo xtask fetch-data diligent-mv` (a zip downloaded by \
                 hand: data-manifests/diligent-mv.toml says from where), or point \
                 NEURAL_BRDF_DATA (or --data) at a data root that has it"
            }
            CaptureSource::Path { .. } => "check the path",
        };
        let looked: Vec<String> = candidates.iter().map(|c| c.display().to_string()).collect();
        Err(Error::format(
            &candidates[0],
            format!("capture not found (looked in {}); {how}", looked.join(" and ")),
        ))
    }

    /// The data set label its runs carry.
    pub fn dataset(&self, dir: &Path) -> &'static str {
        match self {
            CaptureSource::Diligent(_) => "DiLiGenT",
            CaptureSource::DiligentMv(_) => "DiLiGenT-MV",
            CaptureSource::Path { .. } if dir.join("view_01").is_dir() => "DiLiGenT-MV",
            CaptureSource::Path { .. } => "DiLiGenT",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mesh_sources() {
        assert_eq!(mesh_name("embedded:spot"), "spot");
        assert_eq!(mesh_name("data:meshes/stanford-bunny.obj"), "stanford-bunny");
        let spot = resolve_mesh("embedded:spot", Path::new(".")).unwrap();
        // Written from the binary, outside the source tree, with its notice.
        let source = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        assert!(!spot.starts_with(std::path::absolute(&source).unwrap()), "{}", spot.display());
        assert_eq!(std::fs::read(&spot).unwrap(), EMBEDDED[0].1);
        assert!(spot.with_file_name("NOTICE.md").is_file());
        assert_eq!(resolve_mesh("embedded:spot", Path::new("/x")).unwrap(), spot);
        let e = resolve_mesh("embedded:bunny", Path::new(".")).unwrap_err().to_string();
        assert!(e.contains("embedded meshes: spot"), "{e}");
        let e = resolve_mesh("data:meshes/nope.obj", Path::new("/nonexistent")).unwrap_err();
        assert!(e.to_string().contains("fetch-data"), "{e}");
    }
}
