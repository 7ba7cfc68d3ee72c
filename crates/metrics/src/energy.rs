//! Energy conservation (placeholder while building).
