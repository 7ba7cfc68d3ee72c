//! Stopping a run for a requeue: what a cluster's preemption or time limit asks of a process.
//!
//! A scheduler that preempts a task or reaches its time limit sends SIGTERM (Slurm's
//! `--signal=B:TERM@120`, or USR1) and kills the process a grace period later. After
//! [`install`], the first such signal during training ends the fit at the next step boundary:
//! the training loop writes a checkpoint of that step and returns as interrupted
//! ([`crate::FitOutcome::Stopped`]), so that a requeued task resumes it and ends with the same
//! weights, byte for byte, as an uninterrupted run (a checkpoint holds the weights, Adam's state,
//! the curve and the plateau rule's state, and every batch is a function of (seed, step)). A
//! signal outside training (reading the scene, evaluating) ends the process at once with
//! [`EXIT_REQUEUE`]: every file is written atomically, so nothing is half-written, and what was
//! under way is redone by the requeued task.
//!
//! A signal is a process-wide event, so the request is a process-wide flag; nothing else in
//! the process reads it. Without [`install`] (tests, the library), signals keep their default
//! action.

use std::sync::atomic::{AtomicBool, Ordering};

/// The exit status of a process stopped for a requeue (`EX_TEMPFAIL` of `sysexits.h`): the run
/// is unfinished and resumes from its checkpoint when started again.
pub const EXIT_REQUEUE: i32 = 75;

/// Set by the handler: stop at the next step boundary.
static REQUESTED: AtomicBool = AtomicBool::new(false);
/// Set while a training loop runs (the handler then only sets [`REQUESTED`]).
static TRAINING: AtomicBool = AtomicBool::new(false);

/// Installs the handler of SIGTERM and SIGUSR1 for this process (Unix; elsewhere nothing).
pub fn install() {
    #[cfg(unix)]
    {
        extern "C" fn on_signal(_: libc::c_int) {
            if TRAINING.load(Ordering::SeqCst) {
                REQUESTED.store(true, Ordering::SeqCst);
            } else {
                // Async-signal-safe: no destructor or buffered output runs.
                // SAFETY: `_exit` may be called from a signal handler.
                unsafe { libc::_exit(EXIT_REQUEUE) };
            }
        }
        let handler = on_signal as extern "C" fn(libc::c_int) as libc::sighandler_t;
        for signal in [libc::SIGTERM, libc::SIGUSR1] {
            // SAFETY: the handler only touches atomics or calls `_exit`.
            unsafe { libc::signal(signal, handler) };
        }
    }
}

/// Whether a stop was requested since the training loop began.
pub fn requested() -> bool {
    REQUESTED.load(Ordering::SeqCst)
}

/// Marks the calling code as a training loop until dropped: a signal then waits for the next
/// step boundary instead of ending the process.
pub(crate) struct Training(());

impl Training {
    pub(crate) fn begin() -> Self {
        TRAINING.store(true, Ordering::SeqCst);
        Training(())
    }
}

impl Drop for Training {
    fn drop(&mut self) {
        TRAINING.store(false, Ordering::SeqCst);
    }
}

/// Requests a stop as a signal would (tests of the loop's handling, without signals).
#[doc(hidden)]
pub fn request_for_test(on: bool) {
    REQUESTED.store(on, Ordering::SeqCst);
}
