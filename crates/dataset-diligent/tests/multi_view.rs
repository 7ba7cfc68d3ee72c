//! DiLiGenT-MV import on a miniature written in the exact layout (16-bit PNGs, text files, a
//! compressed MAT v5 calibration, a PLY mesh): the scene opens with dataset-merl's
//! `SceneDataset`, cameras, world lights and radiance are consistent (a Lambertian sphere's
//! samples equal albedo x n . l), the split is the paper's shape, saturation is flagged, and
//! the mesh is decimated; the mesh's normals match the views' `Normal_gt.mat`.

mod common;

use common::miniature;
use dataset_diligent::{MultiViewOptions, import_multi_view};
use scene::SceneDataset;
use scene::{MaterialSpec, Split};

fn options() -> MultiViewOptions {
    MultiViewOptions {
        views: 4,
        train_lights: 4,
        test_lights: 3,
        seed: 3,
        target_vertices: Some(1000),
        ..Default::default()
    }
}

#[test]
fn miniature_imports_into_the_common_dataset_api() {
    let tmp = common::TempDir::new("mv");
    let src = miniature::write(&tmp.0, 4, 8);
    let out = tmp.0.join("scene");
    let r = import_multi_view(&src, &out, &options()).unwrap();
    eprintln!("miniature: {r:#?}");
    let d = r.decimation.unwrap();
    assert_eq!((d.vertices_before, d.vertices_after, r.mesh_vertices), (2562, 1000, 1000));
    // The stretched rotations are factored into the intrinsics, with one warning.
    assert_eq!(r.warnings.len(), 1, "{:?}", r.warnings);
    assert!(r.warnings[0].contains("not orthonormal"), "{:?}", r.warnings);
    let nc = r.normal_check.unwrap();
    eprintln!("miniature normals vs Normal_gt: {nc:?}");
    assert!(nc.pixels > 2500 && nc.mean_deg < 1.5 && nc.max_deg < 8.0, "{nc:?}");
    assert_eq!(r.views.len(), 4);
    for (i, v) in r.views.iter().enumerate() {
        assert_eq!(v.split, if i % 2 == 0 { Split::Train } else { Split::Test });
        assert_eq!(v.lights.len(), if i % 2 == 0 { 4 } else { 3 });
        assert!(v.mask_iou() > 0.93, "view {i}: {v:?}");
    }
    assert!(r.stats.saturated_samples > 0 && r.stats.lit_samples > 1000, "{:?}", r.stats);

    let ds = SceneDataset::open(&out).unwrap();
    assert!(matches!(&ds.manifest.config.material, MaterialSpec::Captured { benchmark, object }
        if benchmark == "DiLiGenT-MV" && object == "mini"));
    assert_eq!(std::fs::read_dir(out.join("geometry")).unwrap().count(), 1);
    for split in [Split::Train, Split::Test] {
        let s = ds.samples(split).unwrap();
        assert!(s.len() > 500, "{split:?}: {}", s.len());
        let (mut sum, mut n, mut worst) = (0.0, 0, 0.0_f64);
        for i in 0..s.len() {
            // Positions lie on the normalised sphere, and n . l reproduces the rendering.
            let p = s.position[i];
            let len = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
            assert!((len - 1.0).abs() < 0.02, "{len}");
            assert_eq!(ds.manifest.views[s.view[i] as usize].split, split);
            if s.saturated[i] {
                // Clipped: raw 65535 over the red intensity 2.4.
                assert!((s.observed[i][0] - 1.0 / 2.4).abs() < 1e-6, "{:?}", s.observed[i]);
                continue;
            }
            let nl: f32 = (0..3).map(|k| s.normal[i][k] * s.l[i][k]).sum();
            for c in 0..3 {
                let e = (s.observed[i][c] as f64 - miniature::ALBEDO[c] * nl as f64).abs();
                sum += e;
                n += 1;
                worst = worst.max(e);
            }
        }
        eprintln!(
            "{split:?}: {} samples, |observed - albedo n.l| mean {:.5} max {:.5}",
            s.len(),
            sum / n as f64,
            worst
        );
        assert!(sum / (n as f64) < 0.01 && worst < 0.08, "{} {worst}", sum / n as f64);
    }
    // Light bookkeeping: source numbers are the split's lights, disjoint between the splits.
    let lights = |v: usize| -> Vec<u32> {
        ds.manifest.views[v].lights.iter().map(|l| l.source_index.unwrap()).collect()
    };
    assert_eq!(lights(0), lights(2));
    assert_eq!(lights(1), lights(3));
    assert!(lights(0).iter().all(|i| !lights(1).contains(i) && (1..=8).contains(i)));
}
