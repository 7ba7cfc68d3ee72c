//! Corrupted copies of real files for the loaders' robustness tests: the stable stand-in for
//! coverage-guided fuzzing that runs in CI (issue 19). A proptest strategy draws a list of
//! [`Mutation`]s (truncation, bit flips, header integers blasted to extremes such as 2^40,
//! spliced and deleted chunks, digits and separators in text, pure noise); [`fuzz_loader`]
//! applies them to each seed file and calls the loader, which must return (`Ok` or `Err`)
//! without panicking. proptest shrinks a failing case to its smallest mutation list, and the
//! corrupted input is written to `target/fuzz-failures/<target>-<hash>.bin` to become a
//! regression test.
//!
//! [`CappedAlloc`] turns an allocation beyond a stated cap (a header that claims 2^40 elements)
//! into an immediate abort with a message, instead of an out-of-memory kill minutes later: a
//! test binary installs it as its `#[global_allocator]`.
//!
//! With [`SEED_DIR_VAR`] set to a folder, [`fuzz_loader`] also copies its seeds there, one
//! sub-folder per target (`-` written `_`): `NEURAL_BRDF_FUZZ_SEEDS=$PWD/fuzz/corpus cargo test
//! --workspace corrupted` fills the libFuzzer targets' corpora with the same real files.

use proptest::prelude::*;
use proptest::test_runner::{Config, TestCaseError, TestError, TestRunner};
use std::alloc::{GlobalAlloc, Layout, System};
use std::panic::{AssertUnwindSafe, catch_unwind};

/// One change to a file's bytes; positions are fractions of the current length.
#[derive(Clone, Debug)]
pub enum Mutation {
    /// Keep the first fraction of the bytes.
    Truncate(f64),
    /// XOR one byte with a non-zero mask.
    Flip(f64, u8),
    /// Overwrite `width` bytes (little endian) with an extreme integer.
    Blast(f64, u64, u8),
    /// Copy a chunk (start, length in bytes) to another position.
    Splice(f64, u16, f64),
    /// Delete a chunk (start, length in bytes).
    Delete(f64, u16),
    /// Overwrite one byte with a character text formats care about.
    Text(f64, u8),
    /// Replace everything with these bytes.
    Noise(Vec<u8>),
}

/// Integers a corrupted header likes to claim.
const EXTREMES: [u64; 10] =
    [0, 1, 0x7F, 0xFF, 0x7FFF_FFFF, 0xFFFF_FFFF, 1 << 31, 1 << 40, u64::MAX, 0x8000_0000_0000_0000];

/// Characters that change the meaning of text formats.
const TEXT: &[u8] = b"0123456789-.eE+\n\r \t/#\"'[]{}=,:\0nN";

/// A strategy for one mutation.
pub fn mutation() -> impl Strategy<Value = Mutation> {
    let at = 0.0f64..1.0;
    prop_oneof![
        3 => at.clone().prop_map(Mutation::Truncate),
        4 => (at.clone(), 1u8..=255).prop_map(|(p, m)| Mutation::Flip(p, m)),
        4 => (at.clone(), prop::sample::select(&EXTREMES[..]), prop::sample::select(&[1u8, 2, 4, 8][..]))
            .prop_map(|(p, v, w)| Mutation::Blast(p, v, w)),
        1 => (at.clone(), 1u16..512, at.clone()).prop_map(|(a, n, b)| Mutation::Splice(a, n, b)),
        1 => (at.clone(), 1u16..512).prop_map(|(a, n)| Mutation::Delete(a, n)),
        3 => (at, prop::sample::select(TEXT)).prop_map(|(p, c)| Mutation::Text(p, c)),
        1 => prop::collection::vec(any::<u8>(), 0..256).prop_map(Mutation::Noise),
    ]
}

