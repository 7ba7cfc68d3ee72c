//! The BRDF figures of `collect`: per object, the probes of its Table 1 runs
//! (`<run>/probe.bin`, written by eval) and of the scene's ground-truth material (evaluated
//! here from the scene's manifest; captured scenes have none), drawn by
//! `report::brdf_plots`:
//!
//! ```text
//! figures/spheres-<object>.png      lit spheres with HDR-FLIP against the ground truth
//! figures/slices-<object>.png       f_r cos(theta_i) in the plane of incidence (linear)
//! figures/slices-log-<object>.png   the same in log10
//! figures/albedo-<object>.png       directional albedo against the incident angle
//! figures/validity-<object>.png     albedo > 1 and reciprocity error on the object
//! ```
//!
//! Runs without a probe (evaluated without images, or by an older version) are left out of
//! the figures; an object none of whose runs has one gets none.

use super::plan::Purpose;
use crate::collected::{CollectSummary, CollectedRun};
use experiments::Result;
use experiments::eval::probe;
use report::RunOptions;
use report::brdf_plots::{self, BrdfProbe};
use run_format::run_dir::{RunDir, SweepLayout};
use std::path::Path;

/// The ground truth's probe of the scene at `scene` (`None` for captured scenes, or when the
/// scene or its material cannot be read).
fn ground_truth_probe(scene: &Path) -> Option<BrdfProbe> {
    let manifest = scene::Manifest::read(&scene.join(scene::MANIFEST_FILE)).ok()?;
    let (_, gt) = dataset_merl::generate::ground_truth(&manifest.config).ok()?;
    let f64s = |d: [f32; 3]| d.map(f64::from);
    let brdf = brdf_analytic::FnSurface(move |_: u32, l: [f32; 3], v: [f32; 3]| {
        gt(f64s(l), f64s(v)).unwrap_or([0.0; 3]).map(|x| x as f32)
    });
    Some(probe::probe(&brdf, 0, String::new(), None))
}

/// Writes the BRDF figures of every object.
pub fn brdf_figures(runs: &[CollectedRun], out: &Path, summary: &mut CollectSummary) -> Result<()> {
    let mut objects: Vec<&str> = runs.iter().map(|r| r.record.object.as_str()).collect();
    objects.sort();
    objects.dedup();
    let figures = SweepLayout::new(out).figures();
    for object in objects {
        let mut mine: Vec<&CollectedRun> = runs
            .iter()
            .filter(|r| {
                r.record.object == object
                    && r.record.options == RunOptions::DEFAULT
                    && r.purposes.contains(&Purpose::Table)
            })
            .collect();
        mine.sort_by_key(|r| r.record.model as usize);
        let probes: Vec<(String, BrdfProbe)> = mine
            .iter()
            .filter_map(|r| {
                let p = probe::read(&RunDir::new(&r.dir).probe()).ok()?;
                Some((r.record.model.paper_name().to_string(), p))
            })
            .collect();
        if probes.is_empty() {
            continue;
        }
        let gt = mine.first().and_then(|r| r.config.scene.as_deref()).and_then(ground_truth_probe);
        let mut write = |name: String, bytes: Vec<u8>| -> Result<()> {
            let path = figures.join(name);
            stdx::fs::write_atomic(&path, &bytes)?;
            summary.files.push(path);
            Ok(())
        };
        let at = &probes[0].1.point;
        let title = if at.is_empty() { object.to_string() } else { format!("{object} ({at})") };
        // Curves: the ground truth first.
        let all: Vec<(String, &BrdfProbe)> = gt
            .iter()
            .map(|g| ("ground truth".to_string(), g))
            .chain(probes.iter().map(|(n, p)| (n.clone(), p)))
            .collect();
        let spheres: Vec<(String, &brdf_plots::LitSphere)> =
            probes.iter().map(|(n, p)| (n.clone(), &p.sphere)).collect();
        let grid = brdf_plots::lit_sphere_grid(
            &format!("{title}: lit spheres, light 45 deg from the view"),
            gt.as_ref().map(|g| &g.sphere),
            &spheres,
        )?;
        write(format!("spheres-{object}.png"), report::image_grid_png(&grid)?)?;
        let slices: Vec<(String, &[brdf_plots::PolarSlice])> =
            all.iter().map(|(n, p)| (n.clone(), p.slices.as_slice())).collect();
        for (log, name) in [(false, "slices"), (true, "slices-log")] {
            let png = brdf_plots::polar_slices_png(&title, &slices, log)?;
            write(format!("{name}-{object}.png"), png)?;
        }
        let albedo: Vec<(String, &[brdf_plots::AlbedoPoint])> =
            all.iter().map(|(n, p)| (n.clone(), p.albedo.as_slice())).collect();
        write(format!("albedo-{object}.png"), brdf_plots::albedo_plot_png(object, &albedo)?)?;
        let maps: Vec<(String, &brdf_plots::ValidityMaps)> = probes
            .iter()
            .filter_map(|(n, p)| p.validity.as_ref().map(|m| (n.clone(), m)))
            .collect();
        if !maps.is_empty() {
            let grid = brdf_plots::validity_grid(object, &maps)?;
            write(format!("validity-{object}.png"), report::image_grid_png(&grid)?)?;
        }
    }
    Ok(())
}
