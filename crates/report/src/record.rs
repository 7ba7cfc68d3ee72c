//! One evaluated run as the tables see it: model, options, dataset, object and its metrics.
//!
//! The lead collects these from run directories (`metrics.json`, the energy and reciprocity
//! analyses); everything in [this crate](crate) is a pure function of a slice of them.

use metrics::aggregate::{Score, TableScale};
use model_spec::{AngleParametrization, ModelConfig, ModelKind, Reciprocity};
use std::collections::BTreeMap;
use std::fmt;

/// Which data set a run was fitted on. Tables order their column groups by this order.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Dataset {
    /// Semi-synthetic scenes rendered from MERL-derived materials (the published NBRDF
    /// networks tabulated into MERL tables); the only data with a BRDF ground truth.
    MerlNbrdf,
    /// DiLiGenT-MV captures.
    DiligentMv,
    /// DiLiGenT captures.
    Diligent,
    /// Anything else, printed by its name.
    Other(String),
}

impl Dataset {
    /// The label every table and caption prints.
    pub fn label(&self) -> &str {
        match self {
            Dataset::MerlNbrdf => "MERL-derived (NBRDF)",
            Dataset::DiligentMv => "DiLiGenT-MV",
            Dataset::Diligent => "DiLiGenT",
            Dataset::Other(name) => name,
        }
    }

    /// Whether the cube-root RMSE in BRDF space can be computed (a ground-truth BRDF exists).
    pub fn has_brdf_ground_truth(&self) -> bool {
        matches!(self, Dataset::MerlNbrdf)
    }

    /// The data set named `label` (one of the labels above, case-insensitive, or a few short
    /// aliases: "merl", "nbrdf", "diligent-mv", "diligent"); anything else is [`Dataset::Other`].
    pub fn from_label(label: &str) -> Dataset {
        let l = label.trim().to_ascii_lowercase();
        match l.as_str() {
            "merl-derived (nbrdf)" | "merl" | "nbrdf" | "merl_nbrdf" => Dataset::MerlNbrdf,
            "diligent-mv" | "diligent_mv" | "diligentmv" => Dataset::DiligentMv,
            "diligent" => Dataset::Diligent,
            _ => Dataset::Other(label.trim().to_string()),
        }
    }
}

impl fmt::Display for Dataset {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.label())
    }
}

/// Whether a larger or a smaller value of a column is better.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direction {
    /// Larger is better (PSNR).
    HigherIsBetter,
    /// Smaller is better (DSSIM, LPIPS, FLIP, RMSE, reciprocity error, energy violations, time).
    LowerIsBetter,
    /// No preference: never ranked or marked.
    Neutral,
}

impl Direction {
    /// The arrow a column header carries ("↑", "↓" or nothing).
    pub fn arrow(self) -> &'static str {
        match self {
            Direction::HigherIsBetter => "↑",
            Direction::LowerIsBetter => "↓",
            Direction::Neutral => "",
        }
    }
}

/// The metrics a run can carry (spec section 7). Values are raw (not table-scaled).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum MetricKind {
    /// PSNR on sRGB in dB.
    Psnr,
    /// DSSIM = (1 - SSIM) / 2.
    Dssim,
    /// LPIPS (AlexNet v0.1); often `Score::Unavailable("weights missing")`.
    Lpips,
    /// Mean HDR-FLIP.
    Flip,
    /// RMSE of cube roots of BRDF values (MERL-derived data only).
    CubeRootRmse,
    /// RMSE between f(x, l, v) and f(x, v, l).
    ReciprocityRmse,
    /// Percentage of (x, l) pairs whose directional albedo exceeds 1.
    EnergyPercentAbove1,
    /// Median directional albedo of the pairs above 1.
    EnergyMedianAbove1,
    /// Training wall time in seconds.
    TrainingSeconds,
}

impl MetricKind {
    /// Every metric, in table order.
    pub const ALL: [MetricKind; 9] = [
        MetricKind::Psnr,
        MetricKind::Dssim,
        MetricKind::Lpips,
        MetricKind::Flip,
        MetricKind::CubeRootRmse,
        MetricKind::ReciprocityRmse,
        MetricKind::EnergyPercentAbove1,
        MetricKind::EnergyMedianAbove1,
        MetricKind::TrainingSeconds,
    ];

