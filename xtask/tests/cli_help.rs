//! One command line: every `cargo xtask` subcommand answers `--help`, and the commands on one
//! run directory are the `experiments` binary's own (the same parser, [`RunCommand`]), with the
//! same options.

use clap::Subcommand;
use experiments::cli::RunCommand;
use std::process::Command;

fn xtask(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_xtask")).args(args).output().unwrap();
    let text =
        String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "xtask {args:?} failed:\n{text}");
    text
}

/// The subcommand names of a `--help` text's "Commands:" list.
fn commands(help: &str) -> Vec<String> {
    help.lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next().map(str::to_string))
        .filter(|c| c != "help")
        .collect()
}

/// The long options of a help text, sorted.
fn options(help: &str) -> Vec<String> {
    let mut o: Vec<String> = help
        .split_whitespace()
        .filter(|w| w.starts_with("--"))
        .map(|w| w.trim_end_matches([',', '.', ')', '`']).to_string())
        .collect();
    o.sort();
    o.dedup();
    o
}

#[test]
fn every_subcommand_has_help_and_the_run_commands_match_the_experiments_binary() {
    let top = xtask(&["--help"]);
    let listed = commands(&top);
    assert!(listed.len() >= 15, "{top}");
    for c in &listed {
        let help = xtask(&[c, "--help"]);
        assert!(help.contains(&format!("Usage: xtask {c}")), "{c}: {help}");
    }
    let mut run = RunCommand::augment_subcommands(clap::Command::new("experiments"));
    run.build();
    let names: Vec<String> =
        run.get_subcommands().map(|s| s.get_name().to_string()).filter(|n| n != "help").collect();
    assert_eq!(names, ["fit", "eval", "energy", "export", "export-merl"]);
    for name in &names {
        assert!(listed.contains(name), "xtask lacks {name}: {top}");
        let ours = run.find_subcommand_mut(name).unwrap().render_long_help().to_string();
        assert_eq!(options(&xtask(&[name, "--help"])), options(&ours), "{name}");
    }
}

/// Runs `cargo xtask ARGS` with the environment variable `var` set to `value`, checks that it
/// failed, and returns its standard error.
fn refused_with(args: &[&str], (var, value): (&str, &str)) -> String {
    let out =
        Command::new(env!("CARGO_BIN_EXE_xtask")).args(args).env(var, value).output().unwrap();
    assert!(!out.status.success(), "{args:?} with {var}={value} succeeded");
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The environment's compute settings are read by the command line, once, before any work:
/// a bad value fails `run-one` and `reproduce-tables` at once, naming the variable and what it
/// takes, and writes nothing.
#[test]
fn a_bad_compute_setting_in_the_environment_is_refused_by_name() {
    let dir = test_support::TempDir::new("xtask-bad-setting");
    for (var, value, expected) in [
        ("NEURAL_BRDF_LOSS_READS", "0", "positive number"),
        ("CPU_KERNELS_AMX", "maybe", "0 or 1"),
        ("NEURAL_BRDF_GPU_TILE", "256", "128v"),
    ] {
        let out_dir = dir.0.join(var);
        for args in [
            vec!["reproduce-tables", "--profile", "smoke", "--out", out_dir.to_str().unwrap()],
            vec!["run-one", out_dir.to_str().unwrap()],
        ] {
            let text = refused_with(&args, (var, value));
            assert!(text.contains(var) && text.contains(expected), "{args:?}: {text}");
        }
        let written: Vec<_> = std::fs::read_dir(&out_dir)
            .map(|d| d.filter_map(|e| e.ok()).map(|e| e.file_name()).collect())
            .unwrap_or_default();
        assert!(written.iter().all(|n| n.to_string_lossy().starts_with('.')), "{var}: {written:?}");
    }
}

/// The importers' limits are settings of the same kind: a bad value stops `reproduce-tables`,
/// `import-capture` and `import-diligent` before they read or write anything, naming the
/// variable.
#[test]
fn a_bad_limit_in_the_environment_is_refused_by_name() {
    let dir = test_support::TempDir::new("xtask-bad-limit");
    let out_dir = dir.0.join("out");
    let (o, missing) = (out_dir.to_str().unwrap(), dir.0.join("nothing-here"));
    let m = missing.to_str().unwrap();
    for (var, value) in [("NEURAL_BRDF_MAX_IMAGE_PIXELS", "0"), ("NEURAL_BRDF_MAX_ALLOC_MIB", "x")]
    {
        for args in [
            vec!["reproduce-tables", "--profile", "smoke", "--out", o],
            vec!["import-capture", m, "--out", o],
            vec!["import-diligent", m, "--out", o],
        ] {
            let text = refused_with(&args, (var, value));
            let named = text.contains(var) && text.contains("positive whole number");
            assert!(named, "{args:?}: {text}");
        }
    }
    assert!(!out_dir.exists(), "something was written");
}