/// `bytes` with `m` applied.
pub fn apply(bytes: &mut Vec<u8>, m: &Mutation) {
    let n = bytes.len();
    let pos = |f: f64| ((f * n as f64) as usize).min(n.saturating_sub(1));
    match m {
        Mutation::Truncate(f) => bytes.truncate((f * n as f64) as usize),
        Mutation::Flip(f, mask) if n > 0 => bytes[pos(*f)] ^= mask,
        Mutation::Blast(f, v, w) if n > 0 => {
            let p = pos(*f);
            for (k, b) in v.to_le_bytes().iter().take(*w as usize).enumerate() {
                if let Some(x) = bytes.get_mut(p + k) {
                    *x = *b;
                }
            }
        }
        Mutation::Splice(a, len, b) if n > 0 => {
            let a = pos(*a);
            let chunk: Vec<u8> = bytes[a..(a + *len as usize).min(n)].to_vec();
            let b = pos(*b);
            bytes.splice(b..b, chunk);
        }
        Mutation::Delete(a, len) if n > 0 => {
            let a = pos(*a);
            bytes.drain(a..(a + *len as usize).min(n));
        }
        Mutation::Text(f, c) if n > 0 => bytes[pos(*f)] = *c,
        Mutation::Noise(v) => *bytes = v.clone(),
        _ => {}
    }
}

/// The environment variable naming a folder that [`fuzz_loader`] copies its seeds to.
pub const SEED_DIR_VAR: &str = "NEURAL_BRDF_FUZZ_SEEDS";

/// Copies the seeds to `$NEURAL_BRDF_FUZZ_SEEDS/<target>/seed-<i>` when the variable is set.
fn export_seeds(target: &str, seeds: &[Vec<u8>]) {
    let Some(root) = std::env::var_os(SEED_DIR_VAR) else { return };
    let dir = std::path::Path::new(&root).join(target.replace('-', "_"));
    let _ = std::fs::create_dir_all(&dir);
    for (i, seed) in seeds.iter().enumerate() {
        let _ = std::fs::write(dir.join(format!("seed-{i}")), seed);
    }
}

/// Runs `loader` on `cases` corrupted copies of the seeds (1 to 4 mutations each, every seed
/// in turn, deterministic for the workspace's `PROPTEST_RNG_SEED`) and on each seed as it is.
/// The loader returns whatever it likes; only a panic fails, and the input that caused it is
/// saved under `target/fuzz-failures/`. Returns how many inputs it ran.
///
/// # Panics
/// When the loader panics on some input (after shrinking), naming the saved file.
pub fn fuzz_loader(target: &str, seeds: &[Vec<u8>], cases: u32, loader: impl Fn(&[u8])) -> usize {
    assert!(!seeds.is_empty(), "{target}: no seed file");
    export_seeds(target, seeds);
    for s in seeds {
        if catch_unwind(AssertUnwindSafe(|| loader(s))).is_err() {
            panic!("{target}: the loader panicked on an unmodified seed");
        }
    }
    let mut runner =
        TestRunner::new(Config { cases, failure_persistence: None, ..Config::default() });
    let strategy = (0..seeds.len(), prop::collection::vec(mutation(), 1..=4));
    let ran = std::cell::Cell::new(seeds.len());
    let corrupt = |i: usize, ms: &[Mutation]| {
        let mut bytes = seeds[i].clone();
        for m in ms {
            apply(&mut bytes, m);
        }
        bytes
    };
    // Each input is on disk while the loader runs, so an abort (the allocation cap) leaves it.
    let current = failure_dir().join(format!("{target}-current.bin"));
    let _ = std::fs::create_dir_all(failure_dir());
    let result = runner.run(&strategy, |(i, ms)| {
        let bytes = corrupt(i, &ms);
        let _ = std::fs::write(&current, &bytes);
        ran.set(ran.get() + 1);
        match catch_unwind(AssertUnwindSafe(|| loader(&bytes))) {
            Ok(()) => Ok(()),
            Err(_) => Err(TestCaseError::fail("the loader panicked")),
        }
    });
    match result {
        Ok(()) => {
            let _ = std::fs::remove_file(&current);
            eprintln!("{target}: {} inputs, no panic", ran.get());
            ran.get()
        }
        Err(TestError::Fail(why, (i, ms))) => {
            let path = save_failure(target, &corrupt(i, &ms));
            panic!("{target}: {why} on seed {i} after {ms:?}; the input is saved as {path}")
        }
        Err(e) => panic!("{target}: {e}"),
    }
}

