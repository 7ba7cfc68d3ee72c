//! Bits of the per-sample flags image (`flags/vVV_lLL.png`): what happened to one (pixel,
//! light) sample. Both the generator and the capture importers set them; training reads only
//! `LIT` samples.

/// The light reaches the point (BRDF evaluated).
pub const LIT: u8 = 1;
/// The point is in shadow.
pub const SHADOWED: u8 = 2;
/// Light or view below the shading surface.
pub const BACK_FACING: u8 = 4;
/// The ground-truth BRDF is valid.
pub const GT_VALID: u8 = 8;
/// A channel reached the saturation level.
pub const SATURATED: u8 = 16;
/// The bits that say whether a foreground sample exists (any of them is set for every
/// foreground pixel, none for background).
pub const FOREGROUND: u8 = LIT | SHADOWED | BACK_FACING;
