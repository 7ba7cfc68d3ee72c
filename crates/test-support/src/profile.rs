//! The tiny sweep profile of the tests that run whole sweeps through the xtask binary: one
//! scene of the embedded Spot mesh (no shared data needed) at 24 px with 2 views of 4 lights,
//! a 16-wide network and a small LBO basis. Each test adds its own `[run.train]`, `[run.eval]`
//! and `[sweep]` tables, the parts that say what it checks.

/// The profile named `name` with `seed`, followed by `tables` (TOML: the test's own tables).
pub fn tiny_profile(name: &str, description: &str, seed: u64, tables: &str) -> String {
    format!(
        r#"name = "{name}"
description = "{description}"
[data]
meshes = ["embedded:spot"]
materials = ["blue-acrylic"]
size = 24
views = 2
lights = 4
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
