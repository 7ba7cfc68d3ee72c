//! A small reader (and writer) of MATLAB v5 MAT files, for what DiLiGenT ships: the normal map
//! `Normal_gt.mat` (a compressed 3-D double array) and the camera calibration
//! `Calib_Results.mat` of the Caltech toolbox (KK, Rc_i, Tc_i doubles among many others).
//!
//! Format (MathWorks, "MAT-File Format", v5/v7): a 128-byte header (text, subsystem offset,
//! version 0x0100, endian indicator "IM" for little endian or "MI" for big endian), then data
//! elements, each an 8-byte tag (type, byte count; or the 4-byte "small element" form) and its
//! data padded to 8 bytes. A variable is an `miMATRIX` element (array flags with the class,
//! dimensions, name, real part, optional imaginary part), possibly wrapped in an `miCOMPRESSED`
//! element holding a zlib stream. Numeric data may be stored in a narrower type than its class
//! (MATLAB saves integral doubles as `miUINT8`, for example); the reader widens it to f64.
//!
//! Supported: every numeric class (double, single, (u)int8..64) and logical arrays, real, N-D,
//! compressed or not, either byte order. Cell, struct, object, char and sparse variables are
//! listed with their class and no data (DiLiGenT's calibration files hold strings and cells that
//! the importer does not need). MATLAB 7.3 files (HDF5) are rejected with a clear message.
//!
//! Data is kept in MATLAB's column-major order; [`MatVariable::index`] and
//! [`MatFile::matrix`] convert.
//! The crate's [`write_mat5`] writes double variables, so tests can build calibration files.

use crate::error::{Error, Result};
use std::path::{Path, PathBuf};
use stdx::Limits;

/// The class of a MATLAB array.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MatClass {
    /// A numeric (or logical) array; its data is widened to f64.
    Numeric(NumericClass),
    /// A cell array (not decoded).
    Cell,
    /// A struct (not decoded).
    Struct,
    /// An object (not decoded).
    Object,
    /// A character array (not decoded).
    Char,
    /// A sparse matrix (not decoded).
    Sparse,
    /// A class code this reader does not know.
    Unknown(u8),
}

/// The numeric classes of MATLAB.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum NumericClass {
    Double,
    Single,
    Int8,
    Uint8,
    Int16,
    Uint16,
    Int32,
    Uint32,
    Int64,
    Uint64,
}

impl MatClass {
    fn from_code(code: u8) -> Self {
        use NumericClass::*;
        match code {
            1 => Self::Cell,
            2 => Self::Struct,
            3 => Self::Object,
            4 => Self::Char,
            5 => Self::Sparse,
            6 => Self::Numeric(Double),
            7 => Self::Numeric(Single),
            8 => Self::Numeric(Int8),
            9 => Self::Numeric(Uint8),
            10 => Self::Numeric(Int16),
            11 => Self::Numeric(Uint16),
            12 => Self::Numeric(Int32),
            13 => Self::Numeric(Uint32),
            14 => Self::Numeric(Int64),
            15 => Self::Numeric(Uint64),
            c => Self::Unknown(c),
        }
    }
}

/// One variable of a MAT file.
#[derive(Clone, Debug, PartialEq)]
pub struct MatVariable {
    /// The variable's name.
    pub name: String,
    /// Its class.
    pub class: MatClass,
    /// Whether MATLAB flagged it logical.
    pub logical: bool,
    /// Dimensions (at least two, as MATLAB stores them).
    pub dims: Vec<usize>,
    /// Real part of a numeric array, column-major, widened to f64; `None` for other classes.
    pub data: Option<Vec<f64>>,
}

impl MatVariable {
    /// The column-major position of a multi-index (as many indices as dimensions, 0-based), or
    /// `None` when out of range or of the wrong length.
    pub fn index(&self, idx: &[usize]) -> Option<usize> {
        if idx.len() != self.dims.len() {
            return None;
        }
        let (mut pos, mut stride) = (0, 1);
        for (&i, &d) in idx.iter().zip(&self.dims) {
            if i >= d {
                return None;
            }
            pos += i * stride;
            stride *= d;
        }
        Some(pos)
    }

