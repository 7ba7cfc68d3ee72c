//! Prints the number of trainable parameters of every model (default configuration, with the
//! reciprocity mapping, and the NOL ablation), as a Markdown table.
//!
//! `cargo run -p model-spec --example param_counts`

use model_spec::{ModelConfig, ModelKind, Reciprocity};

fn main() {
    println!("| model | default | mapping | NOL |\n| --- | ---: | ---: | ---: |");
    for kind in ModelKind::ALL {
        let base = ModelConfig::new(kind);
        let cell = |c: &ModelConfig| {
            if c.validate().is_ok() { c.param_count().to_string() } else { String::new() }
        };
        let mut mapping = base.clone();
        mapping.angles.reciprocity = Reciprocity::Mapping;
        let mut nol = base.clone();
        nol.nol = true;
        let neural = kind.analytic().is_none();
        println!(
            "| {} | {} | {} | {} |",
            kind.paper_name(),
            cell(&base),
            if neural { cell(&mapping) } else { String::new() },
            cell(&nol)
        );
    }
}
