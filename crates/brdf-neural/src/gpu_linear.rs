//! Which kernels compute the linear layers on a GPU (a CubeCL device, `--backend wgpu|cuda`):
//!
//! | value of `NEURAL_BRDF_GPU_LINEAR` | kernels |
//! | --- | --- |
//! | `ours` (the default) | this workspace's `gpu-kernels`: a tiled product with the bias fused, the weight gradient split over the batch inside its kernel and its parts added in a fixed order, through the same backend extension as the CPU kernels ([`crate::linear_op`]) |
//! | `burn` | burn's: CubeCL's autotuned matrix product; the trainer splits the batch ([`crate::batch_split`]) so that autodiff splits the weight gradients |
//!
//! The choice is per process (the environment is read once). An unknown value is refused when a
//! GPU device is made ([`crate::device::BackendDevice::device`]), naming the variable. `ours` is the
//! default because, measured on an H200, it is as fast as burn's kernels once burn's autotune has
//! settled, several times faster in a first process, before the autotune cache holds burn's
//! shapes, and its sums run in a fixed order (figures: `benches/README.md`, "Figures that left
//! the source comments").
//!
//! Three settings of `ours`, for benchmarks and debugging, read (and a bad value refused) when
//! a GPU device is made like the choice of kernels:
//!
//! | variable | values | default |
//! | --- | --- | --- |
//! | `NEURAL_BRDF_GPU_SPLIT_LEN` | batch rows each split of a weight gradient sums: a power of two from 64 to 65,536 | `gpu_kernels::linear::splits`' rule (enough splits for 256 cubes) |
//! | `NEURAL_BRDF_GPU_TILE` | the products' tile: `64`, `128`, `64v` or `128v` (read from shared memory four floats at a time) | `64` |
//! | `NEURAL_BRDF_GPU_CHECKED` | `1`: launch with CubeCL's index checks and wgpu's loop counters (`gpu_kernels::checks`), `0`: without | `0` |

use std::sync::OnceLock;

/// The environment variable that picks the GPU kernels of the linear layers.
pub const VAR: &str = "NEURAL_BRDF_GPU_LINEAR";

/// The kernels of the linear layers on a GPU.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GpuLinear {
    /// burn's own `linear` (CubeCL's matrix product).
    Burn,
    /// The `gpu-kernels` crate.
    #[default]
    Ours,
}

impl GpuLinear {
    /// Parses `burn` or `ours`.
    pub fn parse(value: &str) -> crate::Result<Self> {
        match value.trim().to_ascii_lowercase().as_str() {
            "burn" => Ok(GpuLinear::Burn),
            "ours" | "" => Ok(GpuLinear::Ours),
            other => Err(crate::Error::Setting(format!(
                "{VAR}={other:?}: expected `ours` (the gpu-kernels crate, the default) or \
                 `burn` (burn's kernels)"
            ))),
        }
    }

    /// The value of [`VAR`] (`ours` where it is not set).
    pub fn from_env() -> crate::Result<Self> {
        match std::env::var(VAR) {
            Ok(v) => Self::parse(&v),
            Err(_) => Ok(GpuLinear::Ours),
        }
    }

    /// The process's choice: [`GpuLinear::from_env`] on first use (an unknown value, which
    /// making a GPU device refuses, counts as the default here).
    pub fn current() -> Self {
        static CHOICE: OnceLock<GpuLinear> = OnceLock::new();
        *CHOICE.get_or_init(|| Self::from_env().unwrap_or_default())
    }
}

/// The environment variable that sets the split length of `ours`' weight gradients.
pub const SPLIT_VAR: &str = "NEURAL_BRDF_GPU_SPLIT_LEN";

/// Parses a split length (see the module documentation).
pub fn parse_split_len(value: &str) -> crate::Result<u32> {
    let len = value.trim().parse::<u32>().ok();
    match len {
        Some(len) if len.is_power_of_two() && (64..=65_536).contains(&len) => Ok(len),
        _ => Err(crate::Error::Setting(format!(
            "{SPLIT_VAR}={value:?}: expected a power of two from 64 to 65536 (batch rows per \
             split of a weight gradient; by default the split count fills the GPU)"
        ))),
    }
}

/// The environment variable that sets the tile of `ours`' products.
pub const TILE_VAR: &str = "NEURAL_BRDF_GPU_TILE";

/// The products' tiles of `ours` ([`TILE_VAR`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GpuTile {
    /// `64`: 64 x 64, 4 x 4 sums a unit (the default).
    T64,
    /// `128`: 128 x 128, 8 x 8 sums a unit.
    T128,
    /// `64v`: 64 x 64, the slabs read from shared memory four floats at a time.
    T64V,
    /// `128v`: 128 x 128, 8 x 8 sums a unit, read from shared memory four floats at a time.
    T128V,
}