    /// The value at a multi-index, see [`MatVariable::index`].
    pub fn at(&self, idx: &[usize]) -> Option<f64> {
        Some(self.data.as_ref()?[self.index(idx)?])
    }

    /// The dimensions as text, for example "512 x 612 x 3".
    pub fn shape(&self) -> String {
        self.dims.iter().map(|d| d.to_string()).collect::<Vec<_>>().join(" x ")
    }
}

/// A parsed MAT file.
#[derive(Clone, Debug)]
pub struct MatFile {
    /// Where it was read from (for messages).
    pub path: PathBuf,
    /// Its variables, in file order.
    pub variables: Vec<MatVariable>,
}

// Data types of elements.
const MI_INT8: u32 = 1;
const MI_UINT8: u32 = 2;
const MI_INT16: u32 = 3;
const MI_UINT16: u32 = 4;
const MI_INT32: u32 = 5;
const MI_UINT32: u32 = 6;
const MI_SINGLE: u32 = 7;
const MI_DOUBLE: u32 = 9;
const MI_INT64: u32 = 12;
const MI_UINT64: u32 = 13;
const MI_MATRIX: u32 = 14;
const MI_COMPRESSED: u32 = 15;
const MI_UTF8: u32 = 16;

struct Reader<'a> {
    path: &'a Path,
    big_endian: bool,
    /// A compressed variable inflates to at most `limits.max_alloc` bytes (a guard against
    /// corrupt length fields).
    limits: &'a Limits,
}

/// One element: its type and data bytes, and the offset just past it.
struct Element<'b> {
    ty: u32,
    data: &'b [u8],
    next: usize,
}

