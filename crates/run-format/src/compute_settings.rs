//! The settings that change how a run computes without being part of its configuration (and
//! so of its content address): which bf16 kernel the CPU takes, which kernels and tuning the
//! GPU's linear layers take, how often training reads its loss back, how much memory the LBO
//! solve may take, the allocator's policy. One typed value
//! with documented defaults, in the manner of image-rs's `Limits`:
//!
//! * the CLI builds it, and is the one place that reads environment variables, as overrides
//!   ([`ComputeSettings::variables`], [`ComputeSettings::with_override`]);
//! * the trainer, the kernels (through `brdf_neural::products::Products`) and the LBO solver
//!   take it as a value;
//! * each run's `metrics.json` records the one it trained with ([`crate::RunMetrics::compute`]).

use crate::error::{Error, Result};
use model_spec::GpuTuning;
use serde::{Deserialize, Serialize};

/// How a run computes, beyond its `config.toml`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ComputeSettings {
    /// bf16 products on Intel's AMX tiles where the CPU and the OS allow them (default true);
    /// `false` keeps them on the AVX512-BF16 kernel. Changes the speed, and the values in their
    /// last bits (the two kernels sum in different orders). No effect on f32 runs.
    pub bf16_amx: bool,
    /// Steps between host reads of the training loss (default `None`: every step on the CPU, a
    /// fixed number on a GPU). Changes the speed only: the losses and weights do not depend on
    /// it.
    pub loss_reads: Option<u64>,
    /// The memory the LBO eigensolver's Cholesky factor may take, in GiB (default `None`: three
    /// quarters of the memory available when the solve starts). A solve that would need more
    /// is refused with a decimation hint, before it allocates; the values never change.
    pub lbo_memory_gib: Option<f64>,
    /// Keep freed tensor buffers in the C allocator instead of returning them to the system
    /// (glibc; default true). Changes the speed only.
    pub keep_freed_memory: bool,
    /// How the linear layers run on a GPU ([`GpuTuning`]: which kernels, their tile and split;
    /// default: this workspace's kernels with their own rules). Changes the speed, and the
    /// values in their last bits (the order of the sums).
    pub gpu: GpuTuning,
}

impl Default for ComputeSettings {
    fn default() -> Self {
        ComputeSettings {
            bf16_amx: true,
            loss_reads: None,
            lbo_memory_gib: None,
            keep_freed_memory: true,
            gpu: GpuTuning::default(),
        }
    }
}

