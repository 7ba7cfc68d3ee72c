//! Where a process finds what it reads beside run and scene directories: the data root, the
//! LPIPS weight file and the GPU kernels' cache. These are places, not settings: no value a run
//! computes depends on them (a missing LPIPS file leaves LPIPS out and says so). The command
//! line fills them once from its options and the environment ([`crate::cli::process_places`]);
//! the stages below take the paths as values and read no variable.
//!
//! | variable | place | default |
//! | --- | --- | --- |
//! | `NEURAL_BRDF_DATA` | the data root (meshes, materials, captures, weights; `cargo xtask fetch-data`) | `./data` |
//! | `NEURAL_BRDF_LPIPS` | the LPIPS weight file | `<data root>/lpips/alex_v0.1.lpipsw` |
//! | `NEURAL_BRDF_GPU_CACHE` | the GPU backends' autotune and kernel cache ([`brdf_neural::gpu_cache`]) | `$XDG_CACHE_HOME/neural-brdfs/gpu`, else `$HOME/.cache/neural-brdfs/gpu`, else the temporary folder's `neural-brdfs-gpu` |

use std::ffi::OsString;
use std::path::{Path, PathBuf};

/// The places of one process (see the module documentation).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Places {
    /// The data root.
    pub data: PathBuf,
    /// The LPIPS weight file when named on its own (`NEURAL_BRDF_LPIPS`); `None`: the data
    /// root's ([`Places::lpips_weights`]).
    pub lpips: Option<PathBuf>,
    /// The GPU backends' cache folder.
    pub gpu_cache: PathBuf,
}

impl Default for Places {
    /// The defaults of the module documentation, with no variable set.
    fn default() -> Self {
        Places::from_vars(|_| None)
    }
}

impl Places {
    /// The variables that name places, each with what it names.
    pub const VARIABLES: [(&'static str, &'static str); 3] = [
        ("NEURAL_BRDF_DATA", "the data root"),
        ("NEURAL_BRDF_LPIPS", "the LPIPS weight file"),
        ("NEURAL_BRDF_GPU_CACHE", "the GPU backends' cache folder"),
    ];

    /// The places from the variables `var` looks up (an empty value counts as unset); the GPU
    /// cache's fallbacks also look up `XDG_CACHE_HOME` and `HOME`.
    pub fn from_vars(var: impl Fn(&str) -> Option<OsString>) -> Self {
        let var = |name: &str| var(name).filter(|v| !v.is_empty()).map(PathBuf::from);
        let gpu_cache = var("NEURAL_BRDF_GPU_CACHE").unwrap_or_else(|| {
            match var("XDG_CACHE_HOME").or_else(|| var("HOME").map(|h| h.join(".cache"))) {
                Some(base) => base.join("neural-brdfs").join("gpu"),
                None => std::env::temp_dir().join("neural-brdfs-gpu"),
            }
        });
        Places {
            data: var("NEURAL_BRDF_DATA").unwrap_or_else(|| PathBuf::from("data")),
            lpips: var("NEURAL_BRDF_LPIPS"),
            gpu_cache,
        }
    }

    /// These places with another data root (`--data`); an LPIPS file named on its own stays.
    pub fn with_data(self, data: Option<&Path>) -> Self {
        match data {
            Some(data) => Places { data: data.to_path_buf(), ..self },
            None => self,
        }
    }

    /// The LPIPS weight file: the one named on its own, else the data root's.
    pub fn lpips_weights(&self) -> PathBuf {
        self.lpips.clone().unwrap_or_else(|| metrics::lpips::weights::default_path(&self.data))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vars<'a>(set: &'a [(&'a str, &'a str)]) -> impl Fn(&str) -> Option<OsString> + 'a {
        move |name| set.iter().find(|(k, _)| *k == name).map(|(_, v)| OsString::from(v))
    }

    #[test]
    fn places_follow_their_variables_in_the_documented_order() {
        let all = Places::from_vars(vars(&[
            ("NEURAL_BRDF_DATA", "/d"),
            ("NEURAL_BRDF_LPIPS", "/w.lpipsw"),
            ("NEURAL_BRDF_GPU_CACHE", "/x/gpu"),
            ("XDG_CACHE_HOME", "/xdg"),
            ("HOME", "/home/u"),
        ]));
        assert_eq!(all.data, PathBuf::from("/d"));
        assert_eq!(all.lpips_weights(), PathBuf::from("/w.lpipsw"));
        assert_eq!(all.gpu_cache, PathBuf::from("/x/gpu"));
        let xdg = Places::from_vars(vars(&[
            ("NEURAL_BRDF_GPU_CACHE", ""),
            ("XDG_CACHE_HOME", "/xdg"),
            ("HOME", "/home/u"),
        ]));
        assert_eq!(xdg.gpu_cache, PathBuf::from("/xdg/neural-brdfs/gpu"));
        let home = Places::from_vars(vars(&[("HOME", "/home/u")]));
        assert_eq!(home.gpu_cache, PathBuf::from("/home/u/.cache/neural-brdfs/gpu"));
        let none = Places::default();
        assert_eq!(none.gpu_cache, std::env::temp_dir().join("neural-brdfs-gpu"));
        assert_eq!(none.data, PathBuf::from("data"));
        assert_eq!(none.lpips_weights(), PathBuf::from("data/lpips/alex_v0.1.lpipsw"));
    }

    #[test]
    fn a_data_option_moves_the_data_roots_weights_but_not_a_named_file() {
        let from_root = Places::default().with_data(Some(Path::new("/mine")));
        assert_eq!(from_root.lpips_weights(), PathBuf::from("/mine/lpips/alex_v0.1.lpipsw"));
        let named = Places::from_vars(vars(&[("NEURAL_BRDF_LPIPS", "/w.lpipsw")]))
            .with_data(Some(Path::new("/mine")));
        assert_eq!(named.lpips_weights(), PathBuf::from("/w.lpipsw"));
        assert_eq!(Places::default().with_data(None), Places::default());
    }
}
