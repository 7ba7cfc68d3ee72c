//! Image files of a scene: linear HDR RGB as float EXR (ZIP compressed), masks and flags as 8-bit
//! grayscale PNG, previews as 8-bit sRGB PNG.
//!
//! The `*_bytes` functions encode in memory (`path` only names the file in errors); the
//! `write_*` functions encode and write plainly, which is right inside a scene directory that is
//! assembled under a temporary name. Files that stand alone (evaluation renders) are written
//! with `stdx::fs::write_atomic` from the encoded bytes.

use crate::error::{Error, Result};
use exr::prelude::*;
use std::path::Path;
use stdx::Limits;

/// Writes encoded bytes to `path` and hands them back (the generator hashes them without
/// reading the file again).
fn write_bytes(path: &Path, bytes: Vec<u8>) -> Result<Vec<u8>> {
    std::fs::write(path, &bytes).map_err(|e| Error::io(path, e))?;
    Ok(bytes)
}

/// Encodes an image with the `image` crate into memory.
fn encode_png(
    path: &Path,
    data: &[u8],
    width: u32,
    height: u32,
    color: image::ExtendedColorType,
) -> Result<Vec<u8>> {
    let mut buf = std::io::Cursor::new(Vec::new());
    image::write_buffer_with_format(&mut buf, data, width, height, color, image::ImageFormat::Png)
        .map_err(|e| image_err(path, e))?;
    Ok(buf.into_inner())
}

fn image_err(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::Image { path: path.into(), fault: e.to_string() }
}

/// Writes a row-major RGB f32 image as an EXR file (ZIP compression, lossless); returns the
/// bytes written.
pub fn write_exr_rgb(
    path: &Path,
    width: usize,
    height: usize,
    rgb: &[[f32; 3]],
) -> Result<Vec<u8>> {
    write_bytes(path, exr_rgb_bytes(path, width, height, rgb)?)
}

/// A row-major RGB f32 image encoded as EXR (ZIP compression, lossless).
pub fn exr_rgb_bytes(
    path: &Path,
    width: usize,
    height: usize,
    rgb: &[[f32; 3]],
) -> Result<Vec<u8>> {
    if rgb.len() != width * height {
        return Err(image_err(path, format!("{} pixels for {width} x {height}", rgb.len())));
    }
    let channels = SpecificChannels::rgb(|Vec2(x, y)| {
        let p: [f32; 3] = rgb[y * width + x];
        (p[0], p[1], p[2])
    });
    let mut buf = std::io::Cursor::new(Vec::new());
    Image::from_encoded_channels((width, height), Encoding::SMALL_LOSSLESS, channels)
        .write()
        .non_parallel()
        .to_buffered(&mut buf)
        .map_err(|e| image_err(path, e))?;
    Ok(buf.into_inner())
}

/// Reads an RGB EXR file: (width, height, row-major pixels). Non-finite values are an error,
/// and so is a layer larger than `limits` admit (checked from the header before any pixel
/// buffer is allocated: the size comes from the file, and a corrupted header must be an error,
/// not an allocation of its claim).
pub fn read_exr_rgb(path: &Path, limits: &Limits) -> Result<(usize, usize, Vec<[f32; 3]>)> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let meta = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(&bytes), false)
        .map_err(|e| image_err(path, e))?;
    for h in &meta.headers {
        let (w, hgt) = (h.layer_size.0 as u64, h.layer_size.1 as u64);
        limits.check_pixels(w, hgt).map_err(|e| image_err(path, e))?;
    }
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .rgb_channels(
            |size, _| (size.0, vec![[0.0_f32; 3]; size.0 * size.1]),
            |(w, px): &mut (usize, Vec<[f32; 3]>), Vec2(x, y), (r, g, b): (f32, f32, f32)| {
                px[y * *w + x] = [r, g, b];
            },
        )
        .first_valid_layer()
        .all_attributes()
        .non_parallel()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(|e| image_err(path, e))?;
    let size = image.layer_data.size;
    let (_, px) = image.layer_data.channel_data.pixels;
    if let Some(i) = px.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
        return Err(image_err(
            path,
            format!("non-finite value at pixel ({}, {})", i % size.0, i / size.0),
        ));
    }
    Ok((size.0, size.1, px))
}

/// Writes an 8-bit grayscale PNG; returns the bytes written.
pub fn write_png_gray(path: &Path, width: u32, height: u32, data: &[u8]) -> Result<Vec<u8>> {
    write_bytes(path, encode_png(path, data, width, height, image::ExtendedColorType::L8)?)
}

