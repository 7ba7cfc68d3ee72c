//! The on-disk cache of the precompute, keyed by content.
//!
//! **Key**: xxh3-128 over the format version, the mesh (positions and triangles, as bits), every
//! view (K, R, t, image size, mask, light directions) and the settings; file names play no part.
//! The file is `<dir>/raycast-<key as 32 hex digits>.bin`.
//!
//! **File format** (all little endian):
//! `magic "NBRDFRCP"` | `u32 format version` | `u128 key` | `u64 payload length` | payload |
//! `u64 xxh3-64 checksum of the payload`. The payload holds the shadow bias, the ray counts and,
//! per view, the arrays of [`crate::ViewPrecompute`] with length prefixes.
//!
//! A file that does not check out (wrong magic, version or key, wrong length, bad checksum,
//! inconsistent payload) is never trusted: it is recomputed and replaced. Writes are atomic: a
//! temporary file in the same directory, then a rename.

use std::path::{Path, PathBuf};

use mesh_encoding::{NormalWeighting, TriMesh};
use xxhash_rust::xxh3::{Xxh3, xxh3_64};

use crate::binio::{ReadResult, Reader, Writer};
use crate::error::Result;
use crate::precompute::{
    PrecomputeSettings, ScenePrecompute, ShadowBias, TraceStats, View, ViewPrecompute,
    precompute_with, validate_views,
};
use crate::shadows::Traversal;
use crate::tracer::Tracer;
use crate::visibility::Visibility;

/// Version of the cache format and of the precompute's semantics; bump on any change to either.
pub const FORMAT_VERSION: u32 = 1;

const MAGIC: &[u8; 8] = b"NBRDFRCP";
const HEADER: usize = 8 + 4 + 16 + 8;

/// How [`precompute_cached`] obtained its result.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CacheOutcome {
    /// Loaded from a valid cache file.
    Hit,
    /// No cache file: computed and stored.
    Miss,
    /// A cache file existed but failed a check: recomputed and replaced.
    Rebuilt {
        /// Which check failed.
        reason: String,
    },
}

/// The content key of a precompute, see the module documentation.
pub fn cache_key(mesh: &TriMesh, views: &[View], settings: &PrecomputeSettings) -> u128 {
    let mut h = Xxh3::new();
    let mut put = |bytes: &[u8]| h.update(bytes);
    put(MAGIC);
    put(&FORMAT_VERSION.to_le_bytes());
    put(&(mesh.positions.len() as u64).to_le_bytes());
    for p in &mesh.positions {
        p.to_array().iter().for_each(|x| put(&x.to_le_bytes()));
    }
    put(&(mesh.triangles.len() as u64).to_le_bytes());
    for t in &mesh.triangles {
        t.iter().for_each(|i| put(&i.to_le_bytes()));
    }
    put(&(views.len() as u64).to_le_bytes());
    for v in views {
        let c = &v.camera;
        for m in [c.k, c.r] {
            m.to_cols_array().iter().for_each(|x| put(&x.to_le_bytes()));
        }
        c.t.to_array().iter().for_each(|x| put(&x.to_le_bytes()));
        put(&c.width.to_le_bytes());
        put(&c.height.to_le_bytes());
        match &v.mask {
            None => put(&[0]),
            Some(m) => {
                put(&[1]);
                put(&m.iter().map(|&b| u8::from(b)).collect::<Vec<u8>>());
            }
        }
        put(&(v.lights.len() as u64).to_le_bytes());
        v.lights.iter().for_each(|l| l.to_array().iter().for_each(|x| put(&x.to_le_bytes())));
    }
    match settings.shadow_bias {
        ShadowBias::Relative(f) => put(&[0].into_iter().chain(f.to_le_bytes()).collect::<Vec<_>>()),
        ShadowBias::Absolute(d) => put(&[1].into_iter().chain(d.to_le_bytes()).collect::<Vec<_>>()),
    }
    put(&[match settings.normal_weighting {
        NormalWeighting::Angle => 0,
        NormalWeighting::Area => 1,
    }]);
    h.digest128()
}

/// The cache file for a key.
pub fn cache_path(dir: &Path, key: u128) -> PathBuf {
    dir.join(format!("raycast-{key:032x}.bin"))
}