/// `target/fuzz-failures/` of the workspace.
fn failure_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/fuzz-failures")
}

/// Writes a failing input under `target/fuzz-failures/` and returns its path.
fn save_failure(target: &str, bytes: &[u8]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bytes {
        h = (h ^ u64::from(*b)).wrapping_mul(0x100_0000_01b3);
    }
    let dir = failure_dir();
    let path = dir.join(format!("{target}-{h:016x}.bin"));
    let _ = std::fs::create_dir_all(&dir);
    let _ = std::fs::write(&path, bytes);
    path.display().to_string()
}

/// The system allocator with a cap on any single allocation: beyond it, a message and an
/// abort (a header that claims 2^40 elements must be an error, not an out-of-memory kill).
pub struct CappedAlloc(pub usize);

// SAFETY: forwards to the system allocator; the cap only adds an abort before it.
unsafe impl GlobalAlloc for CappedAlloc {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if layout.size() > self.0 {
            over_cap();
        }
        // SAFETY: same contract as ours.
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if layout.size() > self.0 {
            over_cap();
        }
        // SAFETY: same contract as ours.
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as ours.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if new_size > self.0 {
            over_cap();
        }
        // SAFETY: same contract as ours.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

fn over_cap() -> ! {
    use std::io::Write as _;
    // No allocation here: a static message straight to the unbuffered stderr.
    let _ = std::io::stderr().write_all(
        b"allocation over the fuzz cap: a loader trusted a size; the input is \
          target/fuzz-failures/<target>-current.bin\n",
    );
    std::process::abort()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mutations_stay_in_bounds_and_change_the_bytes() {
        let seed: Vec<u8> = (0..100).collect();
        let mut b = seed.clone();
        apply(&mut b, &Mutation::Truncate(0.25));
        assert_eq!(b.len(), 25);
        let mut b = seed.clone();
        apply(&mut b, &Mutation::Blast(0.99, 1 << 40, 8));
        assert_eq!(b.len(), 100, "a blast at the end is clipped, not grown");
        let mut b = seed.clone();
        apply(&mut b, &Mutation::Blast(0.5, 1 << 40, 8));
        assert_eq!(&b[50..56], &[0, 0, 0, 0, 0, 1]);
        let mut b = seed.clone();
        apply(&mut b, &Mutation::Delete(0.9, 500));
        assert_eq!(b.len(), 90);
        let mut empty = Vec::new();
        for m in [Mutation::Flip(0.5, 1), Mutation::Splice(0.1, 3, 0.2), Mutation::Text(0.0, b'x')]
        {
            apply(&mut empty, &m);
        }
        assert!(empty.is_empty());
    }

    #[test]
    fn a_panicking_loader_is_caught_and_its_input_saved() {
        let seeds = vec![b"ok".to_vec()];
        // Every mutation changes the seed, so this loader panics on the first case.
        let r = catch_unwind(|| fuzz_loader("selftest", &seeds, 16, |b| assert!(b == b"ok")));
        let e = r.expect_err("the panic is reported");
        let msg = e.downcast_ref::<String>().cloned().unwrap_or_default();
        assert!(msg.contains("fuzz-failures/selftest-"), "{msg}");
        let ran = fuzz_loader("selftest-ok", &seeds, 32, |_| {});
        assert_eq!(ran, 33);
    }
}
