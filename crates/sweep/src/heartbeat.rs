//! Plain progress lines for logs. A sweep's progress bars (indicatif) draw only on a terminal;
//! run with its output in a file (CI, Slurm, nohup) a sweep would print nothing for the hour
//! its runs train. When stderr is not a terminal, a [`Heartbeat`] prints a line when a run
//! ends and at least every 30 seconds in between: runs done of the total, each running run with
//! its last checkpointed step, the time elapsed and an estimate of the time left.
//!
//! The estimate weighs each run by its expected cost (the sweep's own cost model, which also
//! orders the runs longest first): the runs left cost what the model expects, scaled by how the
//! finished runs' wall times compared with their expectations. A plain mean over the finished
//! runs would overstate the rest of a longest-first sweep (by 1.5 to 2.2x through most of an
//! every-table default).
//!
//! ```text
//! sweep: 5/27 runs done; running spot__brass__disney__default (step 1200), spot__brass__ts__default (step 400); 12.3 min elapsed, about 31 min left
//! ```
//!
//! When and how often is a [`ProgressLines`] value, the command line's: there
//! `NEURAL_BRDF_PROGRESS_LINES=1` prints them on a terminal too (`0`: never) and
//! `NEURAL_BRDF_PROGRESS_SECS` sets the interval (default 30).

use run_format::run_dir::RunDir;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// When a sweep prints its progress lines, and how often (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ProgressLines {
    /// `Some(true)`: always, `Some(false)`: never; `None` (the default): when stderr is not a
    /// terminal.
    pub wanted: Option<bool>,
    /// The longest time between two lines (default 30 s, at least 1 s).
    pub every: Duration,
}

impl Default for ProgressLines {
    fn default() -> Self {
        ProgressLines { wanted: None, every: Duration::from_secs(30) }
    }
}

impl ProgressLines {
    /// The environment variables that override these settings (read by the command line only).
    pub const VARIABLES: &[(&str, &str)] = &[
        ("NEURAL_BRDF_PROGRESS_LINES", "1: print the lines on a terminal too, 0: never"),
        ("NEURAL_BRDF_PROGRESS_SECS", "seconds between two lines at most (default 30)"),
    ];

    /// These settings with `variable` (one of [`ProgressLines::VARIABLES`]) set from `value`.
    ///
    /// # Errors
    /// A value the variable does not take, or another variable, named.
    pub fn with_override(mut self, variable: &str, value: &str) -> experiments::Result<Self> {
        let bad = |expected: &str| {
            experiments::Error::format(
                Path::new(variable),
                format!("`{value}`: expected {expected}"),
            )
        };
        match (variable, value.trim()) {
            ("NEURAL_BRDF_PROGRESS_LINES", "1") => self.wanted = Some(true),
            ("NEURAL_BRDF_PROGRESS_LINES", "0") => self.wanted = Some(false),
            ("NEURAL_BRDF_PROGRESS_LINES", _) => return Err(bad("1 or 0")),
            ("NEURAL_BRDF_PROGRESS_SECS", v) => match v.parse::<u64>() {
                Ok(secs) if secs >= 1 => self.every = Duration::from_secs(secs),
                _ => return Err(bad("a whole number of seconds, at least 1")),
            },
            _ => return Err(bad("a progress setting's name")),
        }
        Ok(self)
    }

    fn show(&self) -> bool {
        self.wanted.unwrap_or_else(|| !std::io::stderr().is_terminal())
    }
}

/// What the lines report.
struct State {
    total: usize,
    jobs: usize,
    done: usize,
    failed: usize,
    running: Vec<PathBuf>,
    /// Wall seconds of each run finished in this sweep.
    seconds: Vec<f64>,
    /// The expected cost of each run not yet started (any unit; 0 where unknown).
    pending: Vec<(PathBuf, f64)>,
    /// Expected costs and wall seconds of the finished runs whose cost was known, summed.
    finished_expected: f64,
    finished_seconds: f64,
    /// Each running run, its start and its expected cost.
    started: Vec<(PathBuf, Instant, f64)>,
    start: Instant,
    last_line: Instant,
}

