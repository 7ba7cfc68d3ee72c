//! The table model every result table is built into and rendered from: rows, column groups,
//! cells holding raw [`Score`]s, each column with its direction, scale and decimals.
//!
//! Cells print as the scaled value with the column's decimals, `n/a` for a metric that could
//! not be computed (the reasons are listed below the table), and `–` for a combination that
//! was not run. A mean over fewer objects than the table's other rows prints with a `†`, is
//! never marked, and the legend names the objects it lacks. Which cells are highlighted
//! follows [`Marking`] (see [`super::rank`]).

use super::rank::{Mark, improvements, rank};
use super::record::{Direction, MetricKind};
use metrics::aggregate::Score;

/// One cell.
#[derive(Clone, Debug, PartialEq)]
pub enum Cell {
    /// A raw (unscaled) value, or the reason it could not be computed (`n/a`).
    Score(Score),
    /// The combination was not run (printed `–`).
    NotRun,
    /// A mean over fewer objects than the table's other rows (printed with `†`, never
    /// marked): its score and the objects it lacks.
    Partial(Score, Vec<String>),
}

/// The mark of a [`Cell::Partial`].
pub const PARTIAL_MARK: &str = "†";

impl Cell {
    /// A cell holding the value `v`.
    pub fn value(v: f64) -> Cell {
        Cell::Score(Score::Value(v))
    }
}

/// A column: what it shows and how it prints.
#[derive(Clone, Debug, PartialEq)]
pub struct Column {
    /// Header text (plain text; the direction arrow is appended by the renderers).
    pub label: String,
    /// Which values are better.
    pub direction: Direction,
    /// Factor applied to raw values before printing (the tables' scaling convention).
    pub factor: f64,
    /// Decimals printed.
    pub decimals: usize,
    /// Print an explicit `+` on positive values (delta columns).
    pub signed: bool,
    /// A reference (the noise ceiling), never ranked against the others.
    pub reference: bool,
}

impl Column {
    /// The column of `metric`: its label, direction, table scale and decimals.
    pub fn metric(metric: MetricKind) -> Column {
        Column {
            label: metric.label().to_string(),
            direction: metric.direction(),
            factor: metric.factor(),
            decimals: metric.decimals(),
            signed: false,
            reference: false,
        }
    }

    /// The same column with lower values better.
    pub fn with_direction_lower(mut self) -> Column {
        self.direction = Direction::LowerIsBetter;
        self
    }

    /// The same column marked as a reference (never ranked).
    pub fn as_reference(mut self) -> Column {
        self.reference = true;
        self
    }

    /// The column of a difference of `metric` ("ΔPSNR"), signed.
    pub fn delta(metric: MetricKind) -> Column {
        Column { label: format!("Δ{}", metric.label()), signed: true, ..Column::metric(metric) }
    }

    /// The same column with another label.
    pub fn labelled(mut self, label: impl Into<String>) -> Column {
        self.label = label.into();
        self
    }

    /// The printed number of a raw value `v` (scaled, rounded; `-0.00` prints as `0.00`).
    pub fn format(&self, v: f64) -> String {
        let x = v * self.factor;
        if x.is_nan() {
            return "NaN".into();
        }
        if x.is_infinite() {
            return if x > 0.0 { "inf".into() } else { "-inf".into() };
        }
        let mut s = format!("{:.*}", self.decimals, x);
        if s.starts_with('-') && s[1..].chars().all(|c| c == '0' || c == '.') {
            s.remove(0);
        }
        if self.signed && !s.starts_with('-') && s.chars().any(|c| c.is_ascii_digit() && c != '0') {
            s.insert(0, '+');
        }
        s
    }

    /// The printed value parsed back (what ranking compares), `None` if not a finite number.
    fn printed(&self, cell: &Cell) -> Option<f64> {
        match cell {
            Cell::Score(Score::Value(v)) => {
                self.format(*v).parse::<f64>().ok().filter(|p| p.is_finite())
            }
            _ => None,
        }
    }
}

/// Columns under a common header (a data set, or a variant and a data set).
#[derive(Clone, Debug, PartialEq)]
pub struct ColumnGroup {
    /// The group header; empty for none.
    pub title: String,
    /// Its columns.
    pub columns: Vec<Column>,
}

