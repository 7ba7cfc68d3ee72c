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

/// A test image of an evaluation, as [`object_frame`] makes it: an object in a frame.
pub struct ObjectFrame {
    /// The render of a slightly dim model: 0 outside the object.
    pub test: Image,
    /// The observation: the noise-free image plus noise everywhere, background included.
    pub observed: Image,
    /// The noise-free image: 0 outside the object.
    pub clean: Image,
    /// The object's pixels.
    pub mask: Vec<bool>,
}

/// A `w` x `h` frame with a disc of `radius` pixels at `centre`, lit with a gradient and a
/// specular highlight (the exposures span about 2^4), as an evaluation's test image sees it.
pub fn object_frame(w: usize, h: usize, centre: (f32, f32), radius: f32) -> ObjectFrame {
    let inside = |x: usize, y: usize| {
        let (dx, dy) = (x as f32 - centre.0, y as f32 - centre.1);
        dx * dx + dy * dy < radius * radius
    };
    let shade = |x: usize, y: usize, k: f32| {
        if !inside(x, y) {
            return [0.0; 3];
        }
        let (dx, dy) = (x as f32 - centre.0 + 0.3 * radius, y as f32 - centre.1 + 0.3 * radius);
        let spec = 6.0 * k * (-(dx * dx + dy * dy) / 30.0).exp();
        let (u, v) = (x as f32 / w as f32, y as f32 / h as f32);
        [0.1 + k * u + spec, 0.4 * k + spec, 0.05 + 0.5 * v + spec]
    };
    let noise = |x: usize, y: usize, c: usize| 0.02 * val(x, y, c, 3) as f32;
    ObjectFrame {
        test: Image::from_fn(w, h, |x, y| shade(x, y, 0.95)),
        clean: Image::from_fn(w, h, |x, y| shade(x, y, 1.0)),
        observed: Image::from_fn(w, h, |x, y| {
            let s = shade(x, y, 1.0);
            [s[0] + noise(x, y, 0), s[1] + noise(x, y, 1), s[2] + noise(x, y, 2)]
        }),
        mask: (0..w * h).map(|p| inside(p % w, p / w)).collect(),
    }
}