/// Decodes an image file (its format guessed from its bytes) within `limits`: the header's size
/// is checked against [`Limits::max_image_pixels`] before the decoder allocates, and the
/// decoder's buffers are bounded by [`Limits::max_alloc`]. The error is the fault alone, for the
/// caller's own error type to name the file.
///
/// # Errors
///
/// An unreadable file, an image beyond the limits, or a decoding fault.
pub fn decode_within(
    path: &Path,
    limits: &Limits,
) -> std::result::Result<image::DynamicImage, String> {
    let (w, h) = image::image_dimensions(path).map_err(|e| e.to_string())?;
    limits.check_pixels(u64::from(w), u64::from(h))?;
    let mut reader = image::ImageReader::open(path)
        .and_then(|r| r.with_guessed_format())
        .map_err(|e| e.to_string())?;
    let mut bounds = image::Limits::default();
    bounds.max_alloc = Some(limits.max_alloc);
    reader.limits(bounds);
    reader.decode().map_err(|e| e.to_string())
}

/// Reads an 8-bit grayscale PNG within `limits`: (width, height, data).
pub fn read_png_gray(path: &Path, limits: &Limits) -> Result<(u32, u32, Vec<u8>)> {
    let img = decode_within(path, limits).map_err(|e| image_err(path, e))?;
    if !matches!(img.color(), image::ColorType::L8) {
        return Err(image_err(
            path,
            format!("colour type {:?}, expected 8-bit grayscale", img.color()),
        ));
    }
    let g = img.into_luma8();
    Ok((g.width(), g.height(), g.into_raw()))
}

/// The sRGB OETF (IEC 61966-2-1) of a linear value clamped to [0, 1], as an 8-bit code.
pub fn srgb8(linear: f32) -> u8 {
    let c = linear.clamp(0.0, 1.0);
    let s = if c <= 0.003_130_8 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
    (s * 255.0 + 0.5) as u8
}

/// Writes a linear RGB image as an 8-bit sRGB PNG (values clamped to [0, 1]), for viewing;
/// returns the bytes written.
pub fn write_png_srgb(path: &Path, width: u32, height: u32, rgb: &[[f32; 3]]) -> Result<Vec<u8>> {
    write_bytes(path, png_srgb_bytes(path, width, height, rgb)?)
}

/// A linear RGB image encoded as an 8-bit sRGB PNG (values clamped to [0, 1]).
pub fn png_srgb_bytes(path: &Path, width: u32, height: u32, rgb: &[[f32; 3]]) -> Result<Vec<u8>> {
    let bytes: Vec<u8> = rgb.iter().flat_map(|p| p.map(srgb8)).collect();
    encode_png(path, &bytes, width, height, image::ExtendedColorType::Rgb8)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Found by the corrupted-input test: a data window blasted to millions of rows made the reader
    /// allocate the header's claim before the exr crate looked at the chunks.
    #[test]
    fn an_exr_header_claiming_huge_sizes_is_an_error() {
        let dir = test_support::TempDir::new("exr-header");
        let path = dir.0.join("huge.exr");
        let mut bytes = exr_rgb_bytes(&path, 4, 4, &[[0.5; 3]; 16]).unwrap();
        let at = bytes.windows(17).position(|w| w == b"dataWindow\0box2i\0").unwrap();
        // After the name and type: size (4), xMin, yMin, xMax (4 each), then yMax.
        let y_max = at + 17 + 4 + 12;
        bytes[y_max..y_max + 4].copy_from_slice(&19_999_999i32.to_le_bytes());
        std::fs::write(&path, &bytes).unwrap();
        let e = read_exr_rgb(&path, &Limits::default()).unwrap_err().to_string();
        assert!(e.contains("huge.exr") && e.contains("declares 4 x 20000000"), "{e}");
        // The unmodified file still reads.
        write_exr_rgb(&path, 4, 4, &[[0.5; 3]; 16]).unwrap();
        assert_eq!(read_exr_rgb(&path, &Limits::default()).unwrap().2.len(), 16);
    }

    /// The limits are the caller's: a tighter one refuses what the defaults read, before
    /// decoding, naming the file and the limit.
    #[test]
    fn readers_take_the_callers_limits() {
        let dir = test_support::TempDir::new("image-limits");
        let (exr, png) = (dir.0.join("a.exr"), dir.0.join("m.png"));
        write_exr_rgb(&exr, 4, 4, &[[0.5; 3]; 16]).unwrap();
        write_png_gray(&png, 4, 4, &[7; 16]).unwrap();
        let tight = Limits { max_image_pixels: 15, ..Limits::default() };
        for e in [
            read_exr_rgb(&exr, &tight).unwrap_err().to_string(),
            read_png_gray(&png, &tight).unwrap_err().to_string(),
        ] {
            assert!(e.contains("4 x 4") && e.contains("at most 15"), "{e}");
        }
        assert!(read_png_gray(&png, &tight).unwrap_err().to_string().contains("m.png"));
        let enough = Limits { max_image_pixels: 16, ..tight };
        assert_eq!(read_png_gray(&png, &enough).unwrap().2, [7; 16]);
        // The decoder's buffers are bounded too.
        let no_room = Limits { max_alloc: 8, ..Limits::default() };
        assert!(read_png_gray(&png, &no_room).is_err());
    }
}
