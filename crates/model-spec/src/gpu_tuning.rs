//! How the linear layers run on a GPU (a CubeCL device, `--backend wgpu|cuda`): which kernels,
//! and the tuning of this workspace's own. Plain values, so that a run's record
//! (run-format's `ComputeSettings`) can say them without a tensor library; `brdf-neural`
//! hands them to every product as part of a batch's products (`brdf_neural::products`), never
//! through a process-wide or per-thread switch.
//!
//! | setting | values | default | environment variable (read by the CLI only) |
//! | --- | --- | --- | --- |
//! | [`GpuTuning::linear`] | `ours` (the `gpu-kernels` crate: the bias fused, the weight gradient split over the batch inside its kernel, its parts added in a fixed order) or `burn` (CubeCL's autotuned product; the trainer splits the batch so that autodiff splits the weight gradients) | `ours` | `NEURAL_BRDF_GPU_LINEAR` |
//! | [`GpuTuning::split_len`] | batch rows each split of `ours`' weight gradient sums: a power of two from 64 to 65,536 | the kernels' rule (enough splits for 256 cubes) | `NEURAL_BRDF_GPU_SPLIT_LEN` |
//! | [`GpuTuning::tile`] | `ours`' f32 tile: `64`, `128`, `64v` or `128v` (read from shared memory four floats at a time) | `64` | `NEURAL_BRDF_GPU_TILE` |
//! | [`GpuTuning::checked`] | launch with CubeCL's index checks and wgpu's loop counters (a debugging aid; the same values) | off | `NEURAL_BRDF_GPU_CHECKED` |
//!
//! `ours` is the default because, measured on an H200, it is as fast as burn's kernels once
//! burn's autotune has settled, several times faster in a first process, and its sums run in a
//! fixed order (figures: `benches/README.md`, "Figures that left the source comments").

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// The kernels of the linear layers on a GPU.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum GpuLinear {
    /// burn's own `linear` (CubeCL's matrix product).
    Burn,
    /// The `gpu-kernels` crate.
    #[default]
    Ours,
}

/// The f32 products' tile of [`GpuLinear::Ours`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum GpuTile {
    /// `64`: 64 x 64, 4 x 4 sums a unit (the default).
    #[default]
    #[serde(rename = "64")]
    T64,
    /// `128`: 128 x 128, 8 x 8 sums a unit.
    #[serde(rename = "128")]
    T128,
    /// `64v`: 64 x 64, the slabs read from shared memory four floats at a time.
    #[serde(rename = "64v")]
    T64V,
    /// `128v`: 128 x 128, 8 x 8 sums a unit, read from shared memory four floats at a time.
    #[serde(rename = "128v")]
    T128V,
}

/// How the linear layers run on a GPU (see the module documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GpuTuning {
    /// Which kernels.
    pub linear: GpuLinear,
    /// A fixed batch length for every split of a weight gradient (`None`: the kernels' rule).
    pub split_len: Option<u32>,
    /// The f32 products' tile.
    pub tile: GpuTile,
    /// Launch with index checks (a debugging aid; the same values).
    pub checked: bool,
}

impl GpuTuning {
    /// The environment variables that override a setting (read by the CLI only).
    pub const VARIABLES: &[(&str, &str)] = &[
        ("NEURAL_BRDF_GPU_LINEAR", "linear: `ours` (default) or `burn`"),
        ("NEURAL_BRDF_GPU_SPLIT_LEN", "split_len: a power of two from 64 to 65536"),
        ("NEURAL_BRDF_GPU_TILE", "tile: 64 (default), 128, 64v or 128v"),
        ("NEURAL_BRDF_GPU_CHECKED", "checked: 1 launches with index checks, 0 (default) without"),
    ];

