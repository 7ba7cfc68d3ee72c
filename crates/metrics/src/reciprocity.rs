//! Reciprocity (placeholder while building).