/// Prints the progress lines of a sweep's runs while it lives (see the module doc).
pub struct Heartbeat {
    state: Option<Arc<Mutex<State>>>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl Heartbeat {
    /// Starts the lines for `runs` (each with its expected cost, in any unit, 0 where unknown),
    /// `jobs` at a time (nothing when `lines` does not want them).
    pub fn start(runs: Vec<(PathBuf, f64)>, jobs: usize, lines: &ProgressLines) -> Self {
        let stop = Arc::new(AtomicBool::new(false));
        if !lines.show() || runs.is_empty() {
            return Heartbeat { state: None, stop, thread: None };
        }
        let now = Instant::now();
        let state = Arc::new(Mutex::new(State {
            total: runs.len(),
            jobs: jobs.max(1),
            done: 0,
            failed: 0,
            running: Vec::new(),
            seconds: Vec::new(),
            pending: runs,
            finished_expected: 0.0,
            finished_seconds: 0.0,
            started: Vec::new(),
            start: now,
            last_line: now,
        }));
        let every = lines.every.max(Duration::from_secs(1));
        let (s, flag) = (Arc::clone(&state), Arc::clone(&stop));
        let thread = std::thread::spawn(move || {
            while !flag.load(Ordering::Relaxed) {
                std::thread::sleep(Duration::from_millis(200).min(every));
                let mut st = s.lock().unwrap_or_else(PoisonError::into_inner);
                if st.last_line.elapsed() >= every {
                    eprintln!("{}", line(&st));
                    st.last_line = Instant::now();
                }
            }
        });
        Heartbeat { state: Some(state), stop, thread: Some(thread) }
    }

    fn with(&self, f: impl FnOnce(&mut State)) {
        if let Some(s) = &self.state {
            f(&mut s.lock().unwrap_or_else(PoisonError::into_inner));
        }
    }

    /// A run started.
    pub fn started(&self, run: &Path) {
        self.with(|st| {
            st.running.push(run.to_path_buf());
            let cost = match st.pending.iter().position(|(r, _)| r == run) {
                Some(i) => st.pending.swap_remove(i).1,
                None => 0.0,
            };
            st.started.push((run.to_path_buf(), Instant::now(), cost));
        });
    }

    /// A run ended (`ok`: evaluated); prints a line.
    pub fn finished(&self, run: &Path, ok: bool) {
        self.with(|st| {
            st.running.retain(|r| r != run);
            if let Some(i) = st.started.iter().position(|(r, ..)| r == run) {
                let (_, t, cost) = st.started.swap_remove(i);
                let seconds = t.elapsed().as_secs_f64();
                st.seconds.push(seconds);
                if cost > 0.0 {
                    st.finished_expected += cost;
                    st.finished_seconds += seconds;
                }
            }
            st.done += 1;
            if !ok {
                st.failed += 1;
            }
            let what = if ok { "finished" } else { "failed" };
            eprintln!("sweep: {} {what}", name(run));
            eprintln!("{}", line(st));
            st.last_line = Instant::now();
        });
    }
}

impl Drop for Heartbeat {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// A run directory's name without its step budget and id.
fn name(run: &Path) -> String {
    let n = run.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let parts: Vec<&str> = n.split("__").collect();
    if parts.len() > 2 { parts[..parts.len() - 2].join("__") } else { n }
}

/// The step of a run's last checkpoint (the last row of its `curve.csv`).
fn last_step(run: &Path) -> Option<u64> {
    let text = std::fs::read_to_string(RunDir::new(run).curve()).ok()?;
    text.lines().last()?.split(',').next()?.trim().parse().ok()
}

fn minutes(s: f64) -> String {
    if s < 90.0 { format!("{s:.0} s") } else { format!("{:.1} min", s / 60.0) }
}

fn line(st: &State) -> String {
    let mut s = format!("sweep: {}/{} runs done", st.done, st.total);
    if st.failed > 0 {
        s += &format!(", {} failed", st.failed);
    }
    if !st.running.is_empty() {
        let running: Vec<String> = st
            .running
            .iter()
            .map(|r| match last_step(r) {
                Some(step) => format!("{} (step {step})", name(r)),
                None => format!("{} (starting)", name(r)),
            })
            .collect();
        s += &format!("; running {}", running.join(", "));
    }
    let elapsed = st.start.elapsed().as_secs_f64();
    s += &format!("; {} elapsed", minutes(elapsed));
    if let Some(estimate) = seconds_left(st) {
        s += &format!(", about {} left", minutes(estimate));
    }
    s
}

/// The wall seconds the sweep has left, once a run has finished: each run left at its
/// expected cost times the finished runs' seconds per unit of cost (a run of unknown cost at
/// the finished runs' mean), a running run less the time it has run, over the jobs.
fn seconds_left(st: &State) -> Option<f64> {
    if st.done >= st.total || st.seconds.is_empty() {
        return None;
    }
    let mean = st.seconds.iter().sum::<f64>() / st.seconds.len() as f64;
    let rate = (st.finished_expected > 0.0).then(|| st.finished_seconds / st.finished_expected);
    let seconds = |cost: f64| match rate {
        Some(r) if cost > 0.0 => cost * r,
        _ => mean,
    };
    let pending: f64 = st.pending.iter().map(|(_, c)| seconds(*c)).sum();
    let running: f64 =
        st.started.iter().map(|(_, t, c)| (seconds(*c) - t.elapsed().as_secs_f64()).max(0.0)).sum();
    Some((pending + running) / st.jobs as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn progress_settings_parse_and_bad_values_name_the_variable() {
        let d = ProgressLines::default();
        assert_eq!((d.wanted, d.every), (None, Duration::from_secs(30)));
        let on = d.with_override("NEURAL_BRDF_PROGRESS_LINES", "1").unwrap();
        assert!(on.wanted == Some(true) && on.show());
        let off = d.with_override("NEURAL_BRDF_PROGRESS_LINES", " 0 ").unwrap();
        assert!(!off.show());
        let every = d.with_override("NEURAL_BRDF_PROGRESS_SECS", "5").unwrap();
        assert_eq!(every.every, Duration::from_secs(5));
        for (var, bad) in [
            ("NEURAL_BRDF_PROGRESS_LINES", "yes"),
            ("NEURAL_BRDF_PROGRESS_SECS", "0"),
            ("NEURAL_BRDF_PROGRESS_SECS", "soon"),
            ("NEURAL_BRDF_PROGRESS_NOTHING", "1"),
        ] {
            let e = d.with_override(var, bad).unwrap_err().to_string();
            assert!(e.contains(var), "{e}");
        }
    }

    #[test]
    fn lines_name_the_runs_their_steps_and_the_time_left() {
        let tmp = test_support::TempDir::new("heartbeat");
        let run = tmp.0.join("spot__brass__disney__default__6000__0123456789abcdef");
        std::fs::create_dir_all(&run).unwrap();
        let now = Instant::now();
        let mut st = State {
            total: 4,
            jobs: 2,
            done: 1,
            failed: 0,
            running: vec![run.clone()],
            seconds: vec![120.0],
            pending: vec![(tmp.0.join("a"), 0.0), (tmp.0.join("b"), 0.0)],
            finished_expected: 0.0,
            finished_seconds: 0.0,
            started: vec![(run.clone(), now, 0.0)],
            start: now,
            last_line: now,
        };
        let l = line(&st);
        assert!(
            l.starts_with("sweep: 1/4 runs done; running spot__brass__disney__default (starting)"),
            "{l}"
        );
        // 3 runs left at 120 s, 2 at a time, the running one just begun: about 3 min.
        assert!(l.contains("about 3.0 min left"), "{l}");
        std::fs::write(RunDir::new(&run).curve(), "step,loss\n250,0.1\n500,0.05\n").unwrap();
        st.failed = 1;
        let l = line(&st);
        assert!(l.contains("(step 500)") && l.contains(", 1 failed"), "{l}");
    }

    #[test]
    fn the_time_left_weighs_the_runs_left_by_their_expected_cost() {
        // Longest first: two finished runs expected at 400 took 200 s each (0.5 s a unit);
        // one running run expected at 100 began just now, two pending at 100 and 20.
        let now = Instant::now();
        let mut st = State {
            total: 5,
            jobs: 2,
            done: 2,
            failed: 0,
            running: vec![PathBuf::from("c")],
            seconds: vec![200.0, 200.0],
            pending: vec![(PathBuf::from("d"), 100.0), (PathBuf::from("e"), 20.0)],
            finished_expected: 800.0,
            finished_seconds: 400.0,
            started: vec![(PathBuf::from("c"), now, 100.0)],
            start: now,
            last_line: now,
        };
        // (50 + 50 + 10) s over 2 jobs, where the mean of the finished runs would say 300 s.
        let left = seconds_left(&st).unwrap();
        assert!((left - 55.0).abs() < 0.5, "{left}");
        // A pending run of unknown cost counts at the finished runs' mean.
        st.pending.push((PathBuf::from("f"), 0.0));
        st.total = 6;
        let left = seconds_left(&st).unwrap();
        assert!((left - 155.0).abs() < 0.5, "{left}");
        st.done = st.total;
        assert!(seconds_left(&st).is_none());
    }
}
