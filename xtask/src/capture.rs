//! `cargo xtask import-capture` and `export-capture`: users' own captures (posed images, mesh,
//! calibrated directional or point lights; docs/capture-format.md) to and from scene
//! directories (the `dataset-capture` crate).

use anyhow::{Context, Result};
use std::path::Path;
use std::time::Instant;

/// Imports the capture in `capture` as the scene `out`; prints the alignment check per view and
/// writes it beside the scene (`<out>.import-report.json`).
pub fn import(capture: &Path, out: &Path, progress: bool) -> Result<()> {
    let start = Instant::now();
    let limits = experiments::cli::process_limits()?;
    let report = dataset_capture::import_capture(capture, out, progress, &limits)
        .with_context(|| format!("importing the capture {}", capture.display()))?;
    println!("| view | split | images | mask px | silhouette px | IoU |");
    println!("| ---: | --- | ---: | ---: | ---: | ---: |");
    for (i, v) in report.views.iter().enumerate() {
        let iou = v.iou.map_or("no mask".to_string(), |x| format!("{x:.4}"));
        println!(
            "| {i} | {:?} | {} | {} | {} | {iou} |",
            v.split,
            v.images.len(),
            v.mask_pixels,
            v.mesh_pixels
        );
    }
    if report.views.iter().all(|v| v.iou.is_none()) {
        eprintln!("warning: no masks: the mesh's alignment with the cameras was not checked");
    }
    let report_path = dataset_capture::report_path(out);
    stdx::fs::write_atomic(&report_path, dataset_capture::report_json(&report).as_bytes())
        .with_context(|| format!("writing {}", report_path.display()))?;
    let s = &report.manifest.stats;
    eprintln!(
        "{}: {} views, {} lit / {} shadowed / {} saturated samples, in {:.1} s; report {}",
        out.display(),
        report.manifest.views.len(),
        s.lit_samples,
        s.shadowed_samples,
        s.saturated_samples,
        start.elapsed().as_secs_f64(),
        report_path.display()
    );
    Ok(())
}

/// Writes the scene `scene` as a capture in `out`.
pub fn export(scene: &Path, out: &Path) -> Result<()> {
    dataset_capture::export_capture(scene, out)
        .with_context(|| format!("exporting {} as a capture", scene.display()))?;
    eprintln!("{}: capture written (import it with `cargo xtask import-capture`)", out.display());
    Ok(())
}