/// One row: its label and one cell per column (all groups, in order).
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// The row label (a model, an object).
    pub label: String,
    /// The cells; missing trailing cells print as not run.
    pub cells: Vec<Cell>,
    /// A reference row (the noise ceiling), never ranked against the others.
    pub reference: bool,
}

impl Row {
    /// A row of results.
    pub fn new(label: impl Into<String>, cells: Vec<Cell>) -> Row {
        Row { label: label.into(), cells, reference: false }
    }

    /// A reference row (never ranked).
    pub fn reference(label: impl Into<String>, cells: Vec<Cell>) -> Row {
        Row { label: label.into(), cells, reference: true }
    }
}

/// Which cells a table highlights.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Marking {
    /// Best / second / third per column.
    RankColumns,
    /// Best / second / third per row (per-object tables: the best model of each object).
    RankRows,
    /// Improvements over the baseline (delta tables); no ranking, since a delta's size
    /// matters less than whether the variant helps.
    Improvement,
    /// Nothing.
    None,
}

/// A result table.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    /// Caption; states the data ("MERL-derived (NBRDF)") and the profile.
    pub caption: String,
    /// Header of the row-label column ("Model", "Object").
    pub stub_header: String,
    /// Column groups, left to right.
    pub groups: Vec<ColumnGroup>,
    /// Rows, top to bottom.
    pub rows: Vec<Row>,
    /// What is highlighted.
    pub marking: Marking,
    /// Extra lines printed after the table (sign conventions, remarks).
    pub notes: Vec<String>,
}

impl Table {
    /// All columns, left to right.
    pub fn columns(&self) -> Vec<&Column> {
        self.groups.iter().flat_map(|g| g.columns.iter()).collect()
    }

    /// The cell at (row, column); not run where the row is short.
    pub fn cell(&self, row: usize, column: usize) -> &Cell {
        self.rows.get(row).and_then(|r| r.cells.get(column)).unwrap_or(&Cell::NotRun)
    }

    /// The printed text of a cell (without highlighting).
    pub fn cell_text(&self, row: usize, column: usize) -> String {
        let Some(col) = self.columns().get(column).copied() else { return "–".into() };
        match self.cell(row, column) {
            Cell::NotRun => "–".into(),
            Cell::Score(Score::Unavailable(_)) => "n/a".into(),
            Cell::Score(Score::Value(v)) => col.format(*v),
            Cell::Partial(Score::Value(v), _) => format!("{}{PARTIAL_MARK}", col.format(*v)),
            Cell::Partial(Score::Unavailable(_), _) => format!("n/a{PARTIAL_MARK}"),
        }
    }

    /// The partial cells' lines for the legend: "<row> <column> (without a, b)", grouped by
    /// row and missing objects.
    fn partial_notes(&self) -> Vec<String> {
        let columns = self.columns();
        let mut notes: Vec<(String, Vec<String>, Vec<String>)> = Vec::new();
        for row in &self.rows {
            for (c, cell) in row.cells.iter().enumerate() {
                let Cell::Partial(_, missing) = cell else { continue };
                let column = columns.get(c).map_or(String::new(), |c| c.label.clone());
                match notes.iter_mut().find(|(r, m, _)| *r == row.label && m == missing) {
                    Some((_, _, cols)) => {
                        if !cols.contains(&column) {
                            cols.push(column)
                        }
                    }
                    None => notes.push((row.label.clone(), missing.clone(), vec![column])),
                }
            }
        }
        notes
            .into_iter()
            .map(|(row, missing, _)| format!("{row} without {}", missing.join(", ")))
            .collect()
    }

