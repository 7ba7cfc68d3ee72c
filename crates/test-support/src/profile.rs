//! The tiny sweep profiles of the tests that run whole sweeps (through the xtask binary or the
//! sweep library): one scene of Spot (the embedded mesh unless a test names another) at 24 px
//! with 2 views of 4 lights, a 16-wide network and a small LBO basis. Each test adds its own
//! `[run.train]`, `[run.eval]` and `[sweep]` tables, the parts that say what it checks, and may
//! enlarge the scene ([`TinyProfile::scene`]).

/// A tiny profile's head: its name, seed, mesh and scene size. [`TinyProfile::with`] writes it
/// as TOML followed by the test's own tables.
#[derive(Clone, Debug)]
pub struct TinyProfile<'a> {
    name: &'a str,
    description: &'a str,
    seed: u64,
    mesh: &'a str,
    size: u32,
    views: u32,
    lights: u32,
}

impl<'a> TinyProfile<'a> {
    /// The embedded Spot mesh at 24 px, 2 views of 4 lights.
    pub fn new(name: &'a str, description: &'a str, seed: u64) -> Self {
        Self { name, description, seed, mesh: "embedded:spot", size: 24, views: 2, lights: 4 }
    }

    /// Another mesh source (for example `data:meshes/spot.obj`, which needs the shared data).
    pub fn mesh(mut self, mesh: &'a str) -> Self {
        self.mesh = mesh;
        self
    }

    /// Another image size, view count and light count.
    pub fn scene(mut self, size: u32, views: u32, lights: u32) -> Self {
        (self.size, self.views, self.lights) = (size, views, lights);
        self
    }

    /// The profile as TOML, followed by `tables` (the test's own tables).
    pub fn with(&self, tables: &str) -> String {
        let Self { name, description, seed, mesh, size, views, lights } = self;
        format!(
            r#"name = "{name}"
description = "{description}"
[data]
meshes = ["{mesh}"]
materials = ["blue-acrylic"]
size = {size}
views = {views}
lights = {lights}
[run]
seed = {seed}
[run.model]
width = 16
[run.features.lbo]
k_max = 32
first = 16
blocks = 1
block_len = 8
{tables}"#
        )
    }
}

/// The profile named `name` with `seed` on the default tiny scene, followed by `tables`.
pub fn tiny_profile(name: &str, description: &str, seed: u64, tables: &str) -> String {
    TinyProfile::new(name, description, seed).with(tables)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_builder_changes_only_what_it_is_told() {
        let base = tiny_profile("t", "d", 7, "[sweep]\n");
        let big = TinyProfile::new("t", "d", 7).scene(64, 4, 12).with("[sweep]\n");
        assert!(base.contains("size = 24\nviews = 2\nlights = 4\n"), "{base}");
        assert!(big.contains("size = 64\nviews = 4\nlights = 12\n"), "{big}");
        assert_eq!(
            base.replace("size = 24\nviews = 2\nlights = 4", ""),
            big.replace("size = 64\nviews = 4\nlights = 12", "")
        );
        let data = TinyProfile::new("t", "d", 7).mesh("data:meshes/spot.obj").with("");
        assert!(data.contains("meshes = [\"data:meshes/spot.obj\"]") && data.contains("seed = 7"));
        assert!(base.ends_with("block_len = 8\n[sweep]\n"));
    }
}
