//! The on-disk cache of the precompute, keyed by content.
//!
//! **Key**: xxh3-128 over the format version, the mesh (positions and triangles, as bits), every
//! view (K, R, t, image size, mask, light directions) and the settings; file names play no part.
//! The file is `<dir>/raycast-<key as 32 hex digits>.bin`.
//!
//! **File format**: the workspace's cache container (`stdx::cache_file`: magic `NBRDFRCP`,
//! format version, key, the [`ScenePrecompute`] in postcard, xxh3-64 checksum).
//!
//! A file that does not check out (wrong magic, version or key, bad checksum, a payload that
//! does not decode or whose arrays disagree in length) is never trusted: it is recomputed and
//! replaced. Writes are atomic: a temporary file in the same directory, then a rename.

use std::path::{Path, PathBuf};

use mesh_encoding::{NormalWeighting, TriMesh};
use xxhash_rust::xxh3::Xxh3;

use crate::error::Result;
use crate::precompute::{
    PrecomputeSettings, ScenePrecompute, ShadowBias, View, precompute_with, validate_views,
};
use crate::shadows::Traversal;
use crate::tracer::Tracer;
use crate::visibility::Visibility;

/// Version of the cache format and of the precompute's semantics; bump on any change to either.
/// 2: the payload is the serde encoding of [`ScenePrecompute`] (postcard).
pub const FORMAT_VERSION: u32 = 3;

/// The first 8 bytes of every ray-casting cache file.
pub const MAGIC: &[u8; 8] = b"NBRDFRCP";

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
        for light in &v.lights {
            // Directional lights hash as before; a point light's position follows a NaN marker
            // that no valid direction has.
            let p = match light {
                crate::Light::Directional(d) => d,
                crate::Light::Point(p) => {
                    put(&f32::NAN.to_le_bytes());
                    p
                }
            };
            p.to_array().iter().for_each(|x| put(&x.to_le_bytes()));
        }
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
/// [`crate::Error::View`] for invalid views (as [`crate::precompute()`]) and [`crate::Error::Io`] when the cache
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
    stdx::cache_file::encode(MAGIC, FORMAT_VERSION, key, scene)
}

/// Checks and decodes the bytes of a cache file for `key` (what [`precompute_cached`] does
/// before it trusts a file); the error says which check failed. Public for tools that inspect
/// caches and for the fuzz targets.
pub fn decode(bytes: &[u8], key: u128) -> std::result::Result<ScenePrecompute, String> {
    let scene: ScenePrecompute = stdx::cache_file::decode(bytes, MAGIC, FORMAT_VERSION, key)?;
    for v in &scene.views {
        let n = v.pixels.len();
        let words = n * Visibility::words_for(v.lights.len());
        let lens = [v.triangles.len(), v.barycentrics.len(), v.positions.len()];
        let vis = &v.visibility;
        if lens.iter().chain([v.normals.len(), v.view_dirs.len()].iter()).any(|&l| l != n)
            || (vis.pixels, vis.lights) != (n, v.lights.len())
            || vis.lit.len() != words
            || vis.front.len() != words
        {
            return Err("inconsistent array lengths".into());
        }
    }
    Ok(scene)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Camera, precompute};
    use mesh_encoding::glam::Vec3;

    /// Corrupted payloads sealed with a valid checksum (what a bug in a writer, not a damaged
    /// disk, would produce) reach the decoder: an error or a value, never a panic, and no
    /// allocation beyond the cap (a length of 2^40 elements is an error) (issue 19).
    #[test]
    fn corrupted_payloads_past_the_checksum_give_errors_not_panics() {
        let positions = vec![Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::Y];
        let mesh = TriMesh::new(positions, vec![[0, 1, 2]]).unwrap();
        let camera = Camera::look_at(3.0 * Vec3::Z, Vec3::ZERO, Vec3::Y, 45.0, 6, 5).unwrap();
        let lights = vec![Vec3::Z.into(), Vec3::new(0.6, 0.0, 0.8).into()];
        let views = vec![View { camera, lights, mask: None }];
        let scene = precompute(&mesh, &views, &PrecomputeSettings::default()).unwrap();
        assert!(scene.views[0].pixels.len() > 3, "the seed covers some pixels");
        let bytes = encode(&scene, 42);
        assert_eq!(decode(&bytes, 42).unwrap(), scene);
        let seed = stdx::cache_file::payload(&bytes).unwrap().to_vec();
        let ran = test_support::corrupt::fuzz_loader("raycast-cache", &[seed], 3000, |b| {
            let _ = decode(&stdx::cache_file::seal(MAGIC, FORMAT_VERSION, 42, b), 42);
        });
        assert!(ran >= 3000);
    }
}