    /// The mark of every cell, `[row][column]`.
    pub fn marks(&self) -> Vec<Vec<Mark>> {
        let columns = self.columns();
        let (nr, nc) = (self.rows.len(), columns.len());
        let mut marks = vec![vec![Mark::None; nc]; nr];
        // References (the noise ceiling) are shown but never ranked.
        let printed = |r: usize, c: usize| {
            let reference = columns[c].reference || self.rows[r].reference;
            if reference { None } else { columns[c].printed(self.cell(r, c)) }
        };
        match self.marking {
            Marking::None => {}
            Marking::RankColumns | Marking::Improvement => {
                for (c, col) in columns.iter().enumerate() {
                    let values: Vec<Option<f64>> = (0..nr).map(|r| printed(r, c)).collect();
                    let m = if self.marking == Marking::Improvement {
                        improvements(&values, col.direction)
                    } else {
                        rank(&values, col.direction)
                    };
                    for (r, mark) in m.into_iter().enumerate() {
                        marks[r][c] = mark;
                    }
                }
            }
            Marking::RankRows => {
                // Rows compare columns that share a direction (one metric); the first column's
                // direction decides.
                let direction = columns.first().map_or(Direction::Neutral, |c| c.direction);
                for (r, row_marks) in marks.iter_mut().enumerate() {
                    let values: Vec<Option<f64>> = (0..nc).map(|c| printed(r, c)).collect();
                    *row_marks = rank(&values, direction);
                }
            }
        }
        marks
    }

    /// The distinct reasons of the table's `n/a` cells, in order of appearance.
    pub fn unavailable_reasons(&self) -> Vec<String> {
        let mut reasons: Vec<String> = Vec::new();
        for row in &self.rows {
            for cell in &row.cells {
                if let Cell::Score(Score::Unavailable(why))
                | Cell::Partial(Score::Unavailable(why), _) = cell
                    && !reasons.contains(why)
                {
                    reasons.push(why.clone());
                }
            }
        }
        reasons
    }

    /// Whether any cell is not run.
    pub fn has_not_run(&self) -> bool {
        let nc = self.columns().len();
        (0..self.rows.len()).any(|r| (0..nc).any(|c| *self.cell(r, c) == Cell::NotRun))
    }

    /// The legend line: what the highlighting, `–` and `n/a` mean. `styles` names the
    /// renderer's styles for best, second, third and improved.
    pub(crate) fn legend(&self, styles: [&str; 4]) -> String {
        if self.columns().is_empty() {
            return String::new();
        }
        let mut parts = Vec::new();
        match self.marking {
            Marking::RankColumns | Marking::RankRows => {
                let per = if self.marking == Marking::RankRows { "row" } else { "column" };
                parts.push(format!(
                    "Per {per}: best {}, second {}, third {} (ties share a mark)",
                    styles[0], styles[1], styles[2]
                ));
            }
            Marking::Improvement => {
                parts.push(format!("{}: the variant improves on the baseline", styles[3]))
            }
            Marking::None => {}
        }
        if self.has_not_run() {
            parts.push("– not run".into());
        }
        let partial = self.partial_notes();
        if !partial.is_empty() {
            parts.push(format!(
                "{PARTIAL_MARK} a mean over fewer objects than the other rows, left out of the \
                 marks ({})",
                partial.join("; ")
            ));
        }
        let reasons = self.unavailable_reasons();
        if !reasons.is_empty() {
            parts.push(format!("n/a not computable ({})", reasons.join("; ")));
        }
        if parts.is_empty() { String::new() } else { format!("{}.", parts.join("; ")) }
    }
}

