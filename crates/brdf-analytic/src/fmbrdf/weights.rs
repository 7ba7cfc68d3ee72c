//! The shipped weights of the two FMBRDF helper networks: parsing of the crate's compact binary
//! copy (`assets/fmbrdf/fmbrdf_weights.bin`, format in `assets/fmbrdf/NOTICE.md`), done once per
//! process, into contiguous row-major f32 layers.
//!
//! Weights: MIT, Copyright (c) 2023 kyotovision-public (repository kyotovision-public/fmbrdf),
//! converted unchanged; see `assets/fmbrdf/LICENSE`.

use std::sync::OnceLock;

/// The embedded weight file.
static BYTES: &[u8] = include_bytes!("../../assets/fmbrdf/fmbrdf_weights.bin");

/// The embedded weight file as shipped (`assets/fmbrdf/fmbrdf_weights.bin`), for tools outside
/// Rust that evaluate the helper networks themselves (the Python package's Mitsuba plugin).
pub fn file_bytes() -> &'static [u8] {
    BYTES
}

/// Magic number at the start of the weight file.
const MAGIC: &[u8; 8] = b"FMBRDFW1";

/// The tensors the file must hold, in file order, with their PyTorch shapes.
pub(crate) const TENSORS: [(&str, &[usize]); 16] = [
    ("shadowing.fc1.weight", &[300, 4]),
    ("shadowing.fc1.bias", &[300]),
    ("shadowing.fc2.weight", &[100, 300]),
    ("shadowing.fc2.bias", &[100]),
    ("shadowing.fc3.weight", &[50, 100]),
    ("shadowing.fc3.bias", &[50]),
    ("shadowing.fc4.weight", &[1, 50]),
    ("shadowing.fc4.bias", &[1]),
    ("body_reflection.fc_I1.weight", &[200, 11]),
    ("body_reflection.fc_I1.bias", &[200]),
    ("body_reflection.fc_I2.weight", &[100, 200]),
    ("body_reflection.fc_I2.bias", &[100]),
    ("body_reflection.fc_I3.weight", &[100, 100]),
    ("body_reflection.fc_I3.bias", &[100]),
    ("body_reflection.fc_I4.weight", &[1, 100]),
    ("body_reflection.fc_I4.bias", &[1]),
];

/// One dense layer y = W x + b, with W kept transposed: `wt` is [in, out] row-major, so column
/// `i` of W (the weights multiplying input `i`) is contiguous at `i * n_out`.
#[derive(Debug)]
pub(crate) struct Layer {
    /// W transposed, `n_in * n_out` values; W[o][i] is `wt[i * n_out + o]`.
    pub wt: Vec<f32>,
    /// Biases, `n_out` values.
    pub b: Vec<f32>,
    /// Input width.
    pub n_in: usize,
    /// Output width.
    pub n_out: usize,
}

/// All shipped tensors, parsed.
#[derive(Debug)]
pub(crate) struct Weights {
    /// Smith Lambda network fc1..fc4 (4 -> 300 -> 100 -> 50 -> 1).
    pub lambda: [Layer; 4],
    /// Body-reflection intensity branch fc_I1..fc_I4 (11 -> 200 -> 100 -> 100 -> 1).
    pub body: [Layer; 4],
    /// Every tensor as stored: (name, shape, values), in file order.
    pub raw: Vec<(&'static str, &'static [usize], Vec<f32>)>,
}

/// The parsed weights, decoded on first use.
pub(crate) fn weights() -> &'static Weights {
    static W: OnceLock<Weights> = OnceLock::new();
    // The embedded file is fixed at compile time and checked by the tests, so this cannot fail.
    W.get_or_init(|| parse(BYTES).expect("embedded FMBRDF weight file is malformed"))
}

/// A little-endian reader over a byte slice.
struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.bytes.len());
        let end = end.ok_or_else(|| format!("truncated at byte {}", self.pos))?;
        let s = &self.bytes[self.pos..end];
        self.pos = end;
        Ok(s)
    }

    fn u32(&mut self) -> Result<usize, String> {
        let b = self.take(4)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
    }
}

