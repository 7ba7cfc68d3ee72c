//! What a run asks of a cluster node: CPUs, memory, wall time and a GPU, from the measured cost
//! of its model's training step (benches/README.md, "What the `full` profile costs").
//!
//! The time is the run's step budget (`train.iterations`, the plateau rule usually stops well
//! before it) at the measured step time, scaled to the run's batch, plus its evaluation, with a
//! margin of one half, capped at the cluster's limit the user gives (`--slurm-max-time`). A run
//! that outlasts its request is not lost: at two minutes before the limit Slurm sends SIGTERM
//! (`--signal=B:TERM@120`), the run writes a checkpoint and the task requeues itself, to resume
//! where it stopped.

use brdf_neural::ModelKind;
use brdf_neural::device::Backend;
use run_format::config::RunConfig;
use serde::{Deserialize, Serialize};

/// The resources of one array task.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Requests {
    /// `--cpus-per-task`.
    pub cpus: usize,
    /// `--mem`, in MiB.
    pub mem_mib: u64,
    /// `--time`, in minutes.
    pub minutes: u64,
    /// `--gres=gpu:1`.
    pub gpu: bool,
}

impl Requests {
    /// The `#SBATCH` lines.
    pub fn sbatch_lines(&self) -> Vec<String> {
        let mut lines = vec![
            format!("--cpus-per-task={}", self.cpus),
            format!("--mem={}M", self.mem_mib),
            format!("--time={}", slurm_time(self.minutes)),
        ];
        if self.gpu {
            lines.push("--gres=gpu:1".into());
        }
        lines
    }
}

/// Minutes as Slurm's `D-HH:MM:00`.
pub fn slurm_time(minutes: u64) -> String {
    let (d, h, m) = (minutes / 1440, minutes / 60 % 24, minutes % 60);
    format!("{d}-{h:02}:{m:02}:00")
}

/// Parses Slurm's time forms (`M`, `M:S`, `H:M:S`, `D-H`, `D-H:M`, `D-H:M:S`) into minutes,
/// rounding seconds up.
pub fn parse_slurm_time(text: &str) -> Option<u64> {
    let (days, rest) = match text.split_once('-') {
        Some((d, r)) => (d.parse::<u64>().ok()?, r),
        None => (0, text),
    };
    let parts: Vec<u64> = rest.split(':').map(|p| p.parse().ok()).collect::<Option<_>>()?;
    let seconds = match (text.contains('-'), parts.as_slice()) {
        (false, [m]) => m * 60,
        (false, [m, s]) => m * 60 + s,
        (_, [h, m, s]) => h * 3600 + m * 60 + s,
        (true, [h]) => h * 3600,
        (true, [h, m]) => h * 3600 + m * 60,
        _ => return None,
    };
    Some(days * 1440 + seconds.div_ceil(60))
}

/// Measured milliseconds of one training step at a batch of 2^15: on the 2-core CPU the
/// sweeps were timed on, and on one NVIDIA H200 in the real training loop.
fn step_ms(kind: ModelKind, gpu: bool) -> f64 {
    use ModelKind::*;
    let (cpu, h200) = match kind {
        SingleMlp => (167.8, 9.7),
        AdditiveSeparate => (288.7, 11.5),
        AdditiveShared => (315.1, 11.1),
        AdditiveSeparateEnhanced => (276.8, 11.5),
        AdditiveSharedEnhanced => (303.6, 11.4),
        Rp => (204.4, 8.4),
        Ts => (172.6, 8.9),
        Disney => (189.7, 12.8),
        Fmbrdf => (432.3, 18.8),
    };
    if gpu { h200 } else { cpu }
}

/// The steps a run of `kind` typically trains before its plateau rule stops it: the means of
/// the default profile's Table 1 runs (docs/reproduce.md, "What the default run shows").
fn typical_steps(kind: ModelKind) -> u64 {
    use ModelKind::*;
    match kind {
        Rp => 900,
        Ts => 800,
        Disney => 1_000,
        SingleMlp => 1_700,
        AdditiveSeparateEnhanced => 1_700,
        AdditiveSharedEnhanced => 2_100,
        AdditiveSeparate | AdditiveShared => 2_200,
        Fmbrdf => 2_700,
    }
}

/// A rough guess at a run's training seconds on `backend`, before it ran: its typical steps to
/// the plateau (at most its budget) at the measured step time. Only the order matters: the
/// sweep starts the longest runs first, so that the last to finish are short ones and no core
/// waits long for them.
pub fn expected_seconds(config: &RunConfig, backend: Backend) -> f64 {
    let t = &config.train;
    let scale = (t.batch_size as f64 / 32768.0).max(1.0 / 16.0);
    let steps = typical_steps(config.model.kind).min(t.iterations) as f64;
    steps * step_ms(config.model.kind, backend.is_gpu()) * scale / 1000.0
}