/// A small table for the renderers' snapshot tests: two data sets, a tie, an n/a, a not-run
/// cell, and names that need escaping.
#[cfg(test)]
pub(crate) fn sample_table() -> Table {
    let unavailable = || Cell::Score(Score::Unavailable("weights missing".into()));
    Table {
        caption: "Table 1: image metrics. Data: MERL-derived (NBRDF), DiLiGenT-MV. Profile: quick."
            .into(),
        stub_header: "Model".into(),
        groups: vec![
            ColumnGroup {
                title: "MERL-derived (NBRDF)".into(),
                columns: vec![
                    Column::metric(MetricKind::Psnr),
                    Column::metric(MetricKind::Lpips),
                    Column::metric(MetricKind::CubeRootRmse),
                ],
            },
            ColumnGroup {
                title: "DiLiGenT-MV".into(),
                columns: vec![Column::metric(MetricKind::EnergyPercentAbove1)],
            },
        ],
        rows: vec![
            Row::new(
                "RP",
                vec![Cell::value(30.0), unavailable(), Cell::value(0.05), Cell::value(1.0)],
            ),
            Row::new(
                "Add. Sep.",
                vec![Cell::value(32.5), unavailable(), Cell::value(0.04), Cell::NotRun],
            ),
            Row::new(
                "Enh. Add. Shared",
                vec![Cell::value(32.5), unavailable(), Cell::value(0.06), Cell::value(12.25)],
            ),
            Row::new(
                "Disney",
                vec![Cell::value(29.0), unavailable(), Cell::value(0.07), Cell::value(0.5)],
            ),
        ],
        marking: Marking::RankColumns,
        notes: vec!["Values ×100 except PSNR and %.".into()],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_scaled_and_signed_values() {
        let c = Column::metric(MetricKind::Flip);
        assert_eq!(c.format(0.12345), "12.35");
        assert_eq!(c.format(-0.00001), "0.00");
        assert_eq!(c.format(f64::NAN), "NaN");
        let d = Column::delta(MetricKind::Psnr);
        assert_eq!(d.label, "ΔPSNR");
        assert_eq!(d.format(1.234), "+1.23");
        assert_eq!(d.format(-1.234), "-1.23");
        assert_eq!(d.format(0.0001), "0.00");
        assert_eq!(Column::metric(MetricKind::ReciprocityRmse).format(0.012345), "0.0123");
    }

    fn table(marking: Marking, cells: Vec<Vec<Cell>>) -> Table {
        Table {
            caption: String::new(),
            stub_header: "Model".into(),
            groups: vec![ColumnGroup {
                title: String::new(),
                columns: vec![Column::metric(MetricKind::Psnr), Column::metric(MetricKind::Dssim)],
            }],
            rows: cells
                .into_iter()
                .enumerate()
                .map(|(i, cells)| Row::new(format!("m{i}"), cells))
                .collect(),
            marking,
            notes: vec![],
        }
    }

    #[test]
    fn marks_rank_printed_values() {
        // 0.10004 and 0.10001 both print 10.00 and tie.
        let t = table(
            Marking::RankColumns,
            vec![
                vec![Cell::value(30.0), Cell::value(0.10004)],
                vec![Cell::value(31.0), Cell::value(0.10001)],
                vec![Cell::Score(Score::Unavailable("x".into())), Cell::value(0.2)],
                vec![Cell::NotRun],
            ],
        );
        let m = t.marks();
        assert_eq!(m[0], vec![Mark::Second, Mark::First]);
        assert_eq!(m[1], vec![Mark::First, Mark::First]);
        assert_eq!(m[2], vec![Mark::None, Mark::Third]);
        assert_eq!(m[3], vec![Mark::None, Mark::None]);
        assert_eq!(t.cell_text(3, 1), "–");
        assert_eq!(t.cell_text(2, 0), "n/a");
        assert_eq!(t.unavailable_reasons(), vec!["x".to_string()]);
    }

    #[test]
    fn partial_means_print_a_dagger_and_are_never_marked() {
        let t = table(
            Marking::RankColumns,
            vec![
                vec![Cell::value(30.0), Cell::value(0.1)],
                vec![Cell::Partial(Score::Value(41.0), vec!["steel".into()]), Cell::value(0.2)],
                vec![Cell::value(29.0), Cell::value(0.3)],
            ],
        );
        assert_eq!(t.cell_text(1, 0), "41.00†");
        let m = t.marks();
        // The partial mean is the highest but takes no mark: 30 is best, 29 second.
        assert_eq!((m[0][0], m[1][0], m[2][0]), (Mark::First, Mark::None, Mark::Second));
        let legend = t.legend(["b", "u", "i", "B"]);
        assert!(
            legend.contains("† a mean over fewer objects") && legend.contains("m1 without steel")
        );
    }

    #[test]
    fn marks_rows_and_improvements() {
        let cells = vec![vec![Cell::value(30.0), Cell::value(0.1)]];
        let t = table(Marking::RankRows, cells.clone());
        // Rows use the first column's direction (higher is better): 30 > 0.1.
        assert_eq!(t.marks()[0], vec![Mark::First, Mark::Second]);
        let t = table(Marking::Improvement, vec![vec![Cell::value(0.5), Cell::value(0.01)]]);
        assert_eq!(t.marks()[0], vec![Mark::Improved, Mark::None]);
        let t = table(Marking::None, cells);
        assert_eq!(t.marks()[0], vec![Mark::None, Mark::None]);
    }
}