    /// The image metrics of Table 1, in its column order (RMSE∛ is added for MERL data).
    pub const IMAGE: [MetricKind; 4] =
        [MetricKind::Psnr, MetricKind::Dssim, MetricKind::Lpips, MetricKind::Flip];

    /// The column label, without the direction arrow.
    pub fn label(self) -> &'static str {
        match self {
            MetricKind::Psnr => "PSNR",
            MetricKind::Dssim => "DSSIM",
            MetricKind::Lpips => "LPIPS",
            MetricKind::Flip => "FLIP",
            MetricKind::CubeRootRmse => "RMSE∛",
            MetricKind::ReciprocityRmse => "Recip. RMSE",
            MetricKind::EnergyPercentAbove1 => "% E>1",
            MetricKind::EnergyMedianAbove1 => "median E (E>1)",
            MetricKind::TrainingSeconds => "time (s)",
        }
    }

    /// Which values are better.
    pub fn direction(self) -> Direction {
        match self {
            MetricKind::Psnr => Direction::HigherIsBetter,
            _ => Direction::LowerIsBetter,
        }
    }

    /// The tables' scaling convention ([`TableScale`]); `None` for training time.
    pub fn table_scale(self) -> Option<TableScale> {
        match self {
            MetricKind::Psnr => Some(TableScale::Psnr),
            MetricKind::Dssim => Some(TableScale::Dssim),
            MetricKind::Lpips => Some(TableScale::Lpips),
            MetricKind::Flip => Some(TableScale::Flip),
            MetricKind::CubeRootRmse => Some(TableScale::CubeRootRmse),
            MetricKind::ReciprocityRmse => Some(TableScale::Reciprocity),
            MetricKind::EnergyPercentAbove1 => Some(TableScale::EnergyPercent),
            MetricKind::EnergyMedianAbove1 => Some(TableScale::EnergyMedian),
            MetricKind::TrainingSeconds => None,
        }
    }

    /// The factor tables multiply raw values by (100 for DSSIM, LPIPS, FLIP and RMSE∛).
    pub fn factor(self) -> f64 {
        self.table_scale().map_or(1.0, TableScale::factor)
    }

    /// Decimals printed after scaling.
    pub fn decimals(self) -> usize {
        match self {
            MetricKind::ReciprocityRmse => 4,
            MetricKind::EnergyMedianAbove1 => 3,
            MetricKind::TrainingSeconds => 0,
            _ => 2,
        }
    }
}

/// The options of a run that the ablation tables compare (everything else is the default).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RunOptions {
    /// Reciprocity handling (default none).
    pub reciprocity: Reciprocity,
    /// Angle parametrization (default Rusinkiewicz).
    pub parametrization: AngleParametrization,
    /// The NOL ablation (default false).
    pub nol: bool,
    /// NeRFactor's albedo clamp (default false).
    pub albedo_clamp: bool,
    /// NeRFactor's scalar specular (default false).
    pub scalar_specular: bool,
}

impl RunOptions {
    /// The paper's default options.
    pub const DEFAULT: RunOptions = RunOptions {
        reciprocity: Reciprocity::None,
        parametrization: AngleParametrization::Rusinkiewicz,
        nol: false,
        albedo_clamp: false,
        scalar_specular: false,
    };

    /// The options of a model configuration.
    pub fn of(config: &ModelConfig) -> Self {
        RunOptions {
            reciprocity: config.angles.reciprocity,
            parametrization: config.angles.parametrization,
            nol: config.nol,
            albedo_clamp: config.albedo_clamp,
            scalar_specular: config.scalar_specular,
        }
    }

