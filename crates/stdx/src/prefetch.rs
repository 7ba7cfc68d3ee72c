//! Software prefetches for random reads: a loop that gathers rows at random indices (a
//! training batch out of millions of records) waits on memory for each one; asking for the
//! rows a few iterations ahead lets those waits overlap. A hint only: it changes no value, and
//! it is a no-op where the target has no stable prefetch instruction.

/// Cache line size assumed for [`slice`]'s stride (64 bytes on every x86-64 CPU).
const LINE: usize = 64;

/// Asks for the cache line holding `value` to be loaded into every cache level.
#[inline(always)]
pub fn read<T>(value: &T) {
    line(std::ptr::from_ref(value).cast());
}

/// Asks for every cache line of `values` to be loaded into every cache level.
#[inline(always)]
pub fn slice<T>(values: &[T]) {
    let start: *const u8 = values.as_ptr().cast();
    let bytes = std::mem::size_of_val(values);
    // A line's worth apart from the first byte, then the last byte (whose line the strides
    // miss when the slice does not start on a line).
    for offset in (0..bytes).step_by(LINE) {
        line(start.wrapping_add(offset));
    }
    if bytes > 0 {
        line(start.wrapping_add(bytes - 1));
    }
}

#[inline(always)]
fn line(p: *const u8) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch never faults and reads nothing into the program; SSE (which has it)
    // is part of the x86-64 baseline.
    unsafe {
        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(p.cast());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hints_change_nothing_and_accept_any_slice() {
        let rows: Vec<f32> = (0..1000).map(|i| i as f32).collect();
        // Unaligned starts, lengths across line ends, an empty slice, a single value.
        for start in [0, 1, 15, 16, 17, 500] {
            for len in [0, 1, 16, 17, 160, 1000 - start] {
                slice(&rows[start..start + len]);
            }
        }
        read(&rows[999]);
        slice::<u8>(&[]);
        assert!(rows.iter().enumerate().all(|(i, &x)| x == i as f32));
    }
}