impl Reader<'_> {
    fn fault(&self, fault: impl Into<String>) -> Error {
        Error::Mat { path: self.path.into(), fault: fault.into() }
    }

    /// Inflates a compressed variable (a zlib stream holding one miMATRIX element) no further
    /// than the size its own tag declares: the first 8 bytes are inflated alone, and the rest
    /// is limited to that size (at most the limits' `max_alloc`), so a zlib bomb allocates no more
    /// than its tag admits (and the matrix parser checks that against the declared shape).
    fn inflate(&self, data: &[u8], at: usize) -> Result<Vec<u8>> {
        use miniz_oxide::inflate::{TINFLStatus, decompress_to_vec_zlib_with_limit};
        let fault =
            |f: String| Error::input(self.path, format!("compressed variable at byte {at}: {f}"));
        let head = match decompress_to_vec_zlib_with_limit(data, 8) {
            Ok(v) => v,
            Err(e) if e.status == TINFLStatus::HasMoreOutput => e.output,
            Err(e) => return Err(fault(format!("zlib error {:?}", e.status))),
        };
        if head.len() < 8 {
            return Err(fault(format!("{} bytes inflated, no element tag", head.len())));
        }
        let declared = self.u32_at(&head, 4)? as usize;
        let limit = 8 + declared.next_multiple_of(8);
        self.limits.check_alloc(declared as u64, "its tag").map_err(fault)?;
        // The whole stream, checksum included, within the declared size.
        decompress_to_vec_zlib_with_limit(data, limit).map_err(|e| match e.status {
            TINFLStatus::HasMoreOutput => fault(format!(
                "the zlib stream inflates beyond the {declared} bytes its tag declares"
            )),
            status => fault(format!("zlib error {status:?}")),
        })
    }

    fn u32_at(&self, b: &[u8], at: usize) -> Result<u32> {
        let s: [u8; 4] = b
            .get(at..at + 4)
            .and_then(|s| s.try_into().ok())
            .ok_or_else(|| self.fault(format!("truncated at byte {at}")))?;
        Ok(if self.big_endian { u32::from_be_bytes(s) } else { u32::from_le_bytes(s) })
    }

    /// The element starting at `at` in `b`.
    fn element<'b>(&self, b: &'b [u8], at: usize) -> Result<Element<'b>> {
        let first = self.u32_at(b, at)?;
        let (ty, len, start, padded) = if first >> 16 != 0 {
            // Small data element: length in the upper half, data in the next 4 bytes.
            (first & 0xffff, (first >> 16) as usize, at + 4, 4)
        } else {
            let len = self.u32_at(b, at + 4)? as usize;
            let padded = if first == MI_COMPRESSED { len } else { len.div_ceil(8) * 8 };
            (first, len, at + 8, padded)
        };
        if len > 4 && first >> 16 != 0 {
            return Err(self.fault(format!("small element at byte {at} claims {len} bytes")));
        }
        let data = b.get(start..start + len).ok_or_else(|| {
            self.fault(format!(
                "element at byte {at} (type {ty}) claims {len} bytes, {} are left",
                b.len().saturating_sub(start)
            ))
        })?;
        Ok(Element { ty, data, next: (start + padded).min(b.len()) })
    }

    /// Widens numeric element data to f64.
    fn numbers(&self, ty: u32, d: &[u8]) -> Result<Vec<f64>> {
        macro_rules! widen {
            ($t:ty, $n:expr) => {
                d.chunks_exact($n)
                    .map(|c| {
                        let a: [u8; $n] = c.try_into().unwrap();
                        let v = if self.big_endian {
                            <$t>::from_be_bytes(a)
                        } else {
                            <$t>::from_le_bytes(a)
                        };
                        v as f64
                    })
                    .collect()
            };
        }
        let size = match ty {
            MI_INT8 | MI_UINT8 | MI_UTF8 => 1,
            MI_INT16 | MI_UINT16 => 2,
            MI_INT32 | MI_UINT32 | MI_SINGLE => 4,
            MI_DOUBLE | MI_INT64 | MI_UINT64 => 8,
            t => return Err(self.fault(format!("numeric data of unsupported type {t}"))),
        };
        if !d.len().is_multiple_of(size) {
            return Err(self.fault(format!("{} bytes of type {ty} is not whole values", d.len())));
        }
        Ok(match ty {
            MI_INT8 => d.iter().map(|&x| x as i8 as f64).collect(),
            MI_UINT8 | MI_UTF8 => d.iter().map(|&x| x as f64).collect(),
            MI_INT16 => widen!(i16, 2),
            MI_UINT16 => widen!(u16, 2),
            MI_INT32 => widen!(i32, 4),
            MI_UINT32 => widen!(u32, 4),
            MI_SINGLE => widen!(f32, 4),
            MI_DOUBLE => widen!(f64, 8),
            MI_INT64 => widen!(i64, 8),
            _ => widen!(u64, 8),
        })
    }

    /// Parses the contents of an `miMATRIX` element.
    fn matrix(&self, b: &[u8]) -> Result<MatVariable> {
        let flags = self.element(b, 0)?;
        if flags.ty != MI_UINT32 || flags.data.len() != 8 {
            return Err(self.fault("array flags are not 8 bytes of miUINT32"));
        }
        let w0 = self.u32_at(flags.data, 0)?;
        let class = MatClass::from_code((w0 & 0xff) as u8);
        let (complex, logical) = (w0 & 0x800 != 0, w0 & 0x200 != 0);
        let dims_el = self.element(b, flags.next)?;
        if dims_el.ty != MI_INT32 {
            return Err(self.fault(format!("dimensions of type {}, expected miINT32", dims_el.ty)));
        }
        let dims: Vec<usize> = self
            .numbers(MI_INT32, dims_el.data)?
            .into_iter()
            .map(|d| if d >= 0.0 { Ok(d as usize) } else { Err(self.fault("negative dimension")) })
            .collect::<Result<_>>()?;
        let name_el = self.element(b, dims_el.next)?;
        let name = String::from_utf8_lossy(name_el.data).into_owned();
        let mut var = MatVariable { name, class, logical, dims, data: None };
        if let MatClass::Numeric(_) = class {
            let count =
                var.dims.iter().try_fold(1usize, |a, &d| a.checked_mul(d)).ok_or_else(|| {
                    self.fault(format!("variable `{}` dimensions overflow", var.name))
                })?;
            let re = self.element(b, name_el.next)?;
            let data = self.numbers(re.ty, re.data)?;
            if data.len() != count {
                return Err(self.fault(format!(
                    "variable `{}` ({}) holds {} values, its dimensions need {count}",
                    var.name,
                    var.shape(),
                    data.len()
                )));
            }
            if complex {
                return Err(self.fault(format!(
                    "variable `{}` is complex; only real arrays are supported",
                    var.name
                )));
            }
            var.data = Some(data);
        }
        Ok(var)
    }
}

