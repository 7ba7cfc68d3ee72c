//! The real DiLiGenT ball: its MAT v5 normal map reads, and the imported scene opens with
//! dataset-merl's `SceneDataset` with disjoint train and test lights, a sphere that matches the
//! mask and the ground-truth normals, and observations that follow the normals' shading.

mod common;

use dataset_diligent::mat5::{MatClass, MatFile, NumericClass};
use dataset_diligent::{SingleViewOptions, import_single_view};
use scene::SceneDataset;
use scene::{MaterialSpec, Split};

#[test]
fn normal_gt_mat_reads_as_a_unit_normal_map() {
    let Some(dir) = common::shared("diligent/pmsData/ballPNG") else { return };
    let mat = MatFile::read(&dir.join("Normal_gt.mat"), &stdx::Limits::DEFAULT).unwrap();
    let v = mat.numeric(&["Normal_gt"]).unwrap();
    assert_eq!(v.dims, [512, 612, 3]);
    assert_eq!(v.class, MatClass::Numeric(NumericClass::Double));
    // Background is zero; the ball's normals are unit, facing the camera at the centre and up
    // (DiLiGenT's y) at the top.
    assert_eq!([0, 1, 2].map(|c| v.at(&[0, 0, c]).unwrap()), [0.0; 3]);
    let n = |r: usize, c: usize| [0, 1, 2].map(|k| v.at(&[r, c, k]).unwrap());
    let centre = n(263, 307);
    assert!(centre[2] > 0.99, "{centre:?}");
    let top = n(196, 307);
    assert!(top[1] > 0.9, "{top:?}");
    let len = |a: [f64; 3]| (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    assert!((len(top) - 1.0).abs() < 1e-6 && (len(centre) - 1.0).abs() < 1e-6);
}

#[test]
fn ball_imports_into_the_common_dataset_api() {
    let Some(src) = common::shared("diligent/pmsData/ballPNG") else { return };
    let tmp = common::TempDir::new("ball");
    let out = tmp.0.join("scene");
    let r = import_single_view(&src, &out, &SingleViewOptions::default()).unwrap();
    let c = r.circle.unwrap();
    let nc = r.normal_check.unwrap();
    eprintln!(
        "ball: import {:.2} s, {} bytes; circle centre ({:.2}, {:.2}) radius {:.2} px (area radius \
         {:.2}, rms {:.3} px, {} points); mask IoU {:.4}; normals vs Normal_gt over {} px: mean \
         {:.3} deg, median {:.3}, p95 {:.3}, max {:.3}; stats {:?}",
        r.seconds,
        r.bytes,
        c.center[0],
        c.center[1],
        c.radius,
        c.area_radius,
        c.rms_residual,
        c.boundary_points,
        r.views[0].mask_iou(),
        nc.pixels,
        nc.mean_deg,
        nc.median_deg,
        nc.p95_deg,
        nc.max_deg,
        r.stats
    );
    assert!((c.radius - c.area_radius).abs() < 1.0 && c.rms_residual < 0.5, "{c:?}");
    assert!(r.views[0].mask_iou() > 0.98, "{:?}", r.views[0]);
    assert!(nc.pixels > 15_000 && nc.mean_deg < 3.0, "{nc:?}");
    assert_eq!((r.views.len(), r.views[0].lights.len(), r.views[1].lights.len()), (2, 30, 12));

    let ds = SceneDataset::open(&out).unwrap();
    assert!(matches!(
        &ds.manifest.config.material,
        MaterialSpec::Captured { benchmark, object } if benchmark == "DiLiGenT" && object == "ball"
    ));
    assert_eq!(ds.manifest.label, "captured (DiLiGenT ball)");
    // The precompute written by the importer is the one `open` wants: still one cache file.
    assert_eq!(std::fs::read_dir(out.join("geometry")).unwrap().count(), 1);
    let train = ds.samples(Split::Train).unwrap();
    let test = ds.samples(Split::Test).unwrap();
    assert!(
        train.len() > 30 * 10_000 && test.len() > 12 * 10_000,
        "{} {}",
        train.len(),
        test.len()
    );
    let ids = |s: &scene::SampleSet, v: usize| -> Vec<u32> {
        let view = &ds.manifest.views[v];
        let mut ids: Vec<u32> =
            s.light.iter().map(|&l| view.lights[l as usize].source_index.unwrap()).collect();
        ids.sort_unstable();
        ids.dedup();
        ids
    };
    let (tr, te) = (ids(&train, 0), ids(&test, 1));
    assert_eq!((tr.len(), te.len()), (30, 12));
    assert!(tr.iter().all(|i| !te.contains(i)));
    assert!(train.gt_valid.iter().all(|v| !v) && train.irradiance.iter().all(|e| *e == [1.0; 3]));

    // The observations follow the sphere's shading: radiance correlates with n . l.
    let (mut sx, mut sy, mut sxx, mut syy, mut sxy, n) =
        (0.0, 0.0, 0.0, 0.0, 0.0, train.len() as f64);
    for i in 0..train.len() {
        let nl: f64 = (0..3).map(|k| (train.normal[i][k] * train.l[i][k]) as f64).sum();
        let y = train.observed[i].iter().map(|&x| x as f64).sum::<f64>() / 3.0;
        sx += nl;
        sy += y;
        sxx += nl * nl;
        syy += y * y;
        sxy += nl * y;
    }
    let corr = (sxy - sx * sy / n) / ((sxx - sx * sx / n) * (syy - sy * sy / n)).sqrt();
    eprintln!("ball: correlation of observed radiance with n.l over the train samples: {corr:.3}");
    assert!(corr > 0.8, "{corr}");
}
