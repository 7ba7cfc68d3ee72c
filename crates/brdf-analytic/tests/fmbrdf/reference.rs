//! Test-side helpers for the FMBRDF tests: the shared JSON weights, the converter to the crate's
//! binary format, and an independent f64 evaluation written directly from the spec's addendum
//! (literal trigonometric frame rotations, plain MLP loops over the JSON tensors, the
//! normalisation integral by its own quadrature).

use serde_json::Value;
use std::collections::HashMap;
use std::f64::consts::{FRAC_PI_2, PI};
use std::path::{Path, PathBuf};

/// The shared FMBRDF data folder (`$NEURAL_BRDF_DATA/fmbrdf`, default
/// `<workspace root>/../shared/data/fmbrdf`), or `None` (with a notice) when it is missing.
/// With `CI=true` a missing folder is a failure.
pub fn shared_fmbrdf_dir() -> Option<PathBuf> {
    let root = match std::env::var_os("NEURAL_BRDF_DATA") {
        Some(d) => PathBuf::from(d),
        None => Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"),
    };
    let dir = root.join("fmbrdf");
    if dir.join("shadowing.json").is_file() && dir.join("body_reflection.json").is_file() {
        return Some(dir);
    }
    let msg = format!(
        "FMBRDF shared data not found at {} (set NEURAL_BRDF_DATA to the folder holding fmbrdf/)",
        dir.display()
    );
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        panic!("{msg}; it is required when CI=true");
    }
    eprintln!("SKIPPED: {msg}");
    None
}

/// A tensor from the JSON: shape and values (f64, each exactly a float32).
pub struct JsonTensor {
    pub shape: Vec<usize>,
    pub data: Vec<f64>,
}

/// All tensors of one JSON file.
///
/// serde_json (without its `float_roundtrip` feature) may parse a decimal 1 ulp off, so the values
/// are re-read from the raw text with Rust's correctly rounded `str::parse::<f64>`; serde_json
/// provides the structure (names, shapes, value counts) and a cross-check.
pub fn load_json(path: &Path) -> HashMap<String, JsonTensor> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let v: Value = serde_json::from_str(&text).expect("valid JSON");
    let obj = v.as_object().expect("top-level object");
    obj.iter()
        .map(|(k, t)| {
            let shape = t["shape"].as_array().unwrap().iter().map(|d| d.as_u64().unwrap() as usize);
            let approx = t["data"].as_array().unwrap();
            let data = raw_data(&text, k);
            assert_eq!(data.len(), approx.len(), "{k}");
            for (x, a) in data.iter().zip(approx) {
                assert!((x - a.as_f64().unwrap()).abs() <= 1e-15 * x.abs(), "{k}: {x} vs {a}");
            }
            (k.clone(), JsonTensor { shape: shape.collect(), data })
        })
        .collect()
}

/// The numbers of the `"data"` array of tensor `key`, parsed from the raw JSON text.
fn raw_data(text: &str, key: &str) -> Vec<f64> {
    let quoted = format!("\"{key}\"");
    let at = text.find(&quoted).unwrap_or_else(|| panic!("{key} not in the JSON text"));
    let rest = &text[at + quoted.len()..];
    let data = rest.find("\"data\"").expect("data field");
    let rest = &rest[data..];
    let open = rest.find('[').expect("data array");
    let close = rest.find(']').expect("end of data array");
    rest[open + 1..close]
        .split(',')
        .map(|x| x.trim().parse::<f64>().unwrap_or_else(|e| panic!("{key}: {x:?}: {e}")))
        .collect()
}

/// The tensors the crate ships, in file order: (json file stem, state-dict key).
pub fn shipped_tensor_keys() -> Vec<(&'static str, String)> {
    let mut keys = Vec::new();
    for (stem, layer) in [("shadowing", "fc"), ("body_reflection", "fc_I")] {
        for i in 1..=4 {
            for kind in ["weight", "bias"] {
                keys.push((stem, format!("{layer}{i}.{kind}")));
            }
        }
    }
    keys
}