/// The precompute of [`crate::precompute()`], loaded from `cache_dir` when a valid file for the same
/// content exists, else computed and stored there (the directory is created if needed).
///
/// # Errors
/// [`Error::View`] for invalid views (as [`crate::precompute()`]) and [`Error::Io`] when the cache
/// directory or file cannot be created or written. A corrupted file is not an error.
pub fn precompute_cached(
    mesh: &TriMesh,
    views: &[View],
    settings: &PrecomputeSettings,
    cache_dir: &Path,
) -> Result<(ScenePrecompute, CacheOutcome)> {
    let lights = validate_views(views)?;
    let key = cache_key(mesh, views, settings);
    let path = cache_path(cache_dir, key);
    let outcome = match std::fs::read(&path) {
        Ok(bytes) => match decode(&bytes, key) {
            Ok(scene) => return Ok((scene, CacheOutcome::Hit)),
            Err(reason) => CacheOutcome::Rebuilt { reason },
        },
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => CacheOutcome::Miss,
        Err(e) => CacheOutcome::Rebuilt { reason: format!("unreadable: {e}") },
    };
    let scene = precompute_with(&Tracer::new(mesh), views, &lights, settings, Traversal::default());
    stdx::fs::write_atomic(&path, &encode(&scene, key))?;
    Ok((scene, outcome))
}

/// The complete file for a scene.
pub(crate) fn encode(scene: &ScenePrecompute, key: u128) -> Vec<u8> {
    let mut w = Writer::default();
    w.f32(scene.shadow_bias);
    w.u64(scene.stats.primary_rays);
    w.u64(scene.stats.shadow_rays);
    w.u64(scene.stats.skipped_back_facing);
    w.u64(scene.views.len() as u64);
    for v in &scene.views {
        w.u32(v.width);
        w.u32(v.height);
        w.u32s(&v.pixels);
        w.u32s(&v.triangles);
        w.vec2s(&v.barycentrics);
        w.vec3s(&v.positions);
        w.vec3s(&v.normals);
        w.vec3s(&v.view_dirs);
        w.vec3s(&v.lights);
        w.u64s(&v.visibility.lit);
        w.u64s(&v.visibility.front);
    }
    let payload = w.bytes;
    let mut out = Vec::with_capacity(HEADER + payload.len() + 8);
    out.extend(MAGIC);
    out.extend(FORMAT_VERSION.to_le_bytes());
    out.extend(key.to_le_bytes());
    out.extend((payload.len() as u64).to_le_bytes());
    out.extend(&payload);
    out.extend(xxh3_64(&payload).to_le_bytes());
    out
}

/// Checks and decodes a file; the error says which check failed.
pub(crate) fn decode(bytes: &[u8], key: u128) -> ReadResult<ScenePrecompute> {
    if bytes.len() < HEADER + 8 || &bytes[..8] != MAGIC {
        return Err("not a cache file (magic or size)".into());
    }
    let mut header = Reader::new(&bytes[8..HEADER]);
    let version = header.u32()?;
    if version != FORMAT_VERSION {
        return Err(format!("format version {version}, expected {FORMAT_VERSION}"));
    }
    let stored_key = u128::from(header.u64()?) | (u128::from(header.u64()?) << 64);
    if stored_key != key {
        return Err("key mismatch".into());
    }
    let len = header.u64()?;
    if len != (bytes.len() - HEADER - 8) as u64 {
        return Err(format!("payload length {len} does not match the file size"));
    }
    let payload = &bytes[HEADER..bytes.len() - 8];
    let checksum = u64::from_le_bytes(bytes[bytes.len() - 8..].try_into().expect("8 bytes"));
    if xxh3_64(payload) != checksum {
        return Err("checksum mismatch".into());
    }
    let mut r = Reader::new(payload);
    let shadow_bias = r.f32()?;
    let stats =
        TraceStats { primary_rays: r.u64()?, shadow_rays: r.u64()?, skipped_back_facing: r.u64()? };
    let n_views = r.u64()?;
    let mut views = Vec::new();
    for _ in 0..n_views {
        let (width, height) = (r.u32()?, r.u32()?);
        let pixels = r.u32s()?;
        let n = pixels.len();
        let v = ViewPrecompute {
            width,
            height,
            pixels,
            triangles: r.u32s()?,
            barycentrics: r.vec2s()?,
            positions: r.vec3s()?,
            normals: r.vec3s()?,
            view_dirs: r.vec3s()?,
            lights: r.vec3s()?,
            visibility: Visibility::default(),
        };
        let (lit, front) = (r.u64s()?, r.u64s()?);
        let words = n * Visibility::words_for(v.lights.len());
        let lens = [v.triangles.len(), v.barycentrics.len(), v.positions.len()];
        if lens.iter().chain([v.normals.len(), v.view_dirs.len()].iter()).any(|&l| l != n)
            || lit.len() != words
            || front.len() != words
        {
            return Err("inconsistent array lengths".into());
        }
        let visibility = Visibility { pixels: n, lights: v.lights.len(), lit, front };
        views.push(ViewPrecompute { visibility, ..v });
    }
    if !r.is_empty() {
        return Err("trailing bytes in the payload".into());
    }
    Ok(ScenePrecompute { views, shadow_bias, stats })
}
