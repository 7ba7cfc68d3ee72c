use super::*;

/// A Lambertian sphere of albedo `a` under `light` (E = pi).
fn lambert_sphere(a: f32, light: [f64; 3]) -> LitSphere {
    let mut radiance = Vec::new();
    for y in 0..SPHERE_SIZE {
        for x in 0..SPHERE_SIZE {
            radiance.push(match sphere_normal(x, y) {
                Some(n) => {
                    let cos = (n[0] * light[0] + n[1] * light[1] + n[2] * light[2]).max(0.0);
                    [a * cos as f32; 3]
                }
                None => [0.0; 3],
            });
        }
    }
    LitSphere { light, radiance }
}

#[test]
fn sphere_normals_are_unit_inside_the_disk_only() {
    let c = SPHERE_SIZE / 2;
    let n = sphere_normal(c, c).unwrap();
    assert!(n[2] > 0.99, "{n:?}");
    assert!(sphere_normal(0, 0).is_none());
    for y in 0..SPHERE_SIZE {
        for x in 0..SPHERE_SIZE {
            if let Some(n) = sphere_normal(x, y) {
                assert!((n[0] * n[0] + n[1] * n[1] + n[2] * n[2] - 1.0).abs() < 1e-12);
            }
        }
    }
    // Row 0 is the top: y up.
    assert!(sphere_normal(c, 2).unwrap()[1] > 0.9);
}

#[test]
fn lit_spheres_show_zero_error_for_the_ground_truth_and_more_for_a_darker_fit() {
    let light = [-0.5, 0.5, std::f64::consts::FRAC_1_SQRT_2];
    let gt = lambert_sphere(0.8, light);
    let same = gt.clone();
    let darker = lambert_sphere(0.4, light);
    let models = [("same".to_string(), &same), ("darker".to_string(), &darker)];
    let g = lit_sphere_grid("test", Some(&gt), &models).unwrap();
    assert_eq!(g.rows.len(), 3);
    assert_eq!(g.rows[0].label, "Ground truth");
    let mean = |c: &str| c.trim_start_matches("mean ").parse::<f64>().unwrap();
    assert_eq!(mean(&g.rows[1].cells[1].caption), 0.0);
    assert!(mean(&g.rows[2].cells[1].caption) > 0.05, "{}", g.rows[2].cells[1].caption);
    let img = g.rows[1].cells[0].image.as_ref().unwrap();
    assert_eq!(img.width(), 3 * SPHERE_SIZE);
    assert_eq!(img.pixels()[0], SPHERE_BACKGROUND, "outside the disk");
    assert!(crate::image_grid_png(&g).is_ok());
    // A sphere of the wrong size is an error, not a panic.
    let bad = LitSphere { light, radiance: vec![[0.0; 3]; 10] };
    assert!(lit_sphere_grid("t", Some(&bad), &[]).is_err());
}

#[test]
fn slices_and_albedo_plots_draw_linear_and_log() {
    let slice = |k: f32| PolarSlice {
        theta_i_deg: 30.0,
        points: (-89..=89).map(|t| (t as f64, [k * (t as f32).to_radians().cos(); 3])).collect(),
    };
    let (a, b) =
        (vec![slice(0.3), PolarSlice { theta_i_deg: 60.0, ..slice(0.2) }], vec![slice(0.0)]);
    let brdfs = [("GT".to_string(), a.as_slice()), ("zero".to_string(), b.as_slice())];
    for log in [false, true] {
        let png = polar_slices_png("t", &brdfs, log).unwrap();
        assert!(png.len() > 1000);
    }
    assert!(polar_slices_png("t", &[], false).is_err());
    let curve: Vec<(f64, [f32; 3])> =
        (0..45).map(|i| (2.0 * i as f64, [0.9, 1.1, f32::NAN])).collect();
    assert!(albedo_plot_png("t", &[("m".to_string(), curve.as_slice())]).unwrap().len() > 1000);
}

#[test]
fn validity_colours_and_captions() {
    assert_eq!(albedo_colour(f32::NAN), MAP_BACKGROUND);
    assert_eq!(albedo_colour(0.0), [0, 0, 0]);
    assert_eq!(albedo_colour(1.0), [255, 255, 255]);
    assert_eq!(albedo_colour(ALBEDO_RED), [255, 0, 0]);
    let pink = albedo_colour(1.01);
    assert_eq!(pink[0], 255);
    assert!(pink[1] > 150 && pink[1] == pink[2], "{pink:?}");
    assert_eq!(reciprocity_colour(0.0), magma(0.0));
    assert_eq!(reciprocity_colour(1e-6), magma(0.0));
    assert_eq!(reciprocity_colour(10.0), magma(1.0));
    assert_eq!(reciprocity_colour(f32::INFINITY), MAP_BACKGROUND);
    let m = ValidityMaps {
        view: "test view 3".into(),
        width: 4,
        height: 2,
        albedo: vec![0.5, 0.9, 1.1, 1.3, f32::NAN, 0.2, 0.4, 0.6],
        reciprocity: vec![0.0, 1e-3, 1e-2, 0.1, f32::NAN, 0.0, 0.0, 0.0],
    };
    let g = validity_grid("obj", &[("Single MLP".to_string(), &m)]).unwrap();
    assert_eq!(g.rows[0].cells[0].caption, "> 1 at 28.6 % of pixels, max 1.300");
    assert_eq!(g.rows[0].cells[1].caption, "median 0.0e0, max 1.0e-1");
    assert!(g.title.contains("test view 3"));
    let img = g.rows[0].cells[0].image.as_ref().unwrap();
    assert_eq!(img.width(), 4 * 72);
    assert!(crate::image_grid_png(&g).is_ok());
    let short = ValidityMaps { albedo: vec![1.0], ..m };
    assert!(validity_grid("obj", &[("x".to_string(), &short)]).is_err());
}
