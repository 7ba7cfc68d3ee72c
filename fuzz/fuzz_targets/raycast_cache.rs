//! The ray-casting cache's payload (the postcard-encoded precompute), sealed into a file with a
//! valid checksum and read by `raycast_precompute::cache::decode`: what a writer bug, not a
//! damaged disk, would hand the decoder.
#![no_main]
use raycast_precompute::cache::{FORMAT_VERSION, MAGIC, decode};
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = decode(&stdx::cache_file::seal(MAGIC, FORMAT_VERSION, 42, data), 42);
});
