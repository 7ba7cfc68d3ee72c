//! One test image's image metrics as an evaluation computes them (`experiments::eval::images`):
//! a 128 x 128 frame whose object (a disc, 24 % of the frame, the share of Spot in the
//! default's test views) is lit unevenly, an observation with noise everywhere, a render and a
//! noise-free image that are 0 outside the object.
//!
//! * `flip`: the four images prepared for HDR-FLIP at the observation's exposures and the
//!   three comparisons, on the whole frame and on the [`FlipWindow`] around the object;
//! * `dssim`: DSSIM on the object mask and on the whole frame.
//!
//! `cargo bench -p metrics --bench image_metrics`

use criterion::{Criterion, criterion_group, criterion_main};
use metrics::flip::{DEFAULT_PPD, FlipWindow, exposure_range};
use metrics::testimg::{ObjectFrame, object_frame};
use metrics::{FlipExposures, FlipImage, Image, dssim_linear, hdr_flip_prepared};

/// The evaluation's FLIP work on one test image, on `window` (or the whole frame).
fn flip_pair(f: &ObjectFrame, at: &FlipExposures, window: Option<&FlipWindow>) -> f64 {
    let crop = |im: &Image| window.map_or_else(|| im.clone(), |w| w.crop(im).unwrap());
    let mask = window.map_or_else(|| f.mask.clone(), |w| w.crop_mask(&f.mask).unwrap());
    let prep = |im: &Image| FlipImage::new(&crop(im), at).unwrap();
    let (t, o, c) = (prep(&f.test), prep(&f.observed), prep(&f.clean));
    let reference = Image::new(
        f.observed.width(),
        f.observed.height(),
        f.observed
            .data()
            .chunks_exact(3)
            .zip(&f.mask)
            .flat_map(|(p, &m)| if m { [p[0], p[1], p[2]] } else { [0.0; 3] })
            .collect(),
    )
    .unwrap();
    let r = prep(&reference);
    let a = hdr_flip_prepared(&t, &o, Some(&mask)).unwrap().mean;
    let b = hdr_flip_prepared(&t, &r, None).unwrap().mean;
    let d = hdr_flip_prepared(&t, &c, Some(&mask)).unwrap().mean;
    a + b + d
}

fn image_metrics(c: &mut Criterion) {
    // Spot covers 24.4 % of a default test view: a disc of radius 35.7 px in 128 x 128.
    let f = object_frame(128, 128, (60.0, 66.0), 35.7);
    let at = FlipExposures::new(exposure_range(&f.observed, Some(&f.mask)).unwrap(), DEFAULT_PPD)
        .unwrap();
    let pixels = (0..f.mask.len()).filter(|&p| f.mask[p]);
    let window = FlipWindow::around((128, 128), DEFAULT_PPD, pixels).unwrap().unwrap();
    eprintln!(
        "{} exposures; the window holds {:.1} % of the frame",
        at.count(),
        100.0 * window.pixels() as f64 / (128.0 * 128.0)
    );
    let mut group = c.benchmark_group("image_metrics");
    group.sample_size(20);
    group.bench_function("flip, whole frame", |b| b.iter(|| flip_pair(&f, &at, None)));
    group.bench_function("flip, window", |b| b.iter(|| flip_pair(&f, &at, Some(&window))));
    group.bench_function("dssim, mask", |b| {
        b.iter(|| dssim_linear(&f.test, &f.observed, Some(&f.mask)).unwrap())
    });
    group.bench_function("dssim, whole frame", |b| {
        b.iter(|| dssim_linear(&f.test, &f.clean, None).unwrap())
    });
    group.finish();
}

criterion_group!(benches, image_metrics);
criterion_main!(benches);
