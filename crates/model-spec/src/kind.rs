//! The models of the comparison, [`ModelKind`]: their configuration names (TOML), the paper's
//! table row names, and which family each belongs to (parametric, Single MLP, additive, enhanced
//! additive).

use crate::{Error, Result};
use serde::{Deserialize, Serialize};

/// Which analytic model a parametric model drives.
///
/// The columns of the MLP's output ([`Analytic::outputs`] of them):
///
/// | model | outputs | columns |
/// | --- | ---: | --- |
/// | RP | 7 | k (RGB), zeta (RGB), N |
/// | TS | 7 | roughness, rho_d (RGB), F0 (RGB) |
/// | Disney | 12 | base colour (RGB), metallic, subsurface, specular, roughness, specular tint, sheen, sheen tint, clearcoat, clearcoat gloss |
/// | FMBRDF | 6 (+ 2 global) | eta, rho (RGB), k_s, kappa; alpha and beta are two trainable scalars per object, not MLP outputs |
///
/// (The spec counts 13 Disney outputs: its 10 scalars include anisotropic, which the paper fixes
/// to 0, so it is not an output here.)
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Analytic {
    /// Realistic Phong.
    RealisticPhong,
    /// Torrance-Sparrow (GGX).
    TorranceSparrow,
    /// Isotropic Disney.
    Disney,
    /// Fresnel microfacet BRDF.
    Fmbrdf,
}

impl Analytic {
    /// Number of per-point MLP outputs.
    pub fn outputs(self) -> usize {
        match self {
            Analytic::RealisticPhong | Analytic::TorranceSparrow => 7,
            Analytic::Disney => 12,
            Analytic::Fmbrdf => 6,
        }
    }
}

/// The models of the paper's tables.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ModelKind {
    /// Realistic Phong driven by an MLP ("RP").
    Rp,
    /// Torrance-Sparrow driven by an MLP ("TS").
    Ts,
    /// FMBRDF driven by an MLP ("FMBRDF").
    Fmbrdf,
    /// Disney driven by an MLP ("Disney").
    Disney,
    /// Single MLP ("Single MLP", default).
    #[default]
    SingleMlp,
    /// Additive Separate ("Add. Sep.").
    AdditiveSeparate,
    /// Additive Shared ("Add. Shared").
    AdditiveShared,
    /// Enhanced Additive Separate ("Enh. Add. Sep.").
    AdditiveSeparateEnhanced,
    /// Enhanced Additive Shared ("Enh. Add. Shared").
    AdditiveSharedEnhanced,
}

impl ModelKind {
    /// Every model, in the paper's table order.
    pub const ALL: [ModelKind; 9] = [
        ModelKind::Rp,
        ModelKind::Ts,
        ModelKind::Fmbrdf,
        ModelKind::Disney,
        ModelKind::SingleMlp,
        ModelKind::AdditiveSeparate,
        ModelKind::AdditiveShared,
        ModelKind::AdditiveSeparateEnhanced,
        ModelKind::AdditiveSharedEnhanced,
    ];

    /// The configuration name (`snake_case`, as in TOML).
    pub fn config_name(self) -> &'static str {
        match self {
            ModelKind::Rp => "rp",
            ModelKind::Ts => "ts",
            ModelKind::Fmbrdf => "fmbrdf",
            ModelKind::Disney => "disney",
            ModelKind::SingleMlp => "single_mlp",
            ModelKind::AdditiveSeparate => "additive_separate",
            ModelKind::AdditiveShared => "additive_shared",
            ModelKind::AdditiveSeparateEnhanced => "additive_separate_enhanced",
            ModelKind::AdditiveSharedEnhanced => "additive_shared_enhanced",
        }
    }

    /// The paper's table row name.
    pub fn paper_name(self) -> &'static str {
        match self {
            ModelKind::Rp => "RP",
            ModelKind::Ts => "TS",
            ModelKind::Fmbrdf => "FMBRDF",
            ModelKind::Disney => "Disney",
            ModelKind::SingleMlp => "Single MLP",
            ModelKind::AdditiveSeparate => "Add. Sep.",
            ModelKind::AdditiveShared => "Add. Shared",
            ModelKind::AdditiveSeparateEnhanced => "Enh. Add. Sep.",
            ModelKind::AdditiveSharedEnhanced => "Enh. Add. Shared",
        }
    }

    /// Looks a model up by configuration name or paper row name (case-insensitive).
    pub fn from_name(name: &str) -> Result<ModelKind> {
        let n = name.trim();
        Self::ALL
            .into_iter()
            .find(|k| {
                k.config_name().eq_ignore_ascii_case(n) || k.paper_name().eq_ignore_ascii_case(n)
            })
            .ok_or_else(|| Error::UnknownModel(name.to_string()))
    }

    /// The analytic model of a parametric kind.
    pub fn analytic(self) -> Option<Analytic> {
        match self {
            ModelKind::Rp => Some(Analytic::RealisticPhong),
            ModelKind::Ts => Some(Analytic::TorranceSparrow),
            ModelKind::Disney => Some(Analytic::Disney),
            ModelKind::Fmbrdf => Some(Analytic::Fmbrdf),
            _ => None,
        }
    }

    /// Whether the kind is an additive split model.
    pub fn is_additive(self) -> bool {
        matches!(
            self,
            ModelKind::AdditiveSeparate
                | ModelKind::AdditiveShared
                | ModelKind::AdditiveSeparateEnhanced
                | ModelKind::AdditiveSharedEnhanced
        )
    }

    /// Whether the kind is an enhanced additive model.
    pub fn is_enhanced(self) -> bool {
        matches!(self, ModelKind::AdditiveSeparateEnhanced | ModelKind::AdditiveSharedEnhanced)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_families_partition_the_kinds() {
        for k in ModelKind::ALL {
            assert_eq!(ModelKind::from_name(k.config_name()).unwrap(), k);
            assert_eq!(ModelKind::from_name(&k.paper_name().to_uppercase()).unwrap(), k);
            let families = [k.analytic().is_some(), k == ModelKind::SingleMlp, k.is_additive()];
            assert_eq!(families.iter().filter(|&&f| f).count(), 1, "{k:?}");
            assert!(!k.is_enhanced() || k.is_additive(), "{k:?}");
        }
        assert_eq!(
            ModelKind::from_name(" Enh. Add. Sep. ").unwrap(),
            ModelKind::AdditiveSeparateEnhanced
        );
        let e = ModelKind::from_name("mlp").unwrap_err();
        assert_eq!(e.to_string(), "unknown model name \"mlp\" (see ModelKind::ALL for the names)");
    }
}
