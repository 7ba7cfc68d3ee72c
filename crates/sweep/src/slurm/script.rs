//! The job scripts a Slurm submission writes: one array script per group of runs with the same
//! requests, and the collect job's.
//!
//! An array task reads its run directory from line `SLURM_ARRAY_TASK_ID + 1` of its task list,
//! appends its output to that run's `sweep.log` (the log of every execution mode), and runs
//! `run-one` in the background so that the batch shell can trap the signals: on SIGTERM or
//! SIGUSR1 (Slurm's `--signal=B:TERM@120` before the time limit, a preemption, `scancel
//! --signal`) it passes the signal on, waits for the run's checkpoint, and requeues its own
//! task. A run stopped that way exits with [`experiments::interrupt::EXIT_REQUEUE`].

use super::requests::Requests;
use crate::shell::quote as shell_quote;
use std::path::Path;

/// What every script of a submission shares.
pub struct ScriptSettings<'a> {
    /// The job name's stem (`nbrdf-<profile>`).
    pub name: &'a str,
    /// The xtask executable (absolute).
    pub program: &'a str,
    /// `--backend` of `run-one`.
    pub backend: &'a str,
    /// `--lpips-weights` of `run-one` (absolute), when recorded.
    pub lpips_weights: Option<&'a Path>,
    /// `--partition`, `--account`, `--qos` and the user's extra `#SBATCH` options, as
    /// `--key=value` words.
    pub options: &'a [String],
    /// The folder of Slurm's own output files.
    pub logs: &'a Path,
}

/// The `#SBATCH` header.
fn header(lines: &[String]) -> String {
    let mut out = String::from("#!/bin/bash\n");
    for l in lines {
        out.push_str("#SBATCH ");
        out.push_str(l);
        out.push('\n');
    }
    out
}

/// The script of an array of `count` tasks over the run directories listed in `tasks`.
pub fn array_script(
    s: &ScriptSettings,
    label: &str,
    count: usize,
    tasks: &Path,
    r: &Requests,
) -> String {
    let mut lines = vec![
        format!("--job-name={}-{label}", s.name),
        format!("--array=0-{}", count.saturating_sub(1)),
    ];
    lines.extend(r.sbatch_lines());
    lines.extend([
        // Two minutes before the time limit the batch shell gets SIGTERM: time for the
        // checkpoint; then the task requeues itself.
        "--signal=B:TERM@120".to_string(),
        "--requeue".into(),
        "--open-mode=append".into(),
        format!("--output={}", s.logs.join("%A_%a.out").display()),
    ]);
    lines.extend(s.options.iter().cloned());
    let mut out = header(&lines);
    out.push_str(&format!(
        r#"# Written by `cargo xtask reproduce-tables --slurm`: one task per run of the list below.
set -u
tasks={tasks}
run=$(sed -n "$((SLURM_ARRAY_TASK_ID + 1))p" "$tasks")
if [ -z "$run" ]; then
    echo "no run for task $SLURM_ARRAY_TASK_ID in $tasks" >&2
    exit 2
fi
task="${{SLURM_ARRAY_JOB_ID}}_${{SLURM_ARRAY_TASK_ID}}"
exec >>"$run/sweep.log" 2>&1
echo "== task $task (job $SLURM_JOB_ID, start $((${{SLURM_RESTART_COUNT:-0}} + 1))) on $(hostname) at $(date -u +%Y-%m-%dT%H:%M:%SZ)"
# The run's threads: the CPUs Slurm gave the task (also where no cgroup confines them).
export RAYON_NUM_THREADS="${{SLURM_CPUS_PER_TASK:-1}}"
{program} run-one --quiet --backend {backend}{lpips} "$run" &
child=$!
signalled=0
trap 'signalled=1; kill -TERM "$child" 2>/dev/null' TERM USR1
while :; do
    wait "$child"
    rc=$?
    kill -0 "$child" 2>/dev/null || break
done
if [ "$rc" -eq 75 ] || {{ [ "$signalled" -eq 1 ] && [ "$rc" -ne 0 ]; }}; then
    echo "== task $task stopped for a requeue (exit $rc): its checkpoint resumes it"
    scontrol requeue "$task" || echo "== scontrol requeue $task failed (already requeued?)"
    exit 0
fi
echo "== task $task ended with exit $rc at $(date -u +%Y-%m-%dT%H:%M:%SZ)"
exit "$rc"
"#,
        tasks = shell_quote(&tasks.display().to_string()),
        program = shell_quote(s.program),
        backend = shell_quote(s.backend),
        lpips = s.lpips_weights.map_or(String::new(), |p| {
            format!(" --lpips-weights {}", shell_quote(&p.display().to_string()))
        }),
    ));
    out
}

/// The script of the collect job, started when every array has ended (`afterany`).
pub fn collect_script(s: &ScriptSettings, out_dir: &Path) -> String {
    let mut lines = vec![
        format!("--job-name={}-collect", s.name),
        "--cpus-per-task=2".into(),
        "--mem=8G".into(),
        "--time=0-01:00:00".into(),
        format!("--output={}", s.logs.join("collect-%j.out").display()),
    ];
    lines.extend(s.options.iter().cloned());
    let mut out = header(&lines);
    out.push_str(&format!(
        "# Written by `cargo xtask reproduce-tables --slurm`: the tables, the report and the list \
         of failed runs.\nset -u\nexec {} slurm-collect {}\n",
        shell_quote(s.program),
        shell_quote(&out_dir.display().to_string())
    ));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_array_script_selects_its_run_and_requeues_on_a_signal() {
        let options = vec!["--partition=cpu".to_string(), "--qos=long".into()];
        let s = ScriptSettings {
            name: "nbrdf-smoke",
            program: "/opt/x task/xtask",
            backend: "flex",
            lpips_weights: Some(Path::new("/data/lpips/alex_v0.1.lpipsw")),
            options: &options,
            logs: Path::new("/sweep/slurm/logs"),
        };
        let r = Requests { cpus: 2, mem_mib: 4096, minutes: 90, gpu: false };
        let text = array_script(
            &s,
            "single-mlp",
            12,
            Path::new("/sweep/slurm/submit-001/tasks-1.txt"),
            &r,
        );
        for line in [
            "#SBATCH --array=0-11",
            "#SBATCH --cpus-per-task=2",
            "#SBATCH --mem=4096M",
            "#SBATCH --time=0-01:30:00",
            "#SBATCH --signal=B:TERM@120",
            "#SBATCH --requeue",
            "#SBATCH --partition=cpu",
            "#SBATCH --output=/sweep/slurm/logs/%A_%a.out",
            "'/opt/x task/xtask' run-one --quiet --backend flex --lpips-weights \
             /data/lpips/alex_v0.1.lpipsw \"$run\" &",
            "scontrol requeue \"$task\"",
        ] {
            assert!(text.contains(line), "{line} missing from\n{text}");
        }
        assert!(!text.contains("gres"), "{text}");
        // Every #SBATCH line comes before the first command (sbatch stops reading there).
        let first_command = text.lines().position(|l| !l.starts_with('#')).unwrap();
        assert!(text.lines().skip(first_command).all(|l| !l.starts_with("#SBATCH")));
        let collect = collect_script(&s, Path::new("/sweep"));
        assert!(collect.contains("exec '/opt/x task/xtask' slurm-collect /sweep"), "{collect}");
    }
}
