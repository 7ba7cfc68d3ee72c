//! Shared helpers of the integration tests: the shared data folder, temporary directories, a
//! deterministic random generator and scene builders.

#![allow(dead_code)]

use std::path::PathBuf;

use mesh_encoding::glam::Vec3;
use mesh_encoding::{LoadOptions, TriMesh, load_mesh};

use test_support as support;
#[allow(unused_imports)]
pub use test_support::TempDir;

/// The shared data folder (`$NEURAL_BRDF_DATA`, default `<workspace>/../shared/data`) when
/// it holds `meshes/`; see `test_support::shared_data_root`.
pub fn data_dir() -> Option<PathBuf> {
    support::shared_data_root("meshes")
}

/// A shared mesh, cleaned and normalised into the unit sphere.
pub fn shared_mesh(name: &str) -> Option<TriMesh> {
    let path = data_dir()?.join("meshes").join(name);
    let options = LoadOptions { normalize_unit_sphere: true, ..Default::default() };
    Some(load_mesh(&path, &options).unwrap_or_else(|e| panic!("{e}")).mesh)
}

/// The workspace's seeded generator with test directions on top.
pub struct Rng(pub stdx::rng::SplitMix64);

impl Rng {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        Self(stdx::rng::SplitMix64::new(seed))
    }

    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f32 {
        self.0.next_f32()
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
