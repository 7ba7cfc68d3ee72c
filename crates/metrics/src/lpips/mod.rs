//! LPIPS (placeholder while building).
