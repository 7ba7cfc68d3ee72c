//! LaTeX rendering of a [`Table`]: a booktabs `table` with a multicolumn header per column
//! group, highlight macros, and LaTeX escaping of every label.
//!
//! Every rendered table starts with [`LATEX_PREAMBLE`], which defines the highlight macros with
//! `\providecommand`: the output compiles on its own (with booktabs), and a document that
//! defines `\first`, `\second`, `\third` or `\improved` before `\input`-ing it restyles them.
//! (siunitx v2 with free-standing units defines `\second` itself; define the macros first there.)

use super::rank::Mark;
use super::table::Table;

/// The highlight macros: best bold, second underlined, third italic, improvement bold.
pub const LATEX_PREAMBLE: &str = "\
% Requires \\usepackage{booktabs}. Highlight macros (define your own before \\input to restyle):
\\providecommand{\\first}[1]{\\textbf{#1}}
\\providecommand{\\second}[1]{\\underline{#1}}
\\providecommand{\\third}[1]{\\textit{#1}}
\\providecommand{\\improved}[1]{\\textbf{#1}}
";

/// The table as LaTeX (preamble, then a `table` float), ending with a newline.
pub fn to_latex(table: &Table) -> String {
    let columns = table.columns();
    let marks = table.marks();
    let mut out = String::from(LATEX_PREAMBLE);
    out.push_str("\\begin{table}[t]\n\\centering\n");
    let mut caption = table.caption.clone();
    let legend = table.legend(["bold", "underlined", "italic", "Bold"]);
    for extra in std::iter::once(&legend).chain(&table.notes) {
        if !extra.is_empty() {
            if !caption.is_empty() {
                caption.push(' ');
            }
            caption.push_str(extra);
        }
    }
    if !caption.is_empty() {
        out.push_str(&format!("\\caption{{{}}}\n", escape_caption(&caption)));
    }
    let mut spec = String::from("l");
    for g in table.groups.iter().filter(|g| !g.columns.is_empty()) {
        spec.push(' ');
        spec.push_str(&"r".repeat(g.columns.len()));
    }
    out.push_str(&format!("\\begin{{tabular}}{{{spec}}}\n\\toprule\n"));
    if table.groups.iter().any(|g| !g.title.is_empty() && !g.columns.is_empty()) {
        let mut cells = vec![String::new()];
        let mut rules = Vec::new();
        let mut first = 2;
        for g in table.groups.iter().filter(|g| !g.columns.is_empty()) {
            let n = g.columns.len();
            if g.title.is_empty() {
                cells.extend(std::iter::repeat_n(String::new(), n));
            } else {
                cells.push(format!("\\multicolumn{{{n}}}{{c}}{{{}}}", escape_latex(&g.title)));
                rules.push(format!("\\cmidrule(lr){{{first}-{}}}", first + n - 1));
            }
            first += n;
        }
        out.push_str(&row(&cells));
        out.push_str(&rules.join(" "));
        out.push('\n');
    }
    let mut header = vec![escape_latex(&table.stub_header)];
    header.extend(
        columns.iter().map(|c| escape_latex(&format!("{}{}", c.label, c.direction.arrow()))),
    );
    out.push_str(&row(&header));
    out.push_str("\\midrule\n");
    for (r, data) in table.rows.iter().enumerate() {
        let mut cells = vec![escape_latex(&data.label)];
        for c in 0..columns.len() {
            let text = number(&table.cell_text(r, c));
            let mark = marks.get(r).and_then(|m| m.get(c)).copied().unwrap_or(Mark::None);
            cells.push(match mark {
                Mark::None => text,
                Mark::First => format!("\\first{{{text}}}"),
                Mark::Second => format!("\\second{{{text}}}"),
                Mark::Third => format!("\\third{{{text}}}"),
                Mark::Improved => format!("\\improved{{{text}}}"),
            });
        }
        out.push_str(&row(&cells));
    }
    out.push_str("\\bottomrule\n\\end{tabular}\n\\end{table}\n");
    out
}

fn row(cells: &[String]) -> String {
    format!("{} \\\\\n", cells.join(" & "))
}

/// A printed cell in LaTeX: math signs, `--` for not run, the rest escaped.
fn number(text: &str) -> String {
    if let Some(rest) = text.strip_prefix('-')
        && rest.starts_with(|c: char| c.is_ascii_digit() || c == 'i')
    {
        return format!("\\ensuremath{{-}}{}", escape_latex(rest));
    }
    if let Some(rest) = text.strip_prefix('+') {
        return format!("\\ensuremath{{+}}{}", escape_latex(rest));
    }
    escape_latex(text)
}

/// Escapes text for LaTeX: the ten special characters, a few Unicode symbols the tables use
/// (arrows, the cube root, Δ, dashes, ×), and an abbreviation's period before a space
/// (`Add. Sep.` becomes `Add.\ Sep.`, so TeX does not set a sentence space).
pub fn escape_latex(s: &str) -> String {
    escape(s, true)
}

/// Escapes caption text: like [`escape_latex`] but sentence periods keep TeX's spacing.
fn escape_caption(s: &str) -> String {
    escape(s, false)
}

fn escape(s: &str, abbreviations: bool) -> String {
    let mut out = String::with_capacity(s.len() + 8);
    let mut chars = s.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '\\' => out.push_str("\\textbackslash{}"),
            '{' => out.push_str("\\{"),
            '}' => out.push_str("\\}"),
            '$' => out.push_str("\\$"),
            '&' => out.push_str("\\&"),
            '#' => out.push_str("\\#"),
            '%' => out.push_str("\\%"),
            '_' => out.push_str("\\_"),
            '^' => out.push_str("\\textasciicircum{}"),
            '~' => out.push_str("\\textasciitilde{}"),
            '<' => out.push_str("\\textless{}"),
            '>' => out.push_str("\\textgreater{}"),
            '↑' => out.push_str("\\ensuremath{\\uparrow}"),
            '↓' => out.push_str("\\ensuremath{\\downarrow}"),
            '∛' => out.push_str("\\ensuremath{^{\\sqrt[3]{}}}"),
            'Δ' => out.push_str("\\ensuremath{\\Delta}"),
            '†' => out.push_str("\\ensuremath{^\\dagger}"),
            '−' => out.push_str("\\ensuremath{-}"),
            '–' => out.push_str("--"),
            '×' => out.push_str("\\ensuremath{\\times}"),
            '.' if abbreviations && chars.peek() == Some(&' ') => {
                chars.next();
                out.push_str(".\\ ");
            }
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_names_and_specials() {
        assert_eq!(escape_latex("Add. Sep."), "Add.\\ Sep.");
        assert_eq!(escape_latex("Enh. Add. Shared"), "Enh.\\ Add.\\ Shared");
        assert_eq!(escape_latex("% E>1"), "\\% E\\textgreater{}1");
        assert_eq!(escape_latex("a_b & c#d $5 {x}"), "a\\_b \\& c\\#d \\$5 \\{x\\}");
        assert_eq!(escape_latex("\\~^"), "\\textbackslash{}\\textasciitilde{}\\textasciicircum{}");
        assert_eq!(
            escape_latex("RMSE∛↓"),
            "RMSE\\ensuremath{^{\\sqrt[3]{}}}\\ensuremath{\\downarrow}"
        );
        assert_eq!(escape_latex("ΔPSNR↑"), "\\ensuremath{\\Delta}PSNR\\ensuremath{\\uparrow}");
    }

    #[test]
    fn numbers_get_math_signs() {
        assert_eq!(number("-1.25"), "\\ensuremath{-}1.25");
        assert_eq!(number("+0.50"), "\\ensuremath{+}0.50");
        assert_eq!(number("–"), "--");
        assert_eq!(number("n/a"), "n/a");
        assert_eq!(number("-inf"), "\\ensuremath{-}inf");
    }
}

#[cfg(test)]
mod snapshot {
    use super::super::table::sample_table;
    use super::to_latex;

    #[test]
    fn small_table() {
        let expected = r"% Requires \usepackage{booktabs}. Highlight macros (define your own before \input to restyle):
\providecommand{\first}[1]{\textbf{#1}}
\providecommand{\second}[1]{\underline{#1}}
\providecommand{\third}[1]{\textit{#1}}
\providecommand{\improved}[1]{\textbf{#1}}
\begin{table}[t]
\centering
\caption{Table 1: image metrics. Data: MERL-derived (NBRDF), DiLiGenT-MV. Profile: quick. Per column: best bold, second underlined, third italic (ties share a mark); -- not run; n/a not computable (weights missing). Values \ensuremath{\times}100 except PSNR and \%.}
\begin{tabular}{l rrr r}
\toprule
 & \multicolumn{3}{c}{MERL-derived (NBRDF)} & \multicolumn{1}{c}{DiLiGenT-MV} \\
\cmidrule(lr){2-4} \cmidrule(lr){5-5}
Model & PSNR\ensuremath{\uparrow} & LPIPS\ensuremath{\downarrow} & RMSE\ensuremath{^{\sqrt[3]{}}}\ensuremath{\downarrow} & \% E\textgreater{}1\ensuremath{\downarrow} \\
\midrule
RP & \third{30.00} & n/a & \second{5.00} & \second{1.00} \\
Add.\ Sep. & \first{32.50} & n/a & \first{4.00} & -- \\
Enh.\ Add.\ Shared & \first{32.50} & n/a & \third{6.00} & \third{12.25} \\
Disney & 29.00 & n/a & 7.00 & \first{0.50} \\
\bottomrule
\end{tabular}
\end{table}
";
        assert_eq!(to_latex(&sample_table()), expected);
    }
}
