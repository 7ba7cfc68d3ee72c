//! MERL binary tables: any bytes give a table or an error naming the input.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = dataset_merl::MerlBrdf::from_bytes(data, "fuzz.binary");
});
