//! Robustness of the LPIPS weight reader (issue 19): corrupted copies of a weight file
//! (truncated, bit-flipped, counts and dimensions blasted to 2^31 or 2^40, noise) give an
//! error naming the file, never a panic, an overflow or an unbounded allocation.

use metrics::lpips::weights::{Tensors, read, write};
use test_support::corrupt::{CappedAlloc, fuzz_loader};

/// Nothing the reader does may allocate more than 256 MiB at once.
#[global_allocator]
static ALLOC: CappedAlloc = CappedAlloc(1 << 28);

#[test]
fn corrupted_lpips_weights_give_errors_not_panics() {
    let tmp = test_support::TempDir::new("fuzz-lpips");
    let path = tmp.0.join("w.lpipsw");
    let mut t = Tensors::new();
    t.insert("conv1.weight".into(), (vec![2, 3, 1, 1], (0..6).map(|i| i as f32).collect()));
    t.insert("lin0.weight".into(), (vec![1, 2, 1, 1], vec![0.5, 0.25]));
    write(&path, &t).unwrap();
    assert_eq!(read(&path).unwrap(), t);
    let seeds = vec![std::fs::read(&path).unwrap()];
    fuzz_loader("lpips-weights", &seeds, 5000, |b| {
        std::fs::write(&path, b).unwrap();
        if let Err(e) = read(&path) {
            assert!(e.to_string().contains("w.lpipsw"), "{e}");
        }
    });
}

/// A dimension list whose product overflows is an error (the size arithmetic is checked).
#[test]
fn overflowing_dimensions_are_an_error() {
    let tmp = test_support::TempDir::new("lpips-dims");
    let path = tmp.0.join("big.lpipsw");
    let mut b = b"LPIPSW1\0".to_vec();
    b.extend_from_slice(&1u32.to_le_bytes());
    b.extend_from_slice(&1u32.to_le_bytes());
    b.push(b'w');
    b.extend_from_slice(&4u32.to_le_bytes());
    for _ in 0..4 {
        b.extend_from_slice(&u32::MAX.to_le_bytes());
    }
    std::fs::write(&path, &b).unwrap();
    let e = read(&path).unwrap_err().to_string();
    assert!(e.contains("overflow") && e.contains("big.lpipsw"), "{e}");
}
