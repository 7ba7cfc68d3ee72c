//! The figures' font: DejaVu Sans 2.37, embedded (`assets/DejaVuSans.ttf`, Bitstream Vera
//! licence with public-domain DejaVu changes, `assets/LICENSE-DejaVu.txt`), rasterised by
//! plotters through ab_glyph, so figures look the same on every machine and need no system
//! fonts.

use crate::error::{Error, Result};
use plotters::style::{FontDesc, FontFamily, FontStyle, IntoFont, register_font};
use std::sync::OnceLock;

/// The font file.
const DEJAVU_SANS: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// The family name figures draw text with.
pub const FAMILY: &str = "sans-serif";

/// Registers the embedded font with plotters (once per process).
pub fn ensure_registered() -> Result<()> {
    static REGISTERED: OnceLock<std::result::Result<(), String>> = OnceLock::new();
    REGISTERED
        .get_or_init(|| {
            register_font(FAMILY, FontStyle::Normal, DEJAVU_SANS)
                .map_err(|_| "the embedded DejaVu Sans does not parse".to_string())
        })
        .clone()
        .map_err(|fault| Error::figure("report.font", fault))
}

/// The font at `px` pixels.
pub fn font(px: u32) -> FontDesc<'static> {
    (FontFamily::Name(FAMILY), f64::from(px.max(1))).into_font()
}

/// The width and height in pixels of `text` at `px` pixels (0 x 0 for empty text).
pub fn text_size(text: &str, px: u32) -> Result<(u32, u32)> {
    if text.is_empty() {
        return Ok((0, 0));
    }
    ensure_registered()?;
    font(px)
        .box_size(text)
        .map_err(|e| Error::figure("report.font", format!("cannot measure {text:?}: {e:?}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_is_measured_with_the_embedded_font() {
        let (w, h) = text_size("Enh. Add. Shared 43.30 dB", 16).unwrap();
        assert!(w > 100 && w < 400 && (12..=24).contains(&h), "{w} x {h}");
        let (w2, _) = text_size("Enh. Add. Shared 43.30 dB", 32).unwrap();
        assert!(w2 > w * 3 / 2, "{w} {w2}");
        assert_eq!(text_size("", 16).unwrap(), (0, 0));
        // Non-ASCII the captions use.
        assert!(text_size("∛RMSE – °", 16).unwrap().0 > 0);
    }
}