/// Parses a tile: `64`, `128`, `64v` or `128v`.
pub fn parse_tile(value: &str) -> crate::Result<GpuTile> {
    match value.trim() {
        "64" => Ok(GpuTile::T64),
        "128" => Ok(GpuTile::T128),
        "64v" | "64V" => Ok(GpuTile::T64V),
        "128v" | "128V" => Ok(GpuTile::T128V),
        _ => Err(crate::Error::Setting(format!(
            "{TILE_VAR}={value:?}: expected 64, 128, 64v or 128v (the products' tiles; the \
             v ones are read from shared memory four floats at a time)"
        ))),
    }
}

/// The environment variable that launches `ours`' kernels with CubeCL's index checks.
pub const CHECKED_VAR: &str = "NEURAL_BRDF_GPU_CHECKED";

/// Parses `0` or `1` (whether the kernels launch checked).
pub fn parse_checked(value: &str) -> crate::Result<bool> {
    match value.trim() {
        "0" => Ok(false),
        "1" => Ok(true),
        _ => Err(crate::Error::Setting(format!(
            "{CHECKED_VAR}={value:?}: expected 1 (launch the GPU kernels with index checks, a \
             debugging aid) or 0 (without, the default)"
        ))),
    }
}

/// Reads [`VAR`], [`SPLIT_VAR`], [`TILE_VAR`] and [`CHECKED_VAR`] when a GPU device is made: an unknown value
/// is an error naming its variable; the tuning settings are handed to the kernels.
#[cfg(any(feature = "wgpu", feature = "cuda"))]
pub(crate) fn configure() -> crate::Result<()> {
    GpuLinear::from_env()?;
    if let Ok(value) = std::env::var(SPLIT_VAR) {
        let len = parse_split_len(&value)?;
        gpu_kernels::linear::set_split_len(Some(len))
            .map_err(|e| crate::Error::Setting(format!("{SPLIT_VAR}: {e}")))?;
    }
    if let Ok(value) = std::env::var(TILE_VAR) {
        let tiling = match parse_tile(&value)? {
            GpuTile::T64 => gpu_kernels::gemm::Tiling::T64,
            GpuTile::T128 => gpu_kernels::gemm::Tiling::T128,
            GpuTile::T64V => gpu_kernels::gemm::Tiling::T64V,
            GpuTile::T128V => gpu_kernels::gemm::Tiling::T128V,
        };
        gpu_kernels::linear::set_tiling(tiling);
    }
    if let Ok(value) = std::env::var(CHECKED_VAR) {
        gpu_kernels::checks::set_checked(parse_checked(&value)?);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_parse_and_unknown_ones_name_the_variable() {
        assert_eq!(GpuLinear::parse("burn").unwrap(), GpuLinear::Burn);
        assert_eq!(GpuLinear::parse(" Ours ").unwrap(), GpuLinear::Ours);
        assert_eq!(GpuLinear::parse("").unwrap(), GpuLinear::Ours);
        assert_eq!(GpuLinear::default(), GpuLinear::Ours);
        let e = GpuLinear::parse("cublas").unwrap_err().to_string();
        assert!(e.contains(VAR) && e.contains("cublas") && e.contains("ours"), "{e}");
    }

    #[test]
    fn split_lengths_parse_and_bad_ones_name_the_variable() {
        assert_eq!(parse_split_len("512").unwrap(), 512);
        assert_eq!(parse_split_len(" 65536 ").unwrap(), 65_536);
        for bad in ["0", "100", "32", "131072", "-512", "lots"] {
            let e = parse_split_len(bad).unwrap_err().to_string();
            assert!(e.contains(SPLIT_VAR) && e.contains(bad), "{e}");
        }
    }

    #[test]
    fn tiles_parse_and_bad_ones_name_the_variable() {
        assert_eq!(parse_tile("64").unwrap(), GpuTile::T64);
        assert_eq!(parse_tile(" 128").unwrap(), GpuTile::T128);
        assert_eq!(parse_tile("64v").unwrap(), GpuTile::T64V);
        assert_eq!(parse_tile("128v").unwrap(), GpuTile::T128V);
        for bad in ["32", "256", "wide", "", "256v"] {
            let e = parse_tile(bad).unwrap_err().to_string();
            assert!(e.contains(TILE_VAR) && e.contains("128") && e.contains("64v"), "{e}");
        }
    }

    #[test]
    fn checked_parses_and_bad_values_name_the_variable() {
        assert!(parse_checked("1").unwrap());
        assert!(!parse_checked(" 0 ").unwrap());
        for bad in ["yes", "2", ""] {
            let e = parse_checked(bad).unwrap_err().to_string();
            assert!(e.contains(CHECKED_VAR) && e.contains("expected 1"), "{e}");
        }
    }
}
