//! The MERL binary format: exact round trip, clear errors on bad files, and lookup agreeing with
//! the reference reader's indexing.

mod common;

use common::TempDir;
use dataset_merl::merl::lookup::{bin_indices, bin_lower_edges};
use dataset_merl::merl::{CHANNEL_SCALES, FILE_BYTES, TABLE_LEN};
use dataset_merl::{Lookup, MerlBrdf, MerlMaterial};
use proptest::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};
use std::sync::Arc;

/// A table with pseudo-random raw values, some negative (invalid).
fn random_table(seed: u64) -> MerlBrdf {
    let mut s = seed;
    let raw: Vec<f64> = (0..3 * TABLE_LEN)
        .map(|_| {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let u = (s >> 11) as f64 / (1u64 << 53) as f64;
            if u < 0.01 { -1.0 } else { u * 100.0 }
        })
        .collect();
    MerlBrdf::from_raw(raw, "test").unwrap()
}

#[test]
fn write_read_round_trip_is_exact() {
    let dir = TempDir::new("roundtrip");
    let t = random_table(1);
    let path = dir.0.join("x.binary");
    t.write(&path).unwrap();
    assert_eq!(std::fs::metadata(&path).unwrap().len() as usize, FILE_BYTES);
    let back = MerlBrdf::read(&path).unwrap();
    assert!(t.raw().iter().zip(back.raw()).all(|(a, b)| a.to_bits() == b.to_bits()));
    assert_eq!(std::fs::read(&path).unwrap(), t.to_bytes());
    assert!(back.invalid_entries() > 0);
    // No temporary file left behind.
    assert_eq!(std::fs::read_dir(&dir.0).unwrap().count(), 1);
}

#[test]
fn bad_files_give_clear_errors() {
    let dir = TempDir::new("bad");
    let good = random_table(2).to_bytes();
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("short.binary", good[..7].to_vec(), "12-byte header"),
        ("truncated.binary", good[..FILE_BYTES - 8].to_vec(), "truncated"),
        ("trailing.binary", [good.clone(), vec![0u8; 8]].concat(), "trailing data"),
        (
            "dims.binary",
            [&90i32.to_le_bytes()[..], &90i32.to_le_bytes(), &90i32.to_le_bytes(), &good[12..]]
                .concat(),
            "dimensions [90, 90, 90]",
        ),
        (
            "nan.binary",
            {
                let mut b = good.clone();
                b[12 + 8 * 5..12 + 8 * 6].copy_from_slice(&f64::NAN.to_le_bytes());
                b
            },
            "not finite",
        ),
    ];
    for (name, bytes, fault) in cases {
        let path = dir.0.join(name);
        std::fs::write(&path, bytes).unwrap();
        let msg = MerlBrdf::read(&path).unwrap_err().to_string();
        assert!(msg.contains(name) && msg.contains(fault), "{name}: {msg}");
    }
    let missing = dir.0.join("missing.binary");
    let msg = MerlBrdf::read(&missing).unwrap_err().to_string();
    assert!(msg.contains("missing.binary"), "{msg}");
}

/// The MERL reference reader's index functions (BRDFRead.cpp), transcribed literally; phi_ref is
/// atan2's value in (-pi, pi].
fn reference_indices(theta_half: f64, theta_diff: f64, phi_ref: f64) -> (usize, usize, usize) {
    let h = if theta_half <= 0.0 {
        0
    } else {
        let deg = (theta_half / (PI / 2.0)) * 90.0;
        ((deg * 90.0).sqrt() as i64).clamp(0, 89) as usize
    };
    let d = ((theta_diff / (PI * 0.5) * 90.0) as i64).clamp(0, 89) as usize;
    let mut p = phi_ref;
    if p < 0.0 {
        p += PI;
    }
    let ip = ((p / PI * 360.0 / 2.0) as i64).clamp(0, 179) as usize;
    (h, d, ip)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 20_000, ..ProptestConfig::default() })]

    #[test]
    fn indexing_matches_reference(th in 0.0..FRAC_PI_2, td in 0.0..FRAC_PI_2, phi_ref in -PI..PI) {
        // Our convention: phi_d in [0, 2 pi) (the paper's); the reference folds atan2's value.
        let phi_d = phi_ref.rem_euclid(2.0 * PI);
        prop_assert_eq!(bin_indices(th, td, phi_d), reference_indices(th, td, phi_ref));
    }

}

