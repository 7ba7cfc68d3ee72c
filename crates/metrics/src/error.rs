//! The crate's one error type.

use std::path::PathBuf;

/// Everything a metric can reject. Messages name the input (or file) and the fault.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A pixel buffer whose length is not width * height * 3.
    #[error("{what}: buffer of {len} floats does not hold {width} x {height} RGB pixels")]
    BufferLength {
        /// Which image.
        what: &'static str,
        /// Declared width.
        width: usize,
        /// Declared height.
        height: usize,
        /// Actual buffer length.
        len: usize,
    },
    /// Test and reference images of different sizes.
    #[error("image size mismatch: test is {test:?}, reference is {reference:?} (width, height)")]
    SizeMismatch {
        /// Test image (width, height).
        test: (usize, usize),
        /// Reference image (width, height).
        reference: (usize, usize),
    },
    /// A mask whose length is not the pixel count.
    #[error("mask size mismatch: mask has {mask} entries, image has {pixels} pixels")]
    MaskSize {
        /// Mask length.
        mask: usize,
        /// Pixel count of the image.
        pixels: usize,
    },
    /// A mask (or image) that selects no pixel.
    #[error("{0}: no pixel to average over (empty mask or image)")]
    Empty(&'static str),
    /// NaN in an input.
    #[error("{what}: NaN at pixel ({x}, {y}) channel {channel}")]
    NaN {
        /// Which image.
        what: &'static str,
        /// Column.
        x: usize,
        /// Row.
        y: usize,
        /// RGB channel.
        channel: usize,
    },
    /// An image smaller than a metric's window.
    #[error("{metric}: image {width} x {height} is smaller than the {window} x {window} window")]
    TooSmall {
        /// The metric.
        metric: &'static str,
        /// Width.
        width: usize,
        /// Height.
        height: usize,
        /// Window size in pixels.
        window: usize,
    },
    /// HDR-FLIP cannot derive an exposure range from the reference.
    #[error("HDR-FLIP: {0}")]
    Exposure(String),
    /// A configuration value out of its range.
    #[error("invalid configuration: {0}")]
    Config(String),
    /// Slices of a batch whose lengths differ.
    #[error("{what}: lengths differ ({a} vs {b})")]
    LengthMismatch {
        /// Which input.
        what: &'static str,
        /// First length.
        a: usize,
        /// Second length.
        b: usize,
    },
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A weight file that is not in the documented format.
    #[error("{path}: bad LPIPS weight file: {reason}")]
    WeightFormat {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// A file whose sha256 differs from the expected one.
    #[error("{path}: sha256 mismatch: expected {expected}, found {found}")]
    Checksum {
        /// The file.
        path: PathBuf,
        /// Expected hex digest.
        expected: String,
        /// Actual hex digest.
        found: String,
    },
    /// A download that failed (or the `fetch` feature is off).
    #[error("download of {url} failed: {reason}")]
    Download {
        /// The URL.
        url: String,
        /// Why.
        reason: String,
    },
}

/// `Result` with this crate's [`Error`].
pub type Result<T> = std::result::Result<T, Error>;

impl From<stdx::fs::Error> for Error {
    fn from(e: stdx::fs::Error) -> Self {
        Self::Io { path: e.path, source: e.source }
    }
}
