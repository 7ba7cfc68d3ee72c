//! Deterministic test images shared by the tests, the parity example and
//! `devtools/reference_values.py` (which builds the same images in numpy).

use crate::image::Image;

/// lowbias32 integer hash.
fn h32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^ (x >> 16)
}

/// Uniform value in [0, 1) of (x, y, channel, seed).
pub fn val(x: usize, y: usize, c: usize, seed: usize) -> f64 {
    let k = (x + 1000 * y + 1_000_000 * c + seed * 7919) as u32;
    h32(k) as f64 / 4_294_967_296.0
}

/// An LDR (reference, test) pair in [0, 1]: a ramp pattern plus noise, and a perturbed copy.
pub fn ldr_pair(w: usize, h: usize, seed: usize) -> (Image, Image) {
    let mut r = Vec::with_capacity(w * h * 3);
    let mut t = Vec::with_capacity(w * h * 3);
    for y in 0..h {
        for x in 0..w {
            for c in 0..3 {
                let s = ((x * 3 + y * 5 + c * 7) % 17) as f64 / 16.0;
                let rv = 0.6 * s + 0.4 * val(x, y, c, seed);
                let tv = (rv + 0.2 * (val(x, y, c, seed + 1) - 0.5)).clamp(0.0, 1.0);
                r.push(rv as f32);
                t.push(tv as f32);
            }
        }
    }
    (Image::new(w, h, r).expect("size"), Image::new(w, h, t).expect("size"))
}

/// An HDR (reference, test) pair: a ramp plus a heavy-tailed `gain * u^3` term, and a copy
/// scaled per channel by a factor in [0.7, 1.3).
pub fn hdr_pair(w: usize, h: usize, seed: usize, gain: f64) -> (Image, Image) {
    let mut r = Vec::with_capacity(w * h * 3);
    let mut t = Vec::with_capacity(w * h * 3);
    for y in 0..h {
        for x in 0..w {
            for c in 0..3 {
                let v = val(x, y, c, seed);
                let rv = 0.05 + (x + y) as f64 / (w + h) as f64 + gain * v * v * v;
                let tv = rv * (0.7 + 0.6 * val(x, y, c, seed + 1));
                r.push(rv as f32);
                t.push(tv as f32);
            }
        }
    }
    (Image::new(w, h, r).expect("size"), Image::new(w, h, t).expect("size"))
}
