//! Result tables and figures from evaluated runs: pure functions from in-memory
//! [`RunRecord`]s to Markdown, LaTeX and PNG bytes (no file access; the experiments crate's
//! `collect` finds the runs and writes the outputs). The last stage of the data flow: it knows
//! the models' names and the metrics' aggregation, nothing about training or scenes.
//!
//! * [`record`]: [`RunRecord`] (model, options, data set, object, metrics) and its vocabulary.
//! * [`average`]: each run's last evaluation, averages per object then over objects, paired
//!   deltas.
//! * [`table`], [`rank`]: the table model and its highlighting (best / second / third,
//!   improvements); [`markdown`] and [`latex`] render it.
//! * [`result_tables`]: Table 1 in both protocols ([`Protocol`]: ours, with the noise ceiling, and
//!   the paper's), against the noise-free renders, reciprocity RMSE, energy conservation,
//!   per-object tables.
//! * [`paper`]: the paper's published Table 1 as data, ours beside it cell by cell under its
//!   protocol, the ranking agreement (Kendall's τ-b) and a checklist of its findings.
//! * [`runtime`]: run time against accuracy (seconds to each model's plateau).
//! * [`deltas`]: the ablations (NOL, reciprocity options, angle parametrization, NeRFactor
//!   changes) as differences to the baseline.
//! * [`brdf_plots`]: BRDF plots from probes of each model and the ground truth: lit spheres
//!   with FLIP maps, slices in the plane of incidence, directional albedo, validity maps.
//! * [`html`]: tables and self-contained pages as HTML (the report), with the link checks.
//! * [`plot`], [`grid`], [`figures`]: line plots (error against training time) and image
//!   grids (qualitative comparisons, FLIP maps, diffuse / specular / albedo splits), drawn with
//!   plotters into a [`raster`] with the embedded TTF [`font`] (DejaVu Sans).
//!
//! Conventions: cells print `–` for a combination that was not run and `n/a` for a metric
//! that could not be computed (its reason is listed under the table); every caption names the
//! data and the profile.

pub mod average;
pub mod brdf_plots;
pub mod deltas;
mod error;
pub mod figures;
pub mod font;
pub mod grid;
pub mod html;
pub mod latex;
pub mod markdown;
pub mod paper;
pub mod plot;
pub mod rank;
pub mod raster;
pub mod record;
pub mod result_tables;
pub mod runtime;
pub mod table;

pub use deltas::{
    Variant, nerfactor_deltas, nol_deltas, parametrization_deltas, reciprocity_deltas,
};
pub use error::{Error, Result};
pub use figures::{ModelRender, QualitativeRow, qualitative_grid, runtime_plot};
pub use grid::{GridCell, GridRow, ImageGrid, RgbImage, image_grid_png};
pub use latex::{LATEX_PREAMBLE, to_latex};
pub use markdown::to_markdown;
pub use plot::{LegendCorner, LinePlot, Series, line_plot_png};
pub use record::{Dataset, Direction, MetricKind, RunOptions, RunRecord};
pub use result_tables::{
    CEILING_LABEL, Protocol, energy_table, per_object_table, reciprocity_table, table1,
    table1_noise_free, table1_paper,
};
pub use runtime::time_to_accuracy;
pub use table::{Cell, Column, ColumnGroup, Marking, Row, Table};