impl MatFile {
    /// Reads and parses a MAT file within `limits`.
    pub fn read(path: &Path, limits: &Limits) -> Result<Self> {
        let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
        Self::parse(&bytes, path, limits)
    }

    /// Parses MAT file bytes within `limits`; `path` names them in messages.
    pub fn parse(bytes: &[u8], path: &Path, limits: &Limits) -> Result<Self> {
        let fault = |f: String| Error::Mat { path: path.into(), fault: f };
        if bytes.len() < 128 {
            return Err(fault(format!("{} bytes, shorter than the 128-byte header", bytes.len())));
        }
        let text = String::from_utf8_lossy(&bytes[..116]);
        if text.starts_with("MATLAB 7.3") {
            return Err(fault(
                "MATLAB 7.3 (HDF5) files are not supported; save with `-v7`".to_string(),
            ));
        }
        let big_endian = match &bytes[126..128] {
            b"IM" => false,
            b"MI" => true,
            other => {
                return Err(fault(format!(
                    "endian indicator {other:?} is neither \"IM\" nor \"MI\" (not a v5 MAT file)"
                )));
            }
        };
        let r = Reader { path, big_endian, limits };
        let version = if big_endian {
            u16::from_be_bytes([bytes[124], bytes[125]])
        } else {
            u16::from_le_bytes([bytes[124], bytes[125]])
        };
        if version != 0x0100 {
            return Err(fault(format!("version 0x{version:04x}, expected 0x0100 (v5)")));
        }
        let mut variables = Vec::new();
        let mut at = 128;
        while at + 8 <= bytes.len() {
            let el = r.element(bytes, at)?;
            match el.ty {
                MI_MATRIX => variables.push(r.matrix(el.data)?),
                MI_COMPRESSED => {
                    let inflated = r.inflate(el.data, at)?;
                    let inner = r.element(&inflated, 0)?;
                    if inner.ty != MI_MATRIX {
                        return Err(fault(format!(
                            "compressed element at byte {at} holds type {}, expected miMATRIX",
                            inner.ty
                        )));
                    }
                    variables.push(r.matrix(inner.data)?);
                }
                _ => {} // Other top-level elements carry no variables.
            }
            at = el.next;
        }
        Ok(Self { path: path.into(), variables })
    }

    /// The variable called `name`.
    pub fn get(&self, name: &str) -> Option<&MatVariable> {
        self.variables.iter().find(|v| v.name == name)
    }

    /// The numeric variable called `name` (the first of `names` that exists).
    ///
    /// # Errors
    /// [`Error::Mat`] naming the variable when none exists or it is not numeric.
    pub fn numeric(&self, names: &[&str]) -> Result<&MatVariable> {
        let fault = |f: String| Error::Mat { path: self.path.clone(), fault: f };
        let v = names
            .iter()
            .find_map(|n| self.get(n))
            .ok_or_else(|| fault(format!("no variable `{}`", names.join("` or `"))))?;
        match (&v.class, &v.data) {
            (MatClass::Numeric(_), Some(_)) => Ok(v),
            (c, _) => {
                Err(fault(format!("variable `{}` is {c:?}, expected a numeric array", v.name)))
            }
        }
    }

