//! Markdown rendering of a [`Table`] (GitHub-flavoured pipe table).
//!
//! The caption comes first in bold, then the table, then the legend and the notes. Best values
//! are **bold**, second <u>underlined</u> (HTML, which GitHub renders), third *italic*;
//! improvements of delta tables are **bold**. Markdown has a single header row, so with more
//! than one column group each header reads "group: metric↑".

use super::rank::Mark;
use super::table::Table;

/// The table as Markdown, ending with a newline.
pub fn to_markdown(table: &Table) -> String {
    let columns = table.columns();
    let marks = table.marks();
    let prefix_groups = table.groups.len() > 1;
    let mut out = String::new();
    if !table.caption.is_empty() {
        out.push_str(&format!("**{}**\n\n", escape(&table.caption)));
    }
    let mut header = vec![escape(&table.stub_header)];
    for g in &table.groups {
        for c in &g.columns {
            let label = format!("{}{}", c.label, c.direction.arrow());
            header.push(if prefix_groups && !g.title.is_empty() {
                escape(&format!("{}: {label}", g.title))
            } else {
                escape(&label)
            });
        }
    }
    out.push_str(&line(&header));
    let mut rule = vec![":--".to_string()];
    rule.extend(columns.iter().map(|_| "--:".to_string()));
    out.push_str(&line(&rule));
    for (r, row) in table.rows.iter().enumerate() {
        let mut cells = vec![escape(&row.label)];
        for c in 0..columns.len() {
            let text = table.cell_text(r, c);
            let mark = marks.get(r).and_then(|m| m.get(c)).copied().unwrap_or(Mark::None);
            cells.push(style(&text, mark));
        }
        out.push_str(&line(&cells));
    }
    let legend = table.legend(["**bold**", "<u>underlined</u>", "*italic*", "**Bold**"]);
    if !legend.is_empty() || !table.notes.is_empty() {
        out.push('\n');
    }
    if !legend.is_empty() {
        out.push_str(&escape(&legend));
        out.push('\n');
    }
    for note in &table.notes {
        out.push_str(&escape(note));
        out.push('\n');
    }
    out
}

fn line(cells: &[String]) -> String {
    format!("| {} |\n", cells.join(" | "))
}

fn style(text: &str, mark: Mark) -> String {
    match mark {
        Mark::None => text.to_string(),
        Mark::First | Mark::Improved => format!("**{text}**"),
        Mark::Second => format!("<u>{text}</u>"),
        Mark::Third => format!("*{text}*"),
    }
}

/// Escapes the pipe, which would split a cell.
fn escape(s: &str) -> String {
    s.replace('|', "\\|")
}

#[cfg(test)]
mod tests {
    use super::super::record::MetricKind;
    use super::super::table::{Cell, Column, ColumnGroup, Marking, Row};
    use super::*;
    use metrics::aggregate::Score;

    #[test]
    fn pipes_are_escaped() {
        assert_eq!(escape("a|b"), "a\\|b");
        assert_eq!(style("1.00", Mark::Second), "<u>1.00</u>");
    }

    #[test]
    fn empty_table_renders() {
        let t = Table {
            caption: String::new(),
            stub_header: "Model".into(),
            groups: vec![],
            rows: vec![Row { label: "RP".into(), cells: vec![], reference: false }],
            marking: Marking::RankColumns,
            notes: vec![],
        };
        assert_eq!(to_markdown(&t), "| Model |\n| :-- |\n| RP |\n");
    }

    #[test]
    fn groups_prefix_headers() {
        let col = || Column::metric(MetricKind::Psnr);
        let t = Table {
            caption: "c".into(),
            stub_header: "Model".into(),
            groups: vec![
                ColumnGroup { title: "A".into(), columns: vec![col()] },
                ColumnGroup { title: "B".into(), columns: vec![col()] },
            ],
            rows: vec![Row {
                label: "x".into(),
                cells: vec![Cell::value(1.0), Cell::Score(Score::Unavailable("why".into()))],
                reference: false,
            }],
            marking: Marking::RankColumns,
            notes: vec!["note".into()],
        };
        let md = to_markdown(&t);
        assert!(md.contains("| Model | A: PSNR↑ | B: PSNR↑ |"), "{md}");
        assert!(md.contains("| x | 1.00 | n/a |"), "{md}");
        assert!(md.ends_with("n/a not computable (why).\nnote\n"), "{md}");
    }
}

#[cfg(test)]
mod snapshot {
    use super::super::table::sample_table;
    use super::to_markdown;

    #[test]
    fn small_table() {
        let expected = "\
**Table 1: image metrics. Data: MERL-derived (NBRDF), DiLiGenT-MV. Profile: quick.**

| Model | MERL-derived (NBRDF): PSNR↑ | MERL-derived (NBRDF): LPIPS↓ | MERL-derived (NBRDF): RMSE∛↓ | DiLiGenT-MV: % E>1↓ |
| :-- | --: | --: | --: | --: |
| RP | *30.00* | n/a | <u>5.00</u> | <u>1.00</u> |
| Add. Sep. | **32.50** | n/a | **4.00** | – |
| Enh. Add. Shared | **32.50** | n/a | *6.00* | *12.25* |
| Disney | 29.00 | n/a | 7.00 | **0.50** |

Per column: best **bold**, second <u>underlined</u>, third *italic* (ties share a mark); – not run; n/a not computable (weights missing).
Values ×100 except PSNR and %.
";
        assert_eq!(to_markdown(&sample_table()), expected);
    }
}