/// Parses and validates a weight file (names, shapes and order as in [`TENSORS`]).
pub(crate) fn parse(bytes: &[u8]) -> Result<Weights, String> {
    let mut r = Reader { bytes, pos: 0 };
    if r.take(MAGIC.len())? != MAGIC {
        return Err("bad magic".into());
    }
    let count = r.u32()?;
    if count != TENSORS.len() {
        return Err(format!("expected {} tensors, found {count}", TENSORS.len()));
    }
    let mut raw = Vec::with_capacity(count);
    for &(name, shape) in &TENSORS {
        let name_len = r.u32()?;
        let found = r.take(name_len)?;
        if found != name.as_bytes() {
            return Err(format!(
                "expected tensor {name}, found {}",
                String::from_utf8_lossy(found)
            ));
        }
        let ndim = r.u32()?;
        let dims = (0..ndim).map(|_| r.u32()).collect::<Result<Vec<_>, _>>()?;
        if dims != shape {
            return Err(format!("tensor {name}: shape {dims:?}, expected {shape:?}"));
        }
        let n: usize = shape.iter().product();
        let data = r.take(4 * n)?;
        let values = data
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect::<Vec<_>>();
        if values.iter().any(|x| !x.is_finite()) {
            return Err(format!("tensor {name} holds a non-finite value"));
        }
        raw.push((name, shape, values));
    }
    if r.pos != bytes.len() {
        return Err(format!("{} trailing bytes", bytes.len() - r.pos));
    }
    let layer = |i: usize| {
        let (_, shape, w) = &raw[2 * i];
        let (_, _, b) = &raw[2 * i + 1];
        let (n_out, n_in) = (shape[0], shape[1]);
        let wt = (0..n_in * n_out).map(|k| w[(k % n_out) * n_in + k / n_out]).collect();
        Layer { wt, b: b.clone(), n_in, n_out }
    };
    let lambda = [layer(0), layer(1), layer(2), layer(3)];
    let body = [layer(4), layer(5), layer(6), layer(7)];
    Ok(Weights { lambda, body, raw })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn embedded_file_parses_with_expected_shapes() {
        let w = weights();
        let widths = |ls: &[Layer; 4]| ls.iter().map(|l| (l.n_in, l.n_out)).collect::<Vec<_>>();
        assert_eq!(widths(&w.lambda), [(4, 300), (300, 100), (100, 50), (50, 1)]);
        assert_eq!(widths(&w.body), [(11, 200), (200, 100), (100, 100), (100, 1)]);
        for l in w.lambda.iter().chain(&w.body) {
            assert_eq!(l.wt.len(), l.n_in * l.n_out);
            assert_eq!(l.b.len(), l.n_out);
        }
        assert_eq!(w.raw.len(), 16);
        // The transposition: W[o][i] of fc2 (row-major in the file) is wt[i * n_out + o].
        let (l, raw) = (&w.lambda[1], &w.raw[2].2);
        for (o, i) in [(0, 0), (3, 7), (99, 299), (42, 150)] {
            assert_eq!(l.wt[i * l.n_out + o], raw[o * l.n_in + i]);
        }
    }

    #[test]
    fn corrupt_files_are_rejected() {
        assert!(parse(&BYTES[..BYTES.len() - 1]).is_err());
        let mut extra = BYTES.to_vec();
        extra.push(0);
        assert!(parse(&extra).is_err());
        let mut bad = BYTES.to_vec();
        bad[0] = b'X';
        assert!(parse(&bad).is_err());
        // A NaN in the first weight (after magic, count, name length, name, ndim and two dims).
        let mut nan = BYTES.to_vec();
        let first = 8 + 4 + 4 + "shadowing.fc1.weight".len() + 4 + 8;
        nan[first..first + 4].copy_from_slice(&f32::NAN.to_le_bytes());
        assert!(parse(&nan).is_err());
        assert!(parse(BYTES).is_ok());
    }
}
