//! Loaders for the real DiLiGenT (single view) and DiLiGenT-MV captures, producing the same dataset
//! API as the semi-synthetic scenes.
//!
//! Not built yet: see the DiLiGenT issue.
