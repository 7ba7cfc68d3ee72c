//! The neural BRDF models of the comparison (spec sections 3 and 4) on burn: parametric models
//! driven by an MLP, Single MLP, and the additive split models with their variants.
//!
//! Not built yet: see the neural models issue.
