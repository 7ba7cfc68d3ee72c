//! Little-endian binary encoding of the cache payload: a growable writer and a bounds-checked
//! reader that reports truncation instead of panicking.

use glam::Vec3;

/// Appends little-endian values to a byte vector.
#[derive(Debug, Default)]
pub(crate) struct Writer {
    pub(crate) bytes: Vec<u8>,
}

impl Writer {
    pub(crate) fn u32(&mut self, x: u32) {
        self.bytes.extend(x.to_le_bytes());
    }

    pub(crate) fn u64(&mut self, x: u64) {
        self.bytes.extend(x.to_le_bytes());
    }

    pub(crate) fn f32(&mut self, x: f32) {
        self.bytes.extend(x.to_le_bytes());
    }

    /// A length-prefixed slice of u32.
    pub(crate) fn u32s(&mut self, xs: &[u32]) {
        self.u64(xs.len() as u64);
        xs.iter().for_each(|&x| self.u32(x));
    }

    /// A length-prefixed slice of u64.
    pub(crate) fn u64s(&mut self, xs: &[u64]) {
        self.u64(xs.len() as u64);
        xs.iter().for_each(|&x| self.u64(x));
    }

    /// A length-prefixed slice of 2-vectors.
    pub(crate) fn vec2s(&mut self, xs: &[[f32; 2]]) {
        self.u64(xs.len() as u64);
        xs.iter().flatten().for_each(|&x| self.f32(x));
    }

    /// A length-prefixed slice of 3-vectors.
    pub(crate) fn vec3s(&mut self, xs: &[Vec3]) {
        self.u64(xs.len() as u64);
        xs.iter().for_each(|v| v.to_array().iter().for_each(|&x| self.f32(x)));
    }
}

/// Reads little-endian values; every read fails cleanly past the end.
#[derive(Debug)]
pub(crate) struct Reader<'a> {
    bytes: &'a [u8],
}

/// A truncated or inconsistent payload.
pub(crate) type ReadResult<T> = Result<T, String>;

impl<'a> Reader<'a> {
    pub(crate) fn new(bytes: &'a [u8]) -> Self {
        Reader { bytes }
    }

    pub(crate) fn is_empty(&self) -> bool {
        self.bytes.is_empty()
    }

    fn take<const N: usize>(&mut self) -> ReadResult<[u8; N]> {
        let (head, rest) =
            self.bytes.split_first_chunk::<N>().ok_or_else(|| "payload truncated".to_string())?;
        self.bytes = rest;
        Ok(*head)
    }

    pub(crate) fn u32(&mut self) -> ReadResult<u32> {
        self.take().map(u32::from_le_bytes)
    }

    pub(crate) fn u64(&mut self) -> ReadResult<u64> {
        self.take().map(u64::from_le_bytes)
    }

    pub(crate) fn f32(&mut self) -> ReadResult<f32> {
        self.take().map(f32::from_le_bytes)
    }

    /// A length prefix, checked against the bytes left (`item` bytes per element).
    fn len(&mut self, item: usize) -> ReadResult<usize> {
        let n = self.u64()?;
        if n.saturating_mul(item as u64) > self.bytes.len() as u64 {
            return Err(format!("length {n} exceeds the payload"));
        }
        Ok(n as usize)
    }

    pub(crate) fn u32s(&mut self) -> ReadResult<Vec<u32>> {
        let n = self.len(4)?;
        (0..n).map(|_| self.u32()).collect()
    }

    pub(crate) fn u64s(&mut self) -> ReadResult<Vec<u64>> {
        let n = self.len(8)?;
        (0..n).map(|_| self.u64()).collect()
    }

    pub(crate) fn vec2s(&mut self) -> ReadResult<Vec<[f32; 2]>> {
        let n = self.len(8)?;
        (0..n).map(|_| Ok([self.f32()?, self.f32()?])).collect()
    }

    pub(crate) fn vec3s(&mut self) -> ReadResult<Vec<Vec3>> {
        let n = self.len(12)?;
        (0..n).map(|_| Ok(Vec3::new(self.f32()?, self.f32()?, self.f32()?))).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_truncation() {
        let mut w = Writer::default();
        w.u32(7);
        w.vec3s(&[Vec3::new(1.0, 2.0, 3.0)]);
        w.u64s(&[u64::MAX]);
        w.vec2s(&[[0.5, 0.25]]);
        let mut r = Reader::new(&w.bytes);
        assert_eq!(r.u32().unwrap(), 7);
        assert_eq!(r.vec3s().unwrap(), vec![Vec3::new(1.0, 2.0, 3.0)]);
        assert_eq!(r.u64s().unwrap(), vec![u64::MAX]);
        assert_eq!(r.vec2s().unwrap(), vec![[0.5, 0.25]]);
        assert!(r.is_empty());
        let mut short = Reader::new(&w.bytes[..w.bytes.len() - 3]);
        short.u32().unwrap();
        short.vec3s().unwrap();
        short.u64s().unwrap();
        assert!(short.vec2s().is_err());
        // A huge length prefix is rejected before allocating.
        let mut w = Writer::default();
        w.u64(u64::MAX / 2);
        assert!(Reader::new(&w.bytes).u32s().is_err());
    }
}
