//! Robustness of the sweep profile reader (issue 19): corrupted copies of every shipped
//! profile (truncated, digits and separators scattered, keys and values spliced, noise) give
//! an error naming the file, never a panic.

use std::path::Path;
use sweep::SweepProfile;
use test_support::corrupt::fuzz_loader;

#[test]
fn corrupted_sweep_profiles_give_errors_not_panics() {
    let seeds: Vec<Vec<u8>> = ["default", "quick", "smoke", "runtime", "full"]
        .iter()
        .map(|name| {
            let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles");
            std::fs::read(dir.join(format!("{name}.toml"))).unwrap()
        })
        .collect();
    fuzz_loader("sweep-profile", &seeds, 4000, |b| {
        if let Ok(text) = std::str::from_utf8(b)
            && let Err(e) = SweepProfile::parse(text, "fuzz-profile.toml")
        {
            assert!(e.to_string().contains("fuzz-profile.toml"), "{e}");
        }
    });
}
