//! The stages of a run import one way (the crate's documentation and docs/ARCHITECTURE.md say
//! so): `eval` imports neither `train` nor `export`, `train` imports neither `eval` nor
//! `export`. What they share sits below them (`data`, `fitted`, `portable`, brdf-neural's
//! `fitted`). Read from the sources, so that a new `use` that reaches across fails here.

use std::path::{Path, PathBuf};

/// The Rust files of a stage: a module file, or a folder of them.
fn stage_files(src: &Path, stage: &str) -> Vec<PathBuf> {
    let file = src.join(format!("{stage}.rs"));
    if file.is_file() {
        return vec![file];
    }
    let dir = src.join(stage);
    let mut out: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "rs"))
        .collect();
    out.sort();
    out
}

/// The lines of `files` (comments left out) that name one of `modules` as a path of this
/// crate (`crate::m::` or `crate::m;`, `use crate::{m, ...}` included).
fn reaches(files: &[PathBuf], modules: &[&str]) -> Vec<String> {
    let mut found = Vec::new();
    for file in files {
        let text = std::fs::read_to_string(file).unwrap();
        for (i, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            for m in modules {
                let named =
                    [format!("crate::{m}::"), format!("crate::{m};"), format!("crate::{m},")]
                        .iter()
                        .any(|p| code.contains(p.as_str()))
                        || (code.contains("crate::{") && code.contains(&format!(" {m},")));
                if named {
                    found.push(format!("{}:{}: {}", file.display(), i + 1, line.trim()));
                }
            }
        }
    }
    found
}

#[test]
fn eval_imports_neither_train_nor_export_and_train_neither_eval_nor_export() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let eval = reaches(&stage_files(&src, "eval"), &["train", "train_loop", "export"]);
    assert!(eval.is_empty(), "eval reaches into another stage:\n{}", eval.join("\n"));
    let mut train = stage_files(&src, "train");
    train.extend(stage_files(&src, "train_loop"));
    let train = reaches(&train, &["eval", "export"]);
    assert!(train.is_empty(), "train reaches into another stage:\n{}", train.join("\n"));
}

#[test]
fn the_check_sees_a_reaching_import() {
    let dir = std::env::temp_dir().join(format!("stages-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("probe.rs");
    std::fs::write(
        &file,
        "// crate::export:: in a comment is fine\nuse crate::train_loop::Loop;\n",
    )
    .unwrap();
    let found = reaches(std::slice::from_ref(&file), &["train_loop", "export"]);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(found[0].ends_with("use crate::train_loop::Loop;"));
    std::fs::remove_dir_all(&dir).unwrap();
}
