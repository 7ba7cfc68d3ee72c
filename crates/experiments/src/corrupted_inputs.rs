//! Robustness of the configuration readers (issue 19): corrupted copies of run configurations
//! (truncated, digits and separators scattered, keys and
//! values spliced, noise) give an error naming the file, never a panic; and a probe file that
//! is not one is refused by its checksum.

use run_format::config::RunConfig;
use std::path::Path;
use test_support::corrupt::fuzz_loader;

const RUN: &str = "seed = 5\n[model]\nkind = \"disney\"\nwidth = 32\n[features]\nspatial = \"lbo\"\n\
    [features.lbo]\nk_max = 24\nfirst = 8\nblocks = 2\nblock_len = 4\n[train]\niterations = 300\n\
    batch_size = 2048\nlearning_rate = 5e-4\nlr_final = 1e-4\nwarmup_steps = 20\n\
    checkpoint_every = 20\nlog_every = 10\n[eval]\nenergy_pairs = 16\n";

#[test]
fn corrupted_run_configs_give_errors_not_panics() {
    RunConfig::from_toml(RUN, Path::new("seed.toml")).unwrap();
    fuzz_loader("run-config", &[RUN.as_bytes().to_vec()], 4000, |b| {
        if let Ok(text) = std::str::from_utf8(b)
            && let Err(e) = RunConfig::from_toml(text, Path::new("fuzz.toml"))
        {
            assert!(e.to_string().contains("fuzz.toml"), "{e}");
        }
    });
}

#[test]
fn corrupted_probe_files_give_errors_not_panics() {
    let white = brdf_analytic::Lambert::new(brdf_analytic::LambertParams { albedo: [0.5f32; 3] });
    let p = crate::eval::probe::probe(&white, 0, String::new(), None);
    let tmp = test_support::TempDir::new("fuzz-probe");
    let path = tmp.0.join("probe.bin");
    crate::eval::probe::write(&path, &p).unwrap();
    let seed = std::fs::read(&path).unwrap();
    fuzz_loader("probe", std::slice::from_ref(&seed), 1000, |b| {
        std::fs::write(&path, b).unwrap();
        // Only the intact file decodes: every mutation changes the checksummed payload, the
        // header or the length.
        assert_eq!(crate::eval::probe::read(&path).is_ok(), b == seed.as_slice());
    });
}