    /// This tuning with the one `variable` (one of [`GpuTuning::VARIABLES`]) set from `value`.
    ///
    /// # Errors
    /// [`Error::InvalidConfig`] naming the variable and what it takes.
    pub fn with_override(mut self, variable: &str, value: &str) -> Result<GpuTuning> {
        let bad = |expected: &str| {
            Error::InvalidConfig(format!("{variable}={value:?}: expected {expected}"))
        };
        let v = value.trim();
        match variable {
            "NEURAL_BRDF_GPU_LINEAR" => {
                self.linear = match v.to_ascii_lowercase().as_str() {
                    "ours" | "" => GpuLinear::Ours,
                    "burn" => GpuLinear::Burn,
                    _ => {
                        return Err(bad(
                            "`ours` (the gpu-kernels crate, the default) or `burn` (burn's kernels)",
                        ));
                    }
                }
            }
            "NEURAL_BRDF_GPU_SPLIT_LEN" => match v.parse::<u32>() {
                Ok(len) if len.is_power_of_two() && (64..=65_536).contains(&len) => {
                    self.split_len = Some(len)
                }
                _ => {
                    return Err(bad(
                        "a power of two from 64 to 65536 (batch rows per split of a weight \
                         gradient; by default the split count fills the GPU)",
                    ));
                }
            },
            "NEURAL_BRDF_GPU_TILE" => {
                self.tile = match v.to_ascii_lowercase().as_str() {
                    "64" => GpuTile::T64,
                    "128" => GpuTile::T128,
                    "64v" => GpuTile::T64V,
                    "128v" => GpuTile::T128V,
                    _ => {
                        return Err(bad(
                            "64, 128, 64v or 128v (the products' tiles; the v ones are read from \
                             shared memory four floats at a time)",
                        ));
                    }
                }
            }
            "NEURAL_BRDF_GPU_CHECKED" => {
                self.checked = match v {
                    "1" => true,
                    "0" => false,
                    _ => {
                        return Err(bad(
                            "1 (launch the GPU kernels with index checks, a debugging aid) or 0 \
                             (without, the default)",
                        ));
                    }
                }
            }
            _ => return Err(Error::InvalidConfig(format!("{variable}: not a GPU setting"))),
        }
        Ok(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn set(var: &str, value: &str) -> Result<GpuTuning> {
        GpuTuning::default().with_override(var, value)
    }

    #[test]
    fn values_parse_and_bad_ones_name_the_variable() {
        assert_eq!(GpuTuning::default().linear, GpuLinear::Ours);
        assert_eq!(set("NEURAL_BRDF_GPU_LINEAR", " Burn ").unwrap().linear, GpuLinear::Burn);
        assert_eq!(set("NEURAL_BRDF_GPU_LINEAR", "").unwrap().linear, GpuLinear::Ours);
        assert_eq!(set("NEURAL_BRDF_GPU_SPLIT_LEN", " 65536 ").unwrap().split_len, Some(65_536));
        assert_eq!(set("NEURAL_BRDF_GPU_TILE", "128v").unwrap().tile, GpuTile::T128V);
        assert!(set("NEURAL_BRDF_GPU_CHECKED", "1").unwrap().checked);
        for (var, bad) in [
            ("NEURAL_BRDF_GPU_LINEAR", "cublas"),
            ("NEURAL_BRDF_GPU_SPLIT_LEN", "100"),
            ("NEURAL_BRDF_GPU_SPLIT_LEN", "32"),
            ("NEURAL_BRDF_GPU_SPLIT_LEN", "131072"),
            ("NEURAL_BRDF_GPU_SPLIT_LEN", "lots"),
            ("NEURAL_BRDF_GPU_TILE", "256"),
            ("NEURAL_BRDF_GPU_TILE", ""),
            ("NEURAL_BRDF_GPU_CHECKED", "yes"),
            ("NEURAL_BRDF_GPU_NOTHING", "1"),
        ] {
            let e = set(var, bad).unwrap_err().to_string();
            assert!(e.contains(var), "{e}");
        }
    }

    #[test]
    fn a_record_reads_back() {
        let t = GpuTuning { split_len: Some(512), tile: GpuTile::T64V, ..Default::default() };
        let text = serde_json::to_string(&t).unwrap();
        assert!(text.contains("\"64v\"") && text.contains("\"ours\""), "{text}");
        assert_eq!(serde_json::from_str::<GpuTuning>(&text).unwrap(), t);
    }
}