    /// A short label: "default", or the non-default options joined by ", " (e.g. "NOL",
    /// "swap", "mapping", "view-light", "albedo clamp", "scalar specular").
    pub fn label(&self) -> String {
        let mut parts = Vec::new();
        match self.reciprocity {
            Reciprocity::None => {}
            Reciprocity::RandomSwap => parts.push("swap"),
            Reciprocity::Mapping => parts.push("mapping"),
        }
        if self.parametrization == AngleParametrization::ViewLight {
            parts.push("view-light");
        }
        if self.nol {
            parts.push("NOL");
        }
        if self.albedo_clamp {
            parts.push("albedo clamp");
        }
        if self.scalar_specular {
            parts.push("scalar specular");
        }
        if parts.is_empty() { "default".to_string() } else { parts.join(", ") }
    }
}

/// One evaluated run (or one evaluation of a run's intermediate weights).
#[derive(Clone, Debug, PartialEq)]
pub struct RunRecord {
    /// The model.
    pub model: ModelKind,
    /// Its options.
    pub options: RunOptions,
    /// The data set.
    pub dataset: Dataset,
    /// The object (scene) name; averages are taken per object first.
    pub object: String,
    /// Training steps of the evaluated weights; `None` for the final weights. Tables use each
    /// run's last evaluation ([`crate::average::final_records`]); run-time curves use
    /// all of them.
    pub steps: Option<u64>,
    /// Raw metric values; a metric left out was not measured.
    pub metrics: BTreeMap<MetricKind, Score>,
}

impl RunRecord {
    /// A record with default options, final weights and no metrics.
    pub fn new(model: ModelKind, dataset: Dataset, object: impl Into<String>) -> Self {
        RunRecord {
            model,
            options: RunOptions::DEFAULT,
            dataset,
            object: object.into(),
            steps: None,
            metrics: BTreeMap::new(),
        }
    }

    /// The same record with `options`.
    pub fn with_options(mut self, options: RunOptions) -> Self {
        self.options = options;
        self
    }

    /// The same record evaluated after `steps` training steps.
    pub fn at_steps(mut self, steps: u64) -> Self {
        self.steps = Some(steps);
        self
    }

    /// The same record with `metric` set to `score`.
    pub fn with(mut self, metric: MetricKind, score: Score) -> Self {
        self.metrics.insert(metric, score);
        self
    }

    /// The same record with `metric` set to the value `v`.
    pub fn with_value(self, metric: MetricKind, v: f64) -> Self {
        self.with(metric, Score::Value(v))
    }

    /// The score of `metric`, if measured.
    pub fn metric(&self, metric: MetricKind) -> Option<&Score> {
        self.metrics.get(&metric)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dataset_labels_round_trip() {
        for d in [Dataset::MerlNbrdf, Dataset::DiligentMv, Dataset::Diligent] {
            assert_eq!(Dataset::from_label(d.label()), d);
        }
        assert_eq!(Dataset::from_label(" my data "), Dataset::Other("my data".into()));
        assert!(Dataset::MerlNbrdf < Dataset::DiligentMv);
        assert!(Dataset::MerlNbrdf.has_brdf_ground_truth());
        assert!(!Dataset::Diligent.has_brdf_ground_truth());
    }

    #[test]
    fn options_labels() {
        assert_eq!(RunOptions::DEFAULT, RunOptions::default());
        assert_eq!(RunOptions::DEFAULT.label(), "default");
        let o = RunOptions { nol: true, reciprocity: Reciprocity::Mapping, ..RunOptions::DEFAULT };
        assert_eq!(o.label(), "mapping, NOL");
        let mut c = ModelConfig::new(ModelKind::AdditiveSeparate);
        c.scalar_specular = true;
        assert_eq!(RunOptions::of(&c).label(), "scalar specular");
    }

    #[test]
    fn metric_conventions() {
        assert_eq!(MetricKind::Flip.factor(), 100.0);
        assert_eq!(MetricKind::ReciprocityRmse.factor(), 1.0);
        assert_eq!(MetricKind::TrainingSeconds.factor(), 1.0);
        assert_eq!(MetricKind::Psnr.direction(), Direction::HigherIsBetter);
        assert_eq!(MetricKind::Lpips.direction(), Direction::LowerIsBetter);
    }
}