/// The converter: the crate's binary weight file built from the shared JSON (format in
/// `assets/fmbrdf/NOTICE.md`). Panics if a JSON value is not exactly a float32.
pub fn encode_weights(dir: &Path) -> Vec<u8> {
    let files: HashMap<&str, _> = ["shadowing", "body_reflection"]
        .into_iter()
        .map(|stem| (stem, load_json(&dir.join(format!("{stem}.json")))))
        .collect();
    let keys = shipped_tensor_keys();
    let mut out = b"FMBRDFW1".to_vec();
    let u32le = |out: &mut Vec<u8>, x: usize| out.extend(u32::try_from(x).unwrap().to_le_bytes());
    u32le(&mut out, keys.len());
    for (stem, key) in keys {
        let t = &files[stem][&key];
        let name = format!("{stem}.{key}");
        u32le(&mut out, name.len());
        out.extend(name.as_bytes());
        u32le(&mut out, t.shape.len());
        for &d in &t.shape {
            u32le(&mut out, d);
        }
        assert_eq!(t.data.len(), t.shape.iter().product::<usize>(), "{name}");
        for &x in &t.data {
            let f = x as f32;
            assert_eq!(f as f64, x, "{name}: {x} is not a float32 value");
            out.extend(f.to_le_bytes());
        }
    }
    out
}

/// A plain MLP: (weight [out, in] row-major, bias) per layer.
pub struct Mlp(Vec<(Vec<Vec<f64>>, Vec<f64>)>);

impl Mlp {
    fn from_json(t: &HashMap<String, JsonTensor>, prefix: &str) -> Self {
        Self(
            (1..=4)
                .map(|i| {
                    let w = &t[&format!("{prefix}{i}.weight")];
                    let rows = w.data.chunks(w.shape[1]).map(<[f64]>::to_vec).collect();
                    (rows, t[&format!("{prefix}{i}.bias")].data.clone())
                })
                .collect(),
        )
    }

    /// Forward pass: ReLU between layers, `last` on the output.
    fn forward(&self, x: &[f64], last: impl Fn(f64) -> f64) -> f64 {
        let mut h = x.to_vec();
        for (i, (w, b)) in self.0.iter().enumerate() {
            assert_eq!(w[0].len(), h.len());
            h = w
                .iter()
                .zip(b)
                .map(|(row, b)| {
                    let s = row.iter().zip(&h).map(|(a, x)| a * x).sum::<f64>() + b;
                    if i + 1 < self.0.len() { s.max(0.0) } else { last(s) }
                })
                .collect();
        }
        h[0]
    }
}

/// Both helper networks, read from the shared JSON.
pub struct RefNets {
    lambda: Mlp,
    body: Mlp,
}

impl RefNets {
    pub fn load(dir: &Path) -> Self {
        let s = load_json(&dir.join("shadowing.json"));
        let b = load_json(&dir.join("body_reflection.json"));
        Self { lambda: Mlp::from_json(&s, "fc"), body: Mlp::from_json(&b, "fc_I") }
    }
}

/// 1/c = 2 pi int_0^{pi/2} exp(-(t/alpha)^beta) cos t sin t dt, by composite Simpson on panels
/// graded geometrically towards 0 ([2^-(k+1), 2^-k] of the range, k = 0..59, 128 intervals
/// each), the range cut where exp(-(t/alpha)^beta) < e^-60.
pub fn inv_c_graded(alpha: f64, beta: f64) -> f64 {
    let f = |t: f64| (-(t / alpha).powf(beta)).exp() * t.cos() * t.sin();
    let top = (alpha * 60f64.powf(1.0 / beta)).min(FRAC_PI_2);
    let simpson = |a: f64, b: f64, n: usize| {
        let h = (b - a) / n as f64;
        let inner: f64 =
            (1..n).map(|k| if k % 2 == 1 { 4.0 } else { 2.0 } * f(a + k as f64 * h)).sum();
        (f(a) + f(b) + inner) * h / 3.0
    };
    let mut sum = 0.0;
    for k in 0..60 {
        let hi = top * 0.5f64.powi(k);
        sum += simpson(hi * 0.5, hi, 128);
    }
    2.0 * PI * sum
}

/// The official code's c: a rectangle sum over `steps` equally spaced angles on [0, pi/2].
pub fn inv_c_official(alpha: f64, beta: f64, steps: usize) -> f64 {
    let d = FRAC_PI_2 / (steps - 1) as f64;
    let sum: f64 = (0..steps)
        .map(|k| {
            let t = k as f64 * d;
            (-(t / alpha).powf(beta)).exp() * t.cos() * t.sin() * d
        })
        .sum();
    2.0 * PI * sum
}

