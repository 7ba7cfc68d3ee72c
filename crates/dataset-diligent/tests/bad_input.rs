//! Bad input gives clear errors that name the file and the fault, never a panic, and leaves no
//! scene (or partial directory) behind: missing views, mismatched light counts, zero, negative
//! or NaN intensities, masks of the wrong size, truncated or 8-bit PNGs, wrong MAT shapes.

mod common;

use common::miniature;
use dataset_diligent::mat5::write_mat5;
use dataset_diligent::{
    MultiViewOptions, SingleViewOptions, import_multi_view, import_single_view,
};
use std::path::Path;

fn options() -> MultiViewOptions {
    MultiViewOptions {
        views: 3,
        train_lights: 2,
        test_lights: 2,
        target_vertices: None,
        ..Default::default()
    }
}

/// Builds a miniature, lets `damage` break it, imports it and returns the error message.
fn import_error(tag: &str, damage: impl FnOnce(&Path)) -> String {
    let tmp = common::TempDir::new(tag);
    let src = miniature::write(&tmp.0, 3, 5);
    damage(&src);
    let out = tmp.0.join("scene");
    let msg = import_multi_view(&src, &out, &options()).unwrap_err().to_string();
    assert!(!out.exists(), "{tag}: a scene was left behind");
    let left: Vec<_> = std::fs::read_dir(&tmp.0).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(left, ["mvpmsData"], "{tag}: partial output left behind");
    eprintln!("{tag}: {msg}");
    msg
}

fn rewrite(path: &Path, f: impl FnOnce(String) -> String) {
    let text = std::fs::read_to_string(path).unwrap();
    std::fs::write(path, f(text)).unwrap();
}