proptest! {
    // About a quarter of all bins lie partly below the horizon (theta_h + theta_d > pi/2):
    // their centres are rejected.
    #![proptest_config(ProptestConfig { cases: 5_000, max_global_rejects: 50_000, ..ProptestConfig::default() })]
    #[test]
    fn lookup_by_directions_hits_the_bin(ih in 0usize..90, id in 0usize..90, ip in 0usize..180) {
        // Directions built from the centre of a bin (in index space) land in that bin.
        let t = table_for_lookup();
        let (th, td, pd) = centre(ih, id, ip);
        let r = angles::Rusinkiewicz { theta_h: th, theta_d: td, phi_d: pd };
        let (l, v) = r.to_local_with_phi_h(0.7);
        prop_assume!(l[2] > 1e-9 && v[2] > 1e-9);
        let got = t.eval_dirs(l, v, Lookup::NearestLower);
        prop_assert_eq!(got, t.bin(ih, id, ip));
        // Swapping l and v gives the same bits.
        prop_assert_eq!(got.map(|f| f.map(f64::to_bits)), t.eval_dirs(v, l, Lookup::NearestLower).map(|f| f.map(f64::to_bits)));
    }
}

fn table_for_lookup() -> &'static MerlBrdf {
    static T: std::sync::OnceLock<MerlBrdf> = std::sync::OnceLock::new();
    T.get_or_init(|| random_table(3))
}

/// Angles at the centre of a bin in index coordinates.
fn centre(ih: usize, id: usize, ip: usize) -> (f64, f64, f64) {
    let uh = (ih as f64 + 0.5) / 90.0;
    (uh * uh * FRAC_PI_2, (id as f64 + 0.5) / 90.0 * FRAC_PI_2, (ip as f64 + 0.5) / 180.0 * PI)
}

#[test]
fn trilinear_interpolates_between_lower_edges() {
    // A table whose raw value is linear in the three indices: trilinear reproduces it exactly
    // between edges, and wraps periodically in phi_d.
    let f = |ih: usize, id: usize, ip: usize| (ih * 10_000 + id * 100 + ip) as f64;
    let raw: Vec<f64> = (0..3)
        .flat_map(|_| (0..TABLE_LEN).map(move |i| f(i / 16_200, (i / 180) % 90, i % 180)))
        .collect();
    let t = MerlBrdf::from_raw(raw, "linear").unwrap();
    let (th, td, pd) = bin_lower_edges(20, 30, 40);
    let (th1, td1, pd1) = bin_lower_edges(21, 31, 41);
    // Midpoint in index space of each axis.
    let uh = (20.5_f64 / 90.0).powi(2) * FRAC_PI_2;
    let got = t.eval_angles(uh, 0.5 * (td + td1), 0.5 * (pd + pd1), Lookup::Trilinear).unwrap();
    let expect = 20.5 * 10_000.0 + 30.5 * 100.0 + 40.5;
    assert!((got[0] / CHANNEL_SCALES[0] - expect).abs() < 1e-6, "{}", got[0] / CHANNEL_SCALES[0]);
    let _ = (th, th1);
    // Halfway between phi bins 179 and 0 (wrap-around): the mean of the two.
    let (_, _, p179) = bin_lower_edges(0, 0, 179);
    let got = t.eval_angles(0.0, 0.0, p179 + 0.5 / 180.0 * PI, Lookup::Trilinear).unwrap();
    assert!((got[0] / CHANNEL_SCALES[0] - 89.5).abs() < 1e-6);
    // Inside a bin, nearest-lower returns the bin's value.
    let got = t.eval_angles(uh, td, pd, Lookup::NearestLower).unwrap();
    assert!((got[0] / CHANNEL_SCALES[0] - f(20, 30, 40)).abs() < 1e-9);
}

#[test]
fn invalid_bins_are_reported_and_render_black() {
    let mut raw = vec![1.0; 3 * TABLE_LEN];
    let i = 5 + 180 * (7 + 90 * 11);
    raw[i + TABLE_LEN] = -1.0; // green of bin (11, 7, 5)
    let t = MerlBrdf::from_raw(raw, "holes").unwrap();
    assert_eq!(t.invalid_entries(), 1);
    assert_eq!(t.bin(11, 7, 5), None);
    let (th, td, pd) = centre(11, 7, 5);
    assert_eq!(t.eval_angles(th, td, pd, Lookup::NearestLower), None);
    assert_eq!(t.eval_angles(th, td, pd, Lookup::Trilinear), None);
    let m = MerlMaterial { table: Arc::new(t), lookup: Lookup::NearestLower };
    let (l, v) = angles::Rusinkiewicz { theta_h: th, theta_d: td, phi_d: pd }.to_local();
    assert_eq!(brdf_analytic::Brdf::<f64>::eval(&m, l, v), [0.0; 3]);
}
