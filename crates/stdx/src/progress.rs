//! The progress bars of every long step, in one style: `label [bar] pos/len unit [elapsed, eta]
//! message`. A bar is hidden when the caller says so (quiet runs, tests) and, by indicatif, when
//! stderr is not a terminal, so logs see only the callers' summary lines.

use indicatif::{ProgressBar, ProgressStyle};

/// The template of a bar counting `unit` (a plain word such as "images" or "steps").
fn template(unit: &str) -> String {
    format!(
        "{{prefix}} [{{bar:30}}] {{pos}}/{{len}} {unit} [{{elapsed_precise}}, eta {{eta}}] {{msg}}"
    )
}

/// The style of a bar counting `unit`.
pub fn style(unit: &str) -> ProgressStyle {
    ProgressStyle::with_template(&template(unit))
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> ")
}

/// A bar of `len` `unit`s labelled `label`; hidden unless `visible`.
pub fn bar(len: u64, unit: &str, label: &str, visible: bool) -> ProgressBar {
    if !visible {
        return ProgressBar::hidden();
    }
    ProgressBar::new(len).with_style(style(unit)).with_prefix(label.to_string())
}

/// A spinner for a step of unknown length, showing `message`; hidden unless `visible`.
pub fn spinner(message: &str, visible: bool) -> ProgressBar {
    if !visible {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new_spinner().with_message(message.to_string());
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    bar
}

/// The byte-counting templates: with a known total, without one.
const BYTES_WITH_TOTAL: &str =
    "{msg:24!} [{bar:30}] {bytes}/{total_bytes} {bytes_per_sec} eta {eta}";
const BYTES_WITHOUT_TOTAL: &str = "{msg:24!} {spinner} {bytes} {bytes_per_sec}";

/// A byte-counting bar labelled `label` (downloads, unpacking, hashing); `total` may be unknown.
/// Indicatif hides it when stderr is not a terminal.
pub fn bytes(label: &str, total: Option<u64>) -> ProgressBar {
    let (bar, template) = match total {
        Some(t) => (ProgressBar::new(t), BYTES_WITH_TOTAL),
        None => (ProgressBar::no_length(), BYTES_WITHOUT_TOTAL),
    };
    if let Ok(style) = ProgressStyle::with_template(template) {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.with_message(label.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_template_parses() {
        for unit in ["images", "steps at most", "views", "pairs", "bins", "runs", "test images"] {
            assert!(ProgressStyle::with_template(&template(unit)).is_ok(), "{unit}");
        }
        for t in [BYTES_WITH_TOTAL, BYTES_WITHOUT_TOTAL] {
            assert!(ProgressStyle::with_template(t).is_ok(), "{t}");
        }
    }

    #[test]
    fn hidden_bars_stay_hidden() {
        assert!(bar(10, "steps", "train", false).is_hidden());
        assert!(spinner("reading", false).is_hidden());
    }
}