#[test]
fn multi_view_faults_name_the_file() {
    let m = import_error("missing-view", |s| std::fs::remove_dir_all(s.join("view_02")).unwrap());
    assert!(m.contains("view_02") && m.contains("missing"), "{m}");

    let m = import_error("fewer-intensities", |s| {
        rewrite(&s.join("view_01/light_intensities.txt"), |t| {
            t.lines().skip(1).map(|l| format!("{l}\n")).collect()
        })
    });
    assert!(
        m.contains("light_intensities.txt") && m.contains("4 light intensities") && m.contains("5"),
        "{m}"
    );

    let m = import_error("view-light-count", |s| {
        let v = s.join("view_03");
        for f in ["light_intensities.txt", "light_directions.txt"] {
            rewrite(&v.join(f), |t| t.lines().take(4).map(|l| format!("{l}\n")).collect());
        }
        std::fs::remove_file(v.join("005.png")).unwrap();
    });
    assert!(m.contains("view_03") && m.contains("4 lights") && m.contains("has 5"), "{m}");

    for (tag, bad) in [("zero", "0 1 1"), ("negative", "1 -2 1"), ("nan", "1 NaN 1")] {
        let m = import_error(tag, |s| {
            rewrite(&s.join("view_02/light_intensities.txt"), |t| {
                t.replacen(t.lines().nth(2).unwrap(), bad, 1)
            })
        });
        assert!(
            m.contains("view_02") && m.contains("light 3") && m.contains("finite and > 0"),
            "{m}"
        );
    }

    let m = import_error("direction", |s| {
        rewrite(&s.join("view_01/light_directions.txt"), |t| {
            t.replacen(t.lines().next().unwrap(), "0 0 0", 1)
        })
    });
    assert!(m.contains("light_directions.txt") && m.contains("not a unit vector"), "{m}");

    let m = import_error("mask-size", |s| {
        image::GrayImage::from_pixel(32, 48, image::Luma([255]))
            .save(s.join("view_02/mask.png"))
            .unwrap();
    });
    assert!(m.contains("view_02") && m.contains("mask.png") && m.contains("32 x 48"), "{m}");

    let m = import_error("truncated-png", |s| {
        let p = s.join("view_01/003.png");
        let bytes = std::fs::read(&p).unwrap();
        std::fs::write(&p, &bytes[..bytes.len() / 2]).unwrap();
    });
    assert!(m.contains("003.png") && m.contains("decode"), "{m}");

    let m = import_error("8-bit", |s| {
        // Light 1 is a training light of view 3 with the default seed.
        image::RgbImage::new(miniature::W, miniature::H).save(s.join("view_03/001.png")).unwrap();
    });
    assert!(m.contains("view_03/001.png") && m.contains("16-bit"), "{m}");

    let m =
        import_error("missing-image", |s| std::fs::remove_file(s.join("view_01/004.png")).unwrap());
    assert!(m.contains("004.png") && m.contains("missing"), "{m}");

    let m = import_error("mat-shape", |s| {
        let eye = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
        let bytes = write_mat5(
            &[
                ("KK", &[3, 3], &eye),
                ("Rc_1", &[3, 3], &eye),
                ("Tc_1", &[3, 1], &[0.0; 3]),
                ("Rc_2", &[3, 2], &[0.0; 6]),
            ],
            true,
        );
        std::fs::write(s.join("Calib_Results.mat"), bytes).unwrap();
    });
    assert!(m.contains("Calib_Results.mat") && m.contains("Rc_2") && m.contains("3 x 2"), "{m}");

    let m = import_error("mat-not-rotation", |s| {
        let eye = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
        let twice = eye.map(|x| 2.0 * x);
        let bytes = write_mat5(
            &[
                ("KK", &[3, 3], &eye),
                ("Rc_1", &[3, 3], &eye),
                ("Tc_1", &[3, 1], &[0.0; 3]),
                ("Rc_2", &[3, 3], &twice),
                ("Tc_2", &[3, 1], &[0.0; 3]),
            ],
            false,
        );
        std::fs::write(s.join("Calib_Results.mat"), bytes).unwrap();
    });
    assert!(m.contains("Calib_Results.mat") && m.contains("`Rc_2` is not a rotation"), "{m}");

    let m = import_error("mat-missing-var", |s| {
        let eye = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
        std::fs::write(s.join("Calib_Results.mat"), write_mat5(&[("KK", &[3, 3], &eye)], false))
            .unwrap();
    });
    assert!(m.contains("Calib_Results.mat") && m.contains("Rc_1"), "{m}");

    let m = import_error("mat-damaged", |s| {
        let p = s.join("Calib_Results.mat");
        let bytes = std::fs::read(&p).unwrap();
        std::fs::write(&p, &bytes[..200]).unwrap();
    });
    assert!(m.contains("Calib_Results.mat"), "{m}");

    let m = import_error("no-mesh", |s| std::fs::remove_file(s.join("mesh_Gt.ply")).unwrap());
    assert!(m.contains("miniPNG") && m.contains("mesh"), "{m}");
}

#[test]
fn bad_options_and_single_view_faults_are_errors() {
    let tmp = common::TempDir::new("opts");
    let src = miniature::write(&tmp.0, 2, 5);
    let out = tmp.0.join("scene");
    let o = MultiViewOptions { views: 2, train_lights: 4, test_lights: 2, ..options() };
    let m = import_multi_view(&src, &out, &o).unwrap_err().to_string();
    assert!(m.contains("train_lights") && m.contains("5"), "{m}");
    let o = MultiViewOptions { views: 2, train_views: Some(vec![1, 2]), ..options() };
    assert!(import_multi_view(&src, &out, &o).unwrap_err().to_string().contains("train_views"));
    // A single-view import of a non-ball object is refused with the reason.
    let view = src.join("view_01");
    let m = import_single_view(&view, &out, &SingleViewOptions::default()).unwrap_err().to_string();
    assert!(m.contains("view_01") && m.contains("normal integration"), "{m}");
    let m = import_single_view(&tmp.0.join("nope"), &out, &SingleViewOptions::default())
        .unwrap_err()
        .to_string();
    assert!(m.contains("nope") && m.contains("missing"), "{m}");
    assert!(!out.exists());
}
