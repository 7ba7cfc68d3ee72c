//! How the CPU backends get their tensor memory back: the C allocator is told to keep freed
//! activation buffers for reuse instead of returning them to the kernel.
//!
//! A training step at batch 32768 allocates and frees dozens of 16 to 25 MB tensors. glibc's
//! malloc serves blocks above its mmap threshold (128 KiB, adapting upwards to at most
//! 32 MiB) with fresh `mmap`ed pages and trims the top of the heap when more than its trim
//! threshold is free, so every step page-faults each activation in again and the kernel zeroes
//! it page by page. Raising both thresholds makes a CPU training step markedly faster, and
//! PyTorch's too under the same setting (figures: `benches/README.md`, "Figures that left the
//! source comments").
//!
//! [`keep_freed_tensor_memory`] raises both thresholds once per process (`mallopt`), so freed
//! buffers return to malloc's free lists and the next step reuses them. The price is that the
//! process keeps its peak heap (about the memory of one training step) until it exits. It runs
//! when a CPU device is first made through
//! [`BackendDevice::device`](crate::device::BackendDevice::device) and does nothing on other C
//! libraries (musl, macOS, Windows), whose allocators behave differently. A command line that
//! was told not to (`keep_freed_memory = false` in run-format's `ComputeSettings`,
//! `BRDF_KEEP_MALLOC=0`) calls [`leave_allocator_alone`] first, for comparisons. The policy
//! changes the speed only, never a value.

use std::sync::Once;

/// Whether [`keep_freed_tensor_memory`] changed the allocator's settings in this process.
pub fn is_active() -> bool {
    ACTIVE.load(std::sync::atomic::Ordering::Relaxed)
}

static ONCE: Once = Once::new();
static ACTIVE: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Raises the C allocator's mmap and trim thresholds so that freed tensor buffers are reused
/// (see the module docs). Idempotent; a no-op off glibc or after [`leave_allocator_alone`].
pub fn keep_freed_tensor_memory() {
    ONCE.call_once(|| {
        ACTIVE.store(raise_thresholds(), std::sync::atomic::Ordering::Relaxed);
    });
}

/// Leaves the allocator's settings as they are for the rest of the process: a later
/// [`keep_freed_tensor_memory`] does nothing. Without effect once the policy was applied.
pub fn leave_allocator_alone() {
    ONCE.call_once(|| {});
}

#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn raise_thresholds() -> bool {
    // SAFETY: mallopt only changes malloc's tuning parameters; it is thread-safe in glibc and
    // any value is accepted or rejected (return 0) without side effects.
    unsafe {
        // Older glibc caps the mmap threshold at 32 MiB (HEAP_MAX_SIZE / 2): still above the
        // largest activation of a batch-32768 step ([32768, 188] f32 = 24.6 MB).
        let mmap = libc::mallopt(libc::M_MMAP_THRESHOLD, 1 << 30) == 1
            || libc::mallopt(libc::M_MMAP_THRESHOLD, 32 << 20) == 1;
        let trim = libc::mallopt(libc::M_TRIM_THRESHOLD, i32::MAX) == 1;
        mmap && trim
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn raise_thresholds() -> bool {
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn policy_is_applied_on_glibc_and_idempotent() {
        keep_freed_tensor_memory();
        let first = is_active();
        keep_freed_tensor_memory();
        assert_eq!(is_active(), first);
        assert_eq!(first, cfg!(all(target_os = "linux", target_env = "gnu")));
        leave_allocator_alone();
        assert_eq!(is_active(), first, "too late to leave it alone");
    }
}