impl ComputeSettings {
    /// The environment variables that override a setting, and what each sets (read by the CLI
    /// only): [`ComputeSettings::VARIABLES`] and the GPU's, [`GpuTuning::VARIABLES`].
    pub fn variables() -> impl Iterator<Item = &'static (&'static str, &'static str)> {
        Self::VARIABLES.iter().chain(GpuTuning::VARIABLES)
    }

    /// The LBO factor's memory budget in bytes, where one is set.
    pub fn lbo_memory_bytes(&self) -> Option<u64> {
        self.lbo_memory_gib.map(|gib| (gib * (1u64 << 30) as f64) as u64)
    }

    /// The CPU's and the trainer's environment variables (see [`ComputeSettings::variables`]).
    pub const VARIABLES: &[(&str, &str)] = &[
        ("CPU_KERNELS_AMX", "bf16_amx: 0 keeps bf16 products off the AMX tiles, 1 (default) on"),
        ("NEURAL_BRDF_LOSS_READS", "loss_reads: steps between host reads of the training loss"),
        ("NEURAL_BRDF_LBO_MEMORY_GIB", "lbo_memory_gib: GiB the LBO's Cholesky factor may take"),
        (
            "BRDF_KEEP_MALLOC",
            "keep_freed_memory: 0 returns freed tensor memory, 1 (default) keeps it",
        ),
    ];

    /// These settings with the one `variable` (one of [`ComputeSettings::variables`]) set from
    /// `value`.
    ///
    /// # Errors
    /// [`Error::Config`] naming the variable, for a value it does not take or a variable that
    /// sets nothing here.
    pub fn with_override(mut self, variable: &str, value: &str) -> Result<ComputeSettings> {
        let bad = |expected: &str| Error::Config {
            key: variable.to_string(),
            message: format!("`{value}`: expected {expected}"),
        };
        let flag = |value: &str| match value.trim() {
            "1" => Ok(true),
            "0" => Ok(false),
            _ => Err(bad("0 or 1")),
        };
        match variable {
            "CPU_KERNELS_AMX" => self.bf16_amx = flag(value)?,
            "BRDF_KEEP_MALLOC" => self.keep_freed_memory = flag(value)?,
            "NEURAL_BRDF_LOSS_READS" => match value.trim().parse::<u64>() {
                Ok(n) if n > 0 => self.loss_reads = Some(n),
                _ => return Err(bad("a positive number of steps between reads of the loss")),
            },
            "NEURAL_BRDF_LBO_MEMORY_GIB" => match value.trim().parse::<f64>() {
                Ok(gib) if gib.is_finite() && gib > 0.0 => self.lbo_memory_gib = Some(gib),
                _ => return Err(bad("a positive number of GiB")),
            },
            _ if GpuTuning::VARIABLES.iter().any(|(v, _)| *v == variable) => {
                self.gpu = self.gpu.with_override(variable, value).map_err(|e| Error::Config {
                    key: variable.to_string(),
                    message: e.to_string(),
                })?;
            }
            _ => {
                return Err(Error::Config {
                    key: variable.to_string(),
                    message: "not a compute setting".into(),
                });
            }
        }
        Ok(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_and_every_variable_override_and_bad_values_name_the_variable() {
        let d = ComputeSettings::default();
        assert!(d.bf16_amx && d.keep_freed_memory && d.loss_reads.is_none());
        let s = d
            .clone()
            .with_override("CPU_KERNELS_AMX", "0")
            .and_then(|s| s.with_override("BRDF_KEEP_MALLOC", " 0 "))
            .and_then(|s| s.with_override("NEURAL_BRDF_LOSS_READS", "16"))
            .and_then(|s| s.with_override("NEURAL_BRDF_LBO_MEMORY_GIB", "1.5"))
            .unwrap();
        assert_eq!(
            s,
            ComputeSettings {
                bf16_amx: false,
                loss_reads: Some(16),
                lbo_memory_gib: Some(1.5),
                keep_freed_memory: false,
                gpu: GpuTuning::default()
            }
        );
        assert_eq!(s.lbo_memory_bytes(), Some(3 << 29));
        for (var, value) in [
            ("NEURAL_BRDF_LBO_MEMORY_GIB", "NaN"),
            ("NEURAL_BRDF_LBO_MEMORY_GIB", "-1"),
            ("CPU_KERNELS_AMX", "yes"),
            ("NEURAL_BRDF_LOSS_READS", "0"),
            ("NEURAL_BRDF_LOSS_READS", "-3"),
            ("BRDF_KEEP_MALLOC", ""),
            ("NEURAL_BRDF_GPU_TILE", "32"),
            ("NEURAL_BRDF_NOTHING", "1"),
        ] {
            let e = d.clone().with_override(var, value).unwrap_err().to_string();
            assert!(e.contains(var), "{e}");
        }
        for (var, _) in ComputeSettings::variables() {
            let value = match *var {
                v if v.ends_with("READS") || v.ends_with("GIB") => "2",
                v if v.ends_with("SPLIT_LEN") => "512",
                v if v.ends_with("TILE") => "128",
                v if v.ends_with("LINEAR") => "burn",
                v if v.ends_with("CHECKED") => "1",
                _ => "0",
            };
            let s = d.clone().with_override(var, value).unwrap();
            assert_ne!(s, d, "{var}={value} changed nothing");
        }
    }

    #[test]
    fn a_record_reads_back_and_unknown_keys_are_refused() {
        let s = ComputeSettings { loss_reads: Some(4), ..Default::default() };
        let back: ComputeSettings =
            serde_json::from_str(&serde_json::to_string(&s).unwrap()).unwrap();
        assert_eq!(back, s);
        let partial: ComputeSettings = serde_json::from_str(r#"{"bf16_amx": false}"#).unwrap();
        assert!(!partial.bf16_amx && partial.keep_freed_memory);
        assert!(serde_json::from_str::<ComputeSettings>(r#"{"bf16_amx2": false}"#).is_err());
    }
}
