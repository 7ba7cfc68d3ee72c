//! The LBO eigenpair cache's payload, sealed into a file with a valid checksum and read by
//! `mesh_encoding::lbo::cache::decode` for 4 vertices and 3 pairs (the seed's sizes).
#![no_main]
use mesh_encoding::lbo::cache::{FORMAT_VERSION, MAGIC, decode};
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = decode(&stdx::cache_file::seal(MAGIC, FORMAT_VERSION, 42, data), 42, 4, 3);
});
