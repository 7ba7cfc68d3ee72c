//! The network math against a direct evaluation with naive loops, on small random weights.

#![allow(clippy::needless_range_loop)]

use super::*;
use crate::testimg::ldr_pair;

type Fm = (usize, usize, usize, Vec<f64>); // (channels, height, width, values c-major)

fn conv(x: &Fm, w: &[f32], b: &[f32], out_c: usize, k: usize, stride: usize, pad: usize) -> Fm {
    let (c_in, h, wd, v) = x;
    let oh = (h + 2 * pad - k) / stride + 1;
    let ow = (wd + 2 * pad - k) / stride + 1;
    let mut o = vec![0.0; out_c * oh * ow];
    for oc in 0..out_c {
        for oy in 0..oh {
            for ox in 0..ow {
                let mut s = b[oc] as f64;
                for ic in 0..*c_in {
                    for ky in 0..k {
                        for kx in 0..k {
                            let iy = (oy * stride + ky) as i64 - pad as i64;
                            let ix = (ox * stride + kx) as i64 - pad as i64;
                            if iy >= 0 && ix >= 0 && (iy as usize) < *h && (ix as usize) < *wd {
                                let wv = w[((oc * c_in + ic) * k + ky) * k + kx] as f64;
                                s += wv * v[(ic * h + iy as usize) * wd + ix as usize];
                            }
                        }
                    }
                }
                o[(oc * oh + oy) * ow + ox] = s.max(0.0);
            }
        }
    }
    (out_c, oh, ow, o)
}

fn pool(x: &Fm) -> Fm {
    let (c, h, w, v) = x;
    let (oh, ow) = ((h - 3) / 2 + 1, (w - 3) / 2 + 1);
    let mut o = vec![f64::MIN; c * oh * ow];
    for ch in 0..*c {
        for oy in 0..oh {
            for ox in 0..ow {
                for ky in 0..3 {
                    for kx in 0..3 {
                        let val = v[(ch * h + oy * 2 + ky) * w + ox * 2 + kx];
                        let t = &mut o[(ch * oh + oy) * ow + ox];
                        *t = t.max(val);
                    }
                }
            }
        }
    }
    (*c, oh, ow, o)
}

fn naive(t: &Tensors, a: &Image, b: &Image) -> f64 {
    let feats = |img: &Image| -> Vec<Fm> {
        let (w, h) = (img.width(), img.height());
        let mut v = vec![0.0; 3 * w * h];
        for y in 0..h {
            for x in 0..w {
                let p = img.pixel(x, y);
                for c in 0..3 {
                    let s = 2.0 * p[c] as f64 - 1.0;
                    v[(c * h + y) * w + x] = (s - SHIFT[c] as f64) / SCALE[c] as f64;
                }
            }
        }
        let mut x: Fm = (3, h, w, v);
        let mut out = vec![];
        for (k, (stride, pad, do_pool)) in LAYERS.iter().enumerate() {
            if *do_pool {
                x = pool(&x);
            }
            let (wd, wv) = &t[&format!("conv{}.weight", k + 1)];
            let (_, bv) = &t[&format!("conv{}.bias", k + 1)];
            x = conv(&x, wv, bv, wd[0], wd[2], *stride, *pad);
            out.push(x.clone());
        }
        out
    };
    let (fa, fb) = (feats(a), feats(b));
    let mut total = 0.0;
    for (k, (x, y)) in fa.iter().zip(&fb).enumerate() {
        let (c, h, w) = (x.0, x.1, x.2);
        let lin = &t[&format!("lin{k}.weight")].1;
        let mut s = 0.0;
        for p in 0..h * w {
            let nx: f64 = (0..c).map(|ch| x.3[ch * h * w + p].powi(2)).sum::<f64>().sqrt() + 1e-10;
            let ny: f64 = (0..c).map(|ch| y.3[ch * h * w + p].powi(2)).sum::<f64>().sqrt() + 1e-10;
            for ch in 0..c {
                let d = x.3[ch * h * w + p] / nx - y.3[ch * h * w + p] / ny;
                s += lin[ch] as f64 * d * d;
            }
        }
        total += s / (h * w) as f64;
    }
    total
}

fn random_weights(channels: [usize; 5], seed: u64) -> Tensors {
    let mut s = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
    let mut next = move || {
        s = s.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        ((s >> 40) as f32 / (1u64 << 24) as f32) - 0.5
    };
    let ks = [11, 5, 3, 3, 3];
    let mut t = Tensors::new();
    let mut cin = 3;
    for k in 0..5 {
        let c = channels[k];
        let n = c * cin * ks[k] * ks[k];
        let scale = 1.0 / ((cin * ks[k] * ks[k]) as f32).sqrt();
        t.insert(
            format!("conv{}.weight", k + 1),
            (vec![c, cin, ks[k], ks[k]], (0..n).map(|_| 2.0 * scale * next()).collect()),
        );
        t.insert(
            format!("conv{}.bias", k + 1),
            (vec![c], (0..c).map(|_| 0.2 * next() + 0.05).collect()),
        );
        t.insert(
            format!("lin{k}.weight"),
            (vec![1, c, 1, 1], (0..c).map(|_| next() + 0.5).collect()),
        );
        cin = c;
    }
    t
}

#[test]
fn matches_direct_evaluation_on_random_weights() {
    let t = random_weights([6, 7, 8, 5, 4], 3);
    let net = Lpips::from_tensors(&t, &Device::default()).unwrap();
    let (a, b) = ldr_pair(47, 43, 5);
    let got = net.distance(&a, &b).unwrap();
    let want = naive(&t, &a, &b);
    assert!(want > 1e-3, "degenerate test: {want}");
    assert!((got - want).abs() <= 1e-4 * want, "burn {got} vs direct {want}");
    assert!(net.distance(&a, &a).unwrap().abs() < 1e-9);
}

#[test]
fn missing_weights_are_reported_not_invented() {
    let (a, b) = ldr_pair(40, 40, 1);
    let p = std::path::Path::new("/nonexistent/alex_v0.1.lpipsw");
    let s = crate::lpips::lpips_score(&a, &b, p).unwrap();
    assert_eq!(s.to_string(), "n/a (weights missing)");
    let mut t = random_weights([2, 2, 2, 2, 2], 1);
    t.remove("lin3.weight");
    assert!(Lpips::from_tensors(&t, &Device::default()).unwrap_err().contains("lin3.weight"));
}
