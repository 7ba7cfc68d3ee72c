//! Whether the kernels launch checked: CubeCL then guards every index into a buffer (an
//! out-of-bounds read gives 0, a write is dropped) and, on wgpu, bounds every loop with a
//! counter. The kernels guard their own reads and writes (the products zero-pad past the
//! matrices' edges), so by default they launch unchecked: the extra compare on each load and
//! the loop counters cost the inner loop of a product, and the counters keep the driver from
//! unrolling it. burn's own GPU products (cubek-matmul) launch unchecked for the same reason.
//! Checked launches remain a process-wide setting, a debugging aid that gives the same
//! results, and a knob for the benchmarks to measure what the checks cost.

use std::sync::atomic::{AtomicBool, Ordering};

static CHECKED_NOW: AtomicBool = AtomicBool::new(false);

/// Launches every kernel of this process checked (`true`) or unchecked (`false`, the default).
pub fn set_checked(checked: bool) {
    CHECKED_NOW.store(checked, Ordering::Relaxed);
}

/// Whether this process's kernels launch checked ([`set_checked`]).
pub fn checked() -> bool {
    CHECKED_NOW.load(Ordering::Relaxed)
}

/// `launch!(kernel, args...)`: `kernel::launch(args...)` when [`checked`], else
/// `kernel::launch_unchecked(args...)` (the kernel is declared `#[cube(launch,
/// launch_unchecked)]`). Expands to unsafe calls: use it inside an `unsafe` block whose
/// caller vouches for the buffers' lengths.
macro_rules! launch {
    ($kernel:ident, $($arg:expr),+ $(,)?) => {
        if $crate::checks::checked() {
            $kernel::launch($($arg),+)
        } else {
            $kernel::launch_unchecked($($arg),+)
        }
    };
}
pub(crate) use launch;
