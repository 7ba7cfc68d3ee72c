//! What a reader of users' files accepts before it allocates on a size the file declares, in the
//! manner of image-rs's `Limits`: one typed value with documented defaults that every loader
//! takes (the scene's EXR and PNG images, DiLiGenT's PNGs and MATLAB files, a capture's images).
//! A corrupted header or length field is then a clear error naming the file and the limit, not
//! an allocation of its claim. The command line builds it, reading its environment variables as
//! overrides ([`Limits::VARIABLES`], [`Limits::with_override`]); nothing below it reads them.

/// The largest sizes a loader accepts from a file's own header or length fields.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// The largest image decoded, in pixels (width x height), checked from the header before any
    /// pixel buffer is allocated (default 8192 x 8192, about 800 MB as f32 RGB).
    pub max_image_pixels: u64,
    /// The largest single buffer allocated on a size the file declares, in bytes (a compressed
    /// variable's inflated size, an image decoder's buffers; default 1 GiB).
    pub max_alloc: u64,
}

impl Default for Limits {
    fn default() -> Self {
        Limits::DEFAULT
    }
}

impl Limits {
    /// The defaults: 8192 x 8192 pixels, 1 GiB.
    pub const DEFAULT: Limits = Limits { max_image_pixels: 8192 * 8192, max_alloc: 1 << 30 };

    /// No limit at all (for trusted files only: a corrupted header then allocates its claim).
    pub const NONE: Limits = Limits { max_image_pixels: u64::MAX, max_alloc: u64::MAX };

    /// The environment variables that override a limit, and what each sets (read by the CLI
    /// only).
    pub const VARIABLES: &[(&str, &str)] = &[
        ("NEURAL_BRDF_MAX_IMAGE_PIXELS", "max_image_pixels: largest image decoded, in pixels"),
        ("NEURAL_BRDF_MAX_ALLOC_MIB", "max_alloc: largest buffer sized by a file, in MiB"),
    ];

    /// An image of `width` x `height` pixels, as its header declares it, is within
    /// [`Limits::max_image_pixels`]; the error says what was declared and what is accepted.
    ///
    /// # Errors
    ///
    /// The declared size, and the limit, as a sentence.
    pub fn check_pixels(&self, width: u64, height: u64) -> Result<(), String> {
        match width.checked_mul(height) {
            Some(n) if n <= self.max_image_pixels => Ok(()),
            _ => Err(format!(
                "the header declares {width} x {height} pixels; at most {} are read \
                 (max_image_pixels, NEURAL_BRDF_MAX_IMAGE_PIXELS)",
                self.max_image_pixels
            )),
        }
    }

    /// A buffer of `bytes` that the file declares is within [`Limits::max_alloc`].
    ///
    /// # Errors
    ///
    /// The declared size, what it is for, and the limit, as a sentence.
    pub fn check_alloc(&self, bytes: u64, what: &str) -> Result<(), String> {
        if bytes <= self.max_alloc {
            Ok(())
        } else {
            Err(format!(
                "{what} declares {bytes} bytes, more than the {} accepted \
                 (max_alloc, NEURAL_BRDF_MAX_ALLOC_MIB)",
                self.max_alloc
            ))
        }
    }

    /// These limits with the one `variable` (one of [`Limits::VARIABLES`]) set from `value`.
    ///
    /// # Errors
    ///
    /// An unknown variable, or a value that is not a positive whole number, named with what the
    /// variable takes.
    pub fn with_override(mut self, variable: &str, value: &str) -> Result<Limits, String> {
        let number = || match value.trim().parse::<u64>() {
            Ok(n) if n > 0 => Ok(n),
            _ => Err(format!("{variable}={value:?}: expected a positive whole number")),
        };
        match variable {
            "NEURAL_BRDF_MAX_IMAGE_PIXELS" => self.max_image_pixels = number()?,
            "NEURAL_BRDF_MAX_ALLOC_MIB" => {
                self.max_alloc = number()?.checked_mul(1 << 20).ok_or_else(|| {
                    format!("{variable}={value:?}: more MiB than a 64-bit size holds")
                })?;
            }
            _ => return Err(format!("{variable} is not a limit's variable")),
        }
        Ok(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_accept_up_to_their_bounds_and_refuse_beyond() {
        let l = Limits::default();
        assert!(l.check_pixels(8192, 8192).is_ok());
        assert!(l.check_pixels(8193, 8192).unwrap_err().contains("8193 x 8192"));
        // An overflowing product is refused, not wrapped.
        assert!(l.check_pixels(u64::MAX, 2).is_err());
        assert!(l.check_alloc(1 << 30, "x").is_ok());
        let e = l.check_alloc((1 << 30) + 1, "a compressed variable").unwrap_err();
        assert!(e.contains("a compressed variable") && e.contains("1073741824"), "{e}");
        assert!(Limits::NONE.check_pixels(1 << 31, 1 << 31).is_ok());
    }

    #[test]
    fn overrides_parse_or_say_what_they_take() {
        let l = Limits::default().with_override("NEURAL_BRDF_MAX_IMAGE_PIXELS", "100").unwrap();
        assert_eq!(l.max_image_pixels, 100);
        let l = l.with_override("NEURAL_BRDF_MAX_ALLOC_MIB", " 3 ").unwrap();
        assert_eq!(l.max_alloc, 3 << 20);
        for bad in ["0", "-1", "1.5", "lots", ""] {
            let e = l.with_override("NEURAL_BRDF_MAX_ALLOC_MIB", bad).unwrap_err();
            assert!(e.contains("positive whole number"), "{e}");
        }
        assert!(l.with_override("NEURAL_BRDF_MAX_ALLOC_MIB", &u64::MAX.to_string()).is_err());
        assert!(l.with_override("NEURAL_BRDF_OTHER", "1").is_err());
        for (var, _) in Limits::VARIABLES {
            assert!(Limits::default().with_override(var, "7").is_ok());
        }
    }
}
