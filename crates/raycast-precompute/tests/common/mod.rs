//! Shared helpers of the integration tests: the shared data folder, temporary directories, a
//! deterministic random generator and scene builders.

#![allow(dead_code)]

use std::path::PathBuf;

use mesh_encoding::glam::Vec3;
use mesh_encoding::{LoadOptions, TriMesh, load_mesh};

#[path = "../../../../test-support/shared_data.rs"]
mod support;

/// The shared data folder (`$NEURAL_BRDF_DATA`, default `<workspace>/../shared/data`) when
/// it holds `meshes/`; see `test-support/shared_data.rs`.
pub fn data_dir() -> Option<PathBuf> {
    support::shared_data_root("meshes")
}

/// A shared mesh, cleaned and normalised into the unit sphere.
pub fn shared_mesh(name: &str) -> Option<TriMesh> {
    let path = data_dir()?.join("meshes").join(name);
    let options = LoadOptions { normalize_unit_sphere: true, ..Default::default() };
    Some(load_mesh(&path, &options).unwrap_or_else(|e| panic!("{e}")).mesh)
}

/// A fresh, empty temporary directory unique to this process and `name`.
pub fn temp_dir(name: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("raycast-precompute-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create temp dir");
    dir
}

/// A small deterministic generator (SplitMix64), enough for test directions.
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform on the unit sphere.
    pub fn direction(&mut self) -> Vec3 {
        let z = 2.0 * self.uniform() - 1.0;
        let phi = std::f32::consts::TAU * self.uniform();
        let s = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(s * phi.cos(), s * phi.sin(), z)
    }
}

/// A UV sphere: `rings` latitude bands, `segments` longitude segments, outward CCW faces.
pub fn uv_sphere(
    center: Vec3,
    radius: f32,
    rings: u32,
    segments: u32,
) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut p = vec![center + radius * Vec3::Z];
    for i in 1..rings {
        let theta = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..segments {
            let phi = std::f32::consts::TAU * j as f32 / segments as f32;
            let d = Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
            p.push(center + radius * d);
        }
    }
    p.push(center - radius * Vec3::Z);
    let south = p.len() as u32 - 1;
    let ring = |i: u32, j: u32| 1 + (i - 1) * segments + j % segments;
    let mut t = Vec::new();
    for j in 0..segments {
        t.push([0, ring(1, j), ring(1, j + 1)]);
        t.push([south, ring(rings - 1, j + 1), ring(rings - 1, j)]);
    }
    for i in 1..rings - 1 {
        for j in 0..segments {
            let (a, b, c, d) = (ring(i, j), ring(i, j + 1), ring(i + 1, j), ring(i + 1, j + 1));
            t.push([a, c, d]);
            t.push([a, d, b]);
        }
    }
    (p, t)
}
