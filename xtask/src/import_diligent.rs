//! `cargo xtask import-diligent`: a DiLiGenT capture as a scene directory (see the
//! `dataset-diligent` crate): the single-view layout (`pmsData/<obj>PNG`, the ball) or a
//! DiLiGenT-MV object (`mvpmsData/<obj>PNG`), chosen by what the directory holds.

use anyhow::{Context, Result};
use dataset_diligent::{
    MultiViewOptions, SingleViewOptions, import_multi_view, import_single_view,
};
use std::path::Path;

/// Imports `src` into `out`.
pub fn run(
    src: &Path,
    out: &Path,
    train_lights: usize,
    test_lights: usize,
    target_vertices: usize,
) -> Result<()> {
    let limits = experiments::cli::process_limits()?;
    let multi_view = src.join("view_01").is_dir();
    let report = if multi_view {
        let o = MultiViewOptions {
            train_lights,
            test_lights,
            target_vertices: Some(target_vertices),
            progress: true,
            limits,
            ..Default::default()
        };
        import_multi_view(src, out, &o)
    } else {
        let o = SingleViewOptions {
            train_lights,
            test_lights,
            progress: true,
            limits,
            ..Default::default()
        };
        import_single_view(src, out, &o)
    }
    .with_context(|| format!("importing {}", src.display()))?;
    eprintln!(
        "{}: {} ({} vertices, {} triangles), {:.1} MB in {:.1} s, {} lit samples",
        report.label,
        report.dir.display(),
        report.mesh_vertices,
        report.mesh_triangles,
        report.bytes as f64 / 1e6,
        report.seconds,
        report.stats.lit_samples
    );
    if let Some(n) = &report.normal_check {
        eprintln!("mesh normals against the ground-truth normal map: {n:?}");
    }
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    Ok(())
}
