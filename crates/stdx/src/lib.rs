//! The workspace's small shared utilities, one home for each (after rust-analyzer's `stdx`):
//!
//! - [`fs`]: atomic, durable writes of a file or a whole directory (a reader never sees a
//!   half-written one), and the removal of a killed writer's temporaries;
//! - [`limits`]: what a loader of users' files accepts before it allocates on a declared size;
//! - [`lock`]: exclusive folder locks (one process at a time in a run directory or a sweep);
//! - [`rng`]: SplitMix64, the seeded generator behind every reproducible stream that is not a
//!   `rand` one (orbit cameras, sensor noise, light splits, Lanczos start blocks, Monte Carlo);
//! - [`progress`]: the progress-bar styles of every long step;
//! - [`simd`]: loops compiled for AVX2 where the CPU has it, with the baseline build's bits;
//! - [`prefetch`]: software prefetches for loops of random reads (hints: no value changes);
//! - [`cache_file`]: the versioned, checksummed container of every on-disk cache (serde values in
//!   postcard).
//!
//! It sits at the bottom of the layering and depends on no crate of ours. `fs`, `progress` and
//! `cache` are features (off by default), so a crate that needs only the generator (brdf-analytic,
//! usable alone by a renderer) pulls in nothing.

#[cfg(feature = "cache")]
pub mod cache_file;
#[cfg(feature = "fs")]
pub mod fs;
pub mod limits;
#[cfg(feature = "fs")]
pub mod lock;
pub mod prefetch;
#[cfg(feature = "progress")]
pub mod progress;
pub mod rng;
pub mod simd;

pub use limits::Limits;