/// FMBRDF parameters for the reference.
#[derive(Clone, Copy, Debug)]
pub struct RefParams {
    pub eta: f64,
    pub rho: [f64; 3],
    pub k_s: f64,
    pub alpha: f64,
    pub beta: f64,
    pub kappa: f64,
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn mat_vec(m: [[f64; 3]; 3], x: [f64; 3]) -> [f64; 3] {
    [dot(m[0], x), dot(m[1], x), dot(m[2], x)]
}

fn mat_mul(a: [[f64; 3]; 3], b: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut m = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    m
}

/// Right-handed rotation by `t` about axis 0 (x), 1 (y) or 2 (z).
fn rot(axis: usize, t: f64) -> [[f64; 3]; 3] {
    let (s, c) = t.sin_cos();
    let mut m = [[0.0; 3]; 3];
    let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
    m[axis][axis] = 1.0;
    m[i][i] = c;
    m[i][j] = -s;
    m[j][i] = s;
    m[j][j] = c;
    m
}

/// The addendum's f(l, v) in f64 for the local frame (n = +z), with `inv_c` = 1/c given.
pub fn reference_eval(
    nets: &RefNets,
    p: &RefParams,
    inv_c: f64,
    l: [f64; 3],
    v: [f64; 3],
) -> [f64; 3] {
    let n = [0.0, 0.0, 1.0];
    if !(dot(n, l) > 0.0 && dot(n, v) > 0.0) {
        return [0.0; 3];
    }
    // Smith: theta = arccos(clamp(n.w, 1e-6, 1 - 1e-6)), input (alpha, beta, tan, alpha tan).
    let lambda = |w: [f64; 3]| {
        let theta = dot(n, w).clamp(1e-6, 1.0 - 1e-6).acos();
        let t = theta.tan();
        nets.lambda.forward(&[p.alpha, p.beta, t, p.alpha * t], |s| s.max(0.0))
    };
    let g = 1.0 / ((1.0 + lambda(l)) * (1.0 + lambda(v)));

    // Frame 1: u = -v onto +z, R = Rx(-rot_x) Ry(-rot_y).
    let u = [-v[0], -v[1], -v[2]];
    let rot_y = u[0].atan2(u[2]);
    let rot_x = -(u[1].asin());
    let r1 = mat_mul(rot(0, -rot_x), rot(1, -rot_y));
    let (n1, l1, v1) = (mat_vec(r1, n), mat_vec(r1, l), mat_vec(r1, v));

    // Specular in that frame.
    let s = [l1[0] + v1[0], l1[1] + v1[1], l1[2] + v1[2]];
    let len = dot(s, s).sqrt();
    let h = [s[0] / len, s[1] / len, s[2] / len];
    let cos_na = dot(n1, h).clamp(0.0, 1.0 - 1e-6);
    let theta_h = cos_na.acos();
    let dist = (-(theta_h / p.alpha).powf(p.beta)).exp() * cos_na / inv_c;
    let a = 1.0 / p.eta;
    let cos_r = dot(v1, h).clamp(0.0, 1.0 - 1e-6);
    let sin_r = (1.0 - cos_r * cos_r).sqrt();
    let sin_t = (a * sin_r).clamp(0.0, 1.0 - 1e-6);
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let rs = (a * cos_r - cos_t) / (a * cos_r + cos_t + 1e-9);
    let rp = -(a * cos_t - cos_r) / (a * cos_t + cos_r + 1e-9);
    let fresnel = (rs * rs + rp * rp) / 2.0;
    let cos_nv = dot(n1, v1).clamp(0.0, 1.0);
    let cos_nh = dot(n1, h).clamp(0.0, 1.0);
    let i_s = p.k_s * dist * fresnel / (4.0 * cos_nv * cos_nh + 1e-9);

    // Frame 2: about z by -atan2(l'_y, l'_x).
    let r2 = rot(2, -(l1[1].atan2(l1[0])));
    let (n2, l2) = (mat_vec(r2, n1), mat_vec(r2, l1));
    let x =
        [n2[0], n2[1], n2[2], l2[0], l2[1], l2[2], p.eta, p.alpha, p.beta, p.kappa, dot(n2, l2)];
    let i_b = nets.body.forward(&x, |s| (1.0 + s.exp()).ln());

    // BRDF = G (I_s + rho I_b) / cos(theta_l), with the official MERL conversion's guard.
    let cos_l = dot(n, l).clamp(0.0, 1.0);
    p.rho.map(|r| g * (i_s + r * i_b) / (cos_l + 1e-9))
}