    /// The 2-D numeric variable `name` of exactly `rows` x `cols`, row-major.
    ///
    /// # Errors
    /// [`Error::Mat`] naming the variable and its actual shape.
    pub fn matrix(&self, names: &[&str], rows: usize, cols: usize) -> Result<Vec<f64>> {
        let v = self.numeric(names)?;
        if v.dims != [rows, cols] {
            return Err(Error::Mat {
                path: self.path.clone(),
                fault: format!("variable `{}` is {}, expected {rows} x {cols}", v.name, v.shape()),
            });
        }
        let d = v.data.as_ref().expect("numeric variables have data");
        Ok((0..rows).flat_map(|i| (0..cols).map(move |j| d[i + rows * j])).collect())
    }

    /// The numeric vector `name` of `n` entries (n x 1 or 1 x n).
    pub fn vector(&self, names: &[&str], n: usize) -> Result<Vec<f64>> {
        let v = self.numeric(names)?;
        if v.dims != [n, 1] && v.dims != [1, n] {
            return Err(Error::Mat {
                path: self.path.clone(),
                fault: format!("variable `{}` is {}, expected a {n}-vector", v.name, v.shape()),
            });
        }
        Ok(v.data.clone().expect("numeric variables have data"))
    }
}

/// Writes double variables as a little-endian MAT v5 file, each optionally zlib-compressed (as
/// MATLAB's default `-v7`). `data` is column-major, `dims` at least two long.
///
/// # Panics
/// When `data.len()` is not the product of `dims` (a programming error).
pub fn write_mat5(variables: &[(&str, &[usize], &[f64])], compress: bool) -> Vec<u8> {
    let mut out = Vec::with_capacity(128);
    let mut text = b"MATLAB 5.0 MAT-file, written by dataset-diligent".to_vec();
    text.resize(116, b' ');
    out.extend_from_slice(&text);
    out.extend_from_slice(&[0; 8]);
    out.extend_from_slice(&0x0100_u16.to_le_bytes());
    out.extend_from_slice(b"IM");
    fn element(out: &mut Vec<u8>, ty: u32, data: &[u8]) {
        out.extend_from_slice(&ty.to_le_bytes());
        out.extend_from_slice(&(data.len() as u32).to_le_bytes());
        out.extend_from_slice(data);
        out.resize(out.len().div_ceil(8) * 8, 0);
    }
    for (name, dims, data) in variables {
        assert_eq!(data.len(), dims.iter().product::<usize>(), "variable {name}");
        let mut m = Vec::new();
        element(&mut m, MI_UINT32, &[6, 0, 0, 0, 0, 0, 0, 0]);
        let d: Vec<u8> = dims.iter().flat_map(|&d| (d as i32).to_le_bytes()).collect();
        element(&mut m, MI_INT32, &d);
        element(&mut m, MI_INT8, name.as_bytes());
        let v: Vec<u8> = data.iter().flat_map(|x| x.to_le_bytes()).collect();
        element(&mut m, MI_DOUBLE, &v);
        let mut matrix = Vec::with_capacity(m.len() + 8);
        element(&mut matrix, MI_MATRIX, &m);
        if compress {
            let z = miniz_oxide::deflate::compress_to_vec_zlib(&matrix, 6);
            out.extend_from_slice(&MI_COMPRESSED.to_le_bytes());
            out.extend_from_slice(&(z.len() as u32).to_le_bytes());
            out.extend_from_slice(&z);
        } else {
            out.extend_from_slice(&matrix);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_plain_and_compressed() {
        let a: Vec<f64> = (0..24).map(|i| i as f64 * 0.5 - 3.0).collect();
        for compress in [false, true] {
            let bytes = write_mat5(
                &[
                    ("KK", &[3, 3], &[1.0, 0.0, 0.0, 0.0, 2.0, 0.0, 3.0, 4.0, 1.0]),
                    ("A", &[2, 3, 4], &a),
                ],
                compress,
            );
            let f = MatFile::parse(&bytes, Path::new("t.mat"), &Limits::DEFAULT).unwrap();
            assert_eq!(f.variables.len(), 2);
            assert_eq!(
                f.matrix(&["KK"], 3, 3).unwrap(),
                [1.0, 0.0, 3.0, 0.0, 2.0, 4.0, 0.0, 0.0, 1.0]
            );
            let v = f.get("A").unwrap();
            assert_eq!(v.dims, [2, 3, 4]);
            assert_eq!(v.at(&[1, 2, 3]), Some(a[1 + 2 * 2 + 6 * 3]));
            assert_eq!(v.at(&[2, 0, 0]), None);
        }
    }

    #[test]
    fn narrow_storage_small_elements_and_big_endian() {
        // A 1 x 3 double stored as miUINT8 in a small element, name in a small element, big
        // endian: the layout MATLAB uses for integral doubles.
        let mut b = b"MATLAB 5.0 MAT-file".to_vec();
        b.resize(116, b' ');
        b.extend_from_slice(&[0; 8]);
        b.extend_from_slice(&0x0100_u16.to_be_bytes());
        b.extend_from_slice(b"MI");
        let mut m = Vec::new();
        for w in [MI_UINT32, 8, 6, 0] {
            m.extend_from_slice(&w.to_be_bytes());
        }
        for w in [MI_INT32, 8, 1, 3] {
            m.extend_from_slice(&w.to_be_bytes());
        }
        m.extend_from_slice(&((2u32 << 16) | MI_INT8).to_be_bytes());
        m.extend_from_slice(b"Tc\0\0");
        m.extend_from_slice(&((3u32 << 16) | MI_UINT8).to_be_bytes());
        m.extend_from_slice(&[7, 8, 255, 0]);
        b.extend_from_slice(&MI_MATRIX.to_be_bytes());
        b.extend_from_slice(&(m.len() as u32).to_be_bytes());
        b.extend_from_slice(&m);
        let f = MatFile::parse(&b, Path::new("be.mat"), &Limits::DEFAULT).unwrap();
        assert_eq!(f.vector(&["Tc_1", "Tc"], 3).unwrap(), [7.0, 8.0, 255.0]);
    }

    #[test]
    fn bad_files_are_clear_errors() {
        let p = Path::new("bad.mat");
        let msg = |b: &[u8]| MatFile::parse(b, p, &Limits::DEFAULT).unwrap_err().to_string();
        assert!(msg(b"short").contains("128-byte header"));
        let mut h = vec![b' '; 128];
        assert!(msg(&h).contains("endian"));
        h[..10].copy_from_slice(b"MATLAB 7.3");
        assert!(msg(&h).contains("HDF5"));
        let good = write_mat5(&[("Rc_1", &[3, 2], &[0.0; 6])], false);
        let f = MatFile::parse(&good, p, &Limits::DEFAULT).unwrap();
        let e = f.matrix(&["Rc_1"], 3, 3).unwrap_err().to_string();
        assert!(e.contains("bad.mat") && e.contains("Rc_1") && e.contains("3 x 2"), "{e}");
        assert!(f.matrix(&["KK"], 3, 3).unwrap_err().to_string().contains("no variable `KK`"));
        let truncated = &good[..good.len() - 9];
        assert!(msg(truncated).contains("claims"), "{}", msg(truncated));
        // Dimensions whose product overflows are an error, not a panic.
        let mut huge = write_mat5(&[("h", &[1, 1, 1], &[1.0])], false);
        let dims_at = 128 + 8 + 16 + 8;
        for k in 0..3 {
            huge[dims_at + 4 * k..dims_at + 4 * k + 4].copy_from_slice(&i32::MAX.to_le_bytes());
        }
        assert!(msg(&huge).contains("overflow"), "{}", msg(&huge));
        let mut z = write_mat5(&[("x", &[1, 1], &[1.0])], true);
        let n = z.len();
        z[n - 6] ^= 0xff;
        assert!(msg(&z).contains("zlib"), "{}", msg(&z));
    }
}
