//! NBRDF networks and the material catalogue: shipped copies equal the published files,
//! tabulation reproduces the network, real MERL files take precedence, unknown names are clear
//! errors.

mod common;

use common::{TempDir, shared_data};
use dataset_merl::catalogue::entry;
use dataset_merl::merl::CHANNEL_SCALES;
use dataset_merl::merl::lookup::bin_lower_edges;
use dataset_merl::*;
use std::collections::HashSet;

#[test]
fn catalogue_has_25_distinct_materials_spanning_the_classes() {
    let names: HashSet<_> = CATALOGUE.iter().map(|e| e.name).collect();
    assert_eq!(names.len(), 25);
    for required in [
        "grease-covered-steel",
        "blue-acrylic",
        "ipswich-pine-221",
        "white-marble",
        "maroon-plastic",
        "green-latex",
    ] {
        assert!(names.contains(required), "{required} missing");
    }
    let classes: HashSet<_> = CATALOGUE.iter().map(|e| e.class).collect();
    use MaterialClass::*;
    for c in [Diffuse, Plastic, Paint, Fabric, Wood, Stone, Metal] {
        assert!(classes.contains(&c), "{c:?} missing");
    }
    for e in &CATALOGUE {
        let n = e.nbrdf().unwrap();
        assert_eq!(n.material(), e.name);
        assert_eq!(n.parameter_count(), 675);
    }
}

#[test]
fn shipped_networks_equal_the_published_files() {
    let Some(data) = shared_data() else { return };
    for e in &CATALOGUE {
        let path = data.join("nbrdf/merl").join(format!("{}.json", e.name));
        let published = std::fs::read_to_string(&path).unwrap();
        assert_eq!(published, e.nbrdf_json(), "{} differs from {}", e.name, path.display());
    }
}

#[test]
fn tabulation_reproduces_the_network_and_stays_non_negative() {
    use std::sync::atomic::{AtomicUsize, Ordering};
    let e = entry("blue-acrylic").unwrap();
    let net = e.nbrdf().unwrap();
    let (table, report) = net.tabulate().unwrap();
    assert_eq!(table.invalid_entries(), 0);
    let clamped = AtomicUsize::new(0);
    // Every 7th bin: the stored value is the network at the bin's lower edge.
    let mut checked = 0;
    for ih in (0..90).step_by(7) {
        for id in (0..90).step_by(7) {
            for ip in (0..180).step_by(7) {
                let (th, td, pd) = bin_lower_edges(ih, id, ip);
                let f = net.eval_raw(th, td, pd);
                let stored = table.bin(ih, id, ip).unwrap();
                for c in 0..3 {
                    if f[c] < 0.0 {
                        clamped.fetch_add(1, Ordering::Relaxed);
                        assert_eq!(stored[c], 0.0);
                    } else {
                        let back = stored[c] / CHANNEL_SCALES[c] * CHANNEL_SCALES[c];
                        assert!(
                            (back - f[c]).abs() <= 1e-12 * f[c].abs().max(1e-300),
                            "{} vs {}",
                            stored[c],
                            f[c]
                        );
                    }
                }
                checked += 1;
            }
        }
    }
    assert!(checked > 3000);
    assert!(clamped.into_inner() <= report.negatives_clamped);
    // Physically plausible: a glossy acrylic has a bright specular peak and a dimmer body.
    let peak = table.bin(0, 10, 90).unwrap();
    let off = table.bin(60, 10, 90).unwrap();
    assert!(peak[2] > 10.0 * off[2], "peak {peak:?} off {off:?}");
}

#[test]
fn real_merl_files_take_precedence() {
    let dir = TempDir::new("precedence");
    // A "measured" table: the NBRDF table halved, written in the real format.
    let (t, _) = entry("green-latex").unwrap().nbrdf().unwrap().tabulate().unwrap();
    let halved = MerlBrdf::from_raw(t.raw().iter().map(|x| 0.5 * x).collect(), "halved").unwrap();
    halved.write(&dir.0.join("green-latex.binary")).unwrap();
    let m = load_material("green-latex", Some(&dir.0)).unwrap();
    assert_eq!(m.source.label(), "MERL");
    assert_eq!(m.table.raw()[1234], halved.raw()[1234]);
    // Without the file (or without a directory) the shipped network is used.
    let m = load_material("blue-acrylic", Some(&dir.0)).unwrap();
    assert_eq!(m.source.label(), "MERL-derived (NBRDF)");
    // A corrupt real file is an error naming it, not a silent fallback.
    let truncated = &halved.to_bytes()[..1000];
    std::fs::write(dir.0.join("white-marble.binary"), truncated).unwrap();
    let msg = load_material("white-marble", Some(&dir.0)).unwrap_err().to_string();
    assert!(msg.contains("white-marble.binary") && msg.contains("truncated"), "{msg}");
}

#[test]
fn unknown_material_and_bad_networks_are_clear_errors() {
    let msg = load_material("unobtainium", None).unwrap_err().to_string();
    assert!(msg.contains("unobtainium") && msg.contains("blue-acrylic"), "{msg}");
    let good = entry("brass").unwrap().nbrdf_json();
    for (bad, fault) in [
        (good.replace("nbrdf-mlp-v1", "v0"), "format"),
        (good.replace("\"relu\"", "\"tanh\""), "activation"),
        (good[..good.len() / 2].to_string(), "EOF"),
        (good.replacen("\"in\":21", "\"in\":20", 1), "layer 1"),
    ] {
        let msg = Nbrdf::from_json(&bad, "brass.json").unwrap_err().to_string();
        assert!(msg.contains("brass.json") && msg.contains(fault), "{fault}: {msg}");
    }
}
