//! The `experiments` binary: help texts, and errors that name the bad key or the missing input.

use std::process::Command;

fn run(args: &[&str]) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_experiments")).args(args).output().unwrap();
    let text =
        String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    (out.status.success(), text)
}

#[test]
fn help_lists_the_commands() {
    let (ok, text) = run(&["--help"]);
    assert!(ok && text.contains("fit") && text.contains("eval"), "{text}");
    let (ok, text) = run(&["fit", "--help"]);
    assert!(ok && text.contains("--config") && text.contains("--scene"), "{text}");
}

#[test]
fn a_bad_key_is_named() {
    let tmp = test_support::TempDir::new("cli");
    let dir = tmp.0.clone();
    let config = dir.join("bad.toml");
    std::fs::write(&config, "[train]\niteratons = 5\n").unwrap();
    let out = dir.join("run");
    let (ok, text) =
        run(&["fit", "--config", config.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert!(!ok && text.contains("iteratons") && text.contains("bad.toml"), "{text}");
    let (ok, text) = run(&["fit", "--out", out.to_str().unwrap()]);
    assert!(!ok && text.contains("--config"), "{text}");
}
