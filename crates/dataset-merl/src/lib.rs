//! The MERL binary BRDF format (spec section 1), the MERL-derived (NBRDF) material catalogue and the
//! semi-synthetic scene generator.
//!
//! Not built yet: see the MERL dataset issue.
