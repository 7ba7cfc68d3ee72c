//! Where the GPU backends keep what they measure and compile, once per machine.
//!
//! With burn's autotune, the first use of each problem shape in a process benchmarks the
//! candidate kernels (a matrix product has dozens), and every kernel is compiled at its first
//! launch: on a GPU that start-up took longer than the training it preceded. CubeCL can keep both
//! in an on-disk store (its `persistence` feature: one database file, shared safely by several
//! processes), which the GPU features turn on. By default CubeCL puts that store under the
//! `target/` folder of the outermost Cargo project around the working directory, so a run
//! started elsewhere, or an installed binary, would tune again. Here every process of a user on
//! a machine, every run and every `--jobs` child, uses one folder: the one the command line
//! names with [`use_dir`] before the first GPU device is made (its default and variables are
//! the command line's, `experiments::places`), else the temporary folder's `neural-brdfs-gpu`.
//!
//! A `cubecl.toml` (or `burn.toml`) in the working directory or above it is CubeCL's own
//! configuration and is left alone: its `[environment]` section says where the store is then.
//! What is cached: autotune's choices (keyed by device, kernel and shape), and the compiled
//! kernels where the runtime can keep them (CUDA's; wgpu keeps its SPIR-V pipelines only with
//! the Vulkan compiler, so on wgpu the kernels are still compiled once per process).

use std::path::PathBuf;
use std::sync::OnceLock;

/// The folder [`use_dir`] named.
static DIR: OnceLock<PathBuf> = OnceLock::new();

/// Names the folder of the GPU backends' persistent caches for this process. Only the first
/// call counts, and only before the first GPU device is made (CubeCL reads its configuration
/// once); it changes where autotune's measurements are kept, never a computed value.
pub fn use_dir(dir: PathBuf) {
    let _ = DIR.set(dir);
}

/// The folder of the GPU backends' persistent caches (see the module documentation).
pub fn gpu_cache_dir() -> PathBuf {
    DIR.get().cloned().unwrap_or_else(|| std::env::temp_dir().join("neural-brdfs-gpu"))
}

/// Points CubeCL's persistent store at [`gpu_cache_dir`], before the first GPU device is
/// made; does nothing when a CubeCL configuration file is found, or once CubeCL's
/// configuration has been read.
#[cfg(any(feature = "wgpu", feature = "cuda"))]
pub(crate) fn configure() {
    use cubecl::config::cache::CacheConfig;
    use cubecl::config::{CubeClRuntimeConfig, RuntimeConfig};
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        if has_cubecl_file() {
            return;
        }
        let mut config = CubeClRuntimeConfig::default().override_from_env();
        config.environment.path = CacheConfig::Directory(gpu_cache_dir());
        CubeClRuntimeConfig::try_set(config);
    });
}

/// Whether a configuration file CubeCL reads exists in the working directory or above it.
#[cfg(any(feature = "wgpu", feature = "cuda"))]
fn has_cubecl_file() -> bool {
    let Ok(mut dir) = std::env::current_dir() else { return false };
    loop {
        let found = ["cubecl.toml", "CubeCL.toml", "burn.toml", "Burn.toml"]
            .iter()
            .any(|name| dir.join(name).is_file());
        if found {
            return true;
        }
        if !dir.pop() {
            return false;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first folder named is the one used. One test, because the folder is the process's.
    #[test]
    fn the_first_folder_named_is_used() {
        use_dir(PathBuf::from("/x/gpu"));
        use_dir(PathBuf::from("/y/gpu"));
        assert_eq!(gpu_cache_dir(), PathBuf::from("/x/gpu"));
    }
}
