//! MAT v5 files (plain and compressed variables).
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = dataset_diligent::mat5::MatFile::parse(data, std::path::Path::new("fuzz.mat"), &stdx::Limits::DEFAULT);
});