/// Settings of the requests that are not measured: the user's (`--slurm-cpus`, `--slurm-mem`,
/// `--slurm-max-time`) or the defaults.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RequestSettings {
    /// CPUs a task (default: 2 on the CPU backend, the machine the costs were measured on; 4
    /// beside a GPU).
    pub cpus: Option<usize>,
    /// Memory a task, MiB (default: 1 GiB plus six times the scene's data, from the peaks
    /// measured on the default profile's scenes).
    pub mem_mib: Option<u64>,
    /// The cluster's (or partition's) longest time, minutes (default: 24 h).
    pub max_minutes: Option<u64>,
}

/// The requests of a run of `config` on a scene of `scene_bytes` bytes of data, on `backend`.
pub fn requests(
    config: &RunConfig,
    scene_bytes: u64,
    backend: Backend,
    s: &RequestSettings,
) -> Requests {
    let gpu = backend.is_gpu();
    let cpus = s.cpus.unwrap_or(if gpu { 4 } else { 2 });
    let t = &config.train;
    // Small batches do not shrink a step below its fixed costs (a sixteenth of the measured
    // step, roughly its launch and bookkeeping).
    let scale = (t.batch_size as f64 / 32768.0).max(1.0 / 16.0);
    let train_s = t.iterations as f64 * step_ms(config.model.kind, gpu) * scale / 1000.0;
    // Opening the scene and evaluating it: measured at up to a few minutes for the paper's
    // 512 px test views on the CPU; proportional to the data, with a floor.
    let eval_s = 300.0 + scene_bytes as f64 / 1e6;
    let minutes = ((1.5 * (train_s + eval_s)) / 60.0).ceil() as u64;
    let minutes = minutes.clamp(10, s.max_minutes.unwrap_or(24 * 60).max(10));
    // A run peaks at under twice the scene's bytes above the process's own footprint
    // (`benches/README.md`, "Figures that left the source comments"). Asked: 1 GiB plus six
    // times the scene's bytes.
    let mem_mib = s.mem_mib.unwrap_or(1024 + (6 * scene_bytes).div_ceil(1 << 20));
    Requests { cpus, mem_mib, minutes, gpu }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slurm_times_round_trip() {
        assert_eq!(slurm_time(90), "0-01:30:00");
        assert_eq!(slurm_time(1440 * 2 + 61), "2-01:01:00");
        for (text, minutes) in [
            ("30", 30),
            ("30:01", 31),
            ("1:00:00", 60),
            ("2-0", 2880),
            ("1-02:03", 1440 + 123),
            ("1-02:03:04", 1440 + 124),
        ] {
            assert_eq!(parse_slurm_time(text), Some(minutes), "{text}");
        }
        for bad in ["", "x", "1:2:3:4", "-1", "1-"] {
            assert_eq!(parse_slurm_time(bad), None, "{bad}");
        }
        assert_eq!(parse_slurm_time(&slurm_time(12345)), Some(12345));
    }

    #[test]
    fn requests_follow_the_model_the_budget_and_the_backend() {
        let mut c = RunConfig::from_toml("", std::path::Path::new("test.toml")).unwrap();
        c.train.iterations = 100_000;
        c.train.batch_size = 32768;
        let s = RequestSettings { max_minutes: Some(100_000), ..Default::default() };
        c.model.kind = ModelKind::SingleMlp;
        let single = requests(&c, 0, Backend::Flex, &s);
        c.model.kind = ModelKind::Fmbrdf;
        let fmbrdf = requests(&c, 0, Backend::Flex, &s);
        // 10^5 steps of 167.8 ms, plus 5 min, times 1.5.
        assert_eq!(single.minutes, ((1.5 * (16780.0 + 300.0)) / 60.0f64).ceil() as u64);
        assert!(fmbrdf.minutes > 2 * single.minutes);
        assert!((single.cpus, single.gpu) == (2, false));
        c.model.kind = ModelKind::SingleMlp;
        let gpu = requests(&c, 0, Backend::Wgpu, &s);
        assert!(gpu.gpu && gpu.cpus == 4 && gpu.minutes < single.minutes / 10);
        assert!(gpu.sbatch_lines().contains(&"--gres=gpu:1".to_string()));
        // The user's limit caps the time; memory grows with the scene.
        let capped = RequestSettings { max_minutes: Some(240), ..Default::default() };
        assert_eq!(requests(&c, 0, Backend::Flex, &capped).minutes, 240);
        assert_eq!(requests(&c, 1 << 30, Backend::Flex, &s).mem_mib, 1024 + 6 * 1024);
        c.train.iterations = 30;
        assert_eq!(requests(&c, 0, Backend::Flex, &s).minutes, 10, "the floor");
    }
}
