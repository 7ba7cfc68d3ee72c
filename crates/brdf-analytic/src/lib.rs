//! Analytic BRDFs of the neural-BRDF comparison, scalar, in f32 and f64, with no tensor library.
//!
//! One small interface, [`Brdf`], and one model a file: [`Lambert`], [`RealisticPhong`],
//! [`TorranceSparrow`], [`Disney`] (isotropic) and [`Fmbrdf`] (Fresnel microfacet BRDF with its
//! two pretrained helper networks, shipped in this crate). Every model is evaluated in the local
//! shading frame (normal on +z; `l` to the light, `v` to the viewer, both pointing away from the
//! surface) and returns f_r in 1/sr as linear RGB, without the cosine factor. Shared physics
//! (Fresnel terms, the GGX distribution and Smith visibility) lives in [`microfacet`].
//!
//! Every model also samples: [`Brdf::sample`] draws a light direction l for a view direction v
//! and returns it with its density and the weight f cos / pdf ([`BrdfSample`]), and
//! [`Brdf::pdf`] gives that density for any pair. The shared samplers (cosine hemisphere, GGX
//! visible normals, Phong and GTR1 lobes) and the lobe mixture live in [`sampling`]; each model's
//! parameter table says which strategy it uses.
//!
//! A fitted material over a surface, analytic or neural, is a [`SurfaceBrdf`]: a batched
//! f(x, l, v) over surface points, which every [`Brdf`] is (spatially uniform) and which
//! `brdf-neural` implements for its models; validation, evaluation, export and the metrics take
//! it.
//!
//! Conventions every model keeps (architecture invariants):
//! * evaluating never fails, never allocates and never returns NaN or Inf: outside the upper
//!   hemisphere (n.l <= 0 or n.v <= 0) it returns 0, and parameters are validated or clamped
//!   when the model is built;
//! * f32 is the hot path, f64 the reference; tests compare the two.
//!
//! A renderer uses the crate alone:
//!
//! ```
//! use brdf_analytic::{Brdf, Disney, DisneyParams};
//! // A red plastic, evaluated for a light at 30 degrees and the viewer at the normal.
//! let brdf = Disney::new(DisneyParams { base_color: [0.8, 0.1, 0.1], roughness: 0.3, ..Default::default() });
//! let (s, c) = 30f32.to_radians().sin_cos();
//! let f = brdf.eval([s, 0.0, c], [0.0, 0.0, 1.0]);
//! // Outgoing radiance for a directional light of irradiance E at normal incidence:
//! let e = 3.0;
//! let radiance: Vec<f32> = f.iter().map(|fi| fi * e * c).collect();
//! assert!(radiance.iter().all(|x| x.is_finite() && *x > 0.0));
//! // Below the horizon the BRDF is zero.
//! assert_eq!(brdf.eval([s, 0.0, -c], [0.0, 0.0, 1.0]), [0.0; 3]);
//! ```
//!
//! Importance sampling, here a Monte Carlo estimate of the directional albedo for a viewer at
//! 45 degrees (the uniforms would come from the renderer's sampler):
//!
//! ```
//! use brdf_analytic::{Brdf, TorranceSparrow, TorranceSparrowParams};
//! let brdf = TorranceSparrow::new(TorranceSparrowParams { roughness: 0.3, ..Default::default() });
//! let v = [0.5f32.sqrt(), 0.0, 0.5f32.sqrt()];
//! let n = 64;
//! let mut albedo = [0.0f32; 3];
//! for i in 0..n {
//!     for j in 0..n {
//!         let u = [(i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32];
//!         // None: the sampled direction fell below the horizon; it contributes 0.
//!         if let Some(s) = brdf.sample(v, u) {
//!             assert!(s.l[2] > 0.0 && s.pdf == brdf.pdf(v, s.l));
//!             (0..3).for_each(|c| albedo[c] += s.weight[c] / (n * n) as f32);
//!         }
//!     }
//! }
//! assert!(albedo.iter().all(|a| *a > 0.3 && *a < 1.0), "{albedo:?}");
//! ```

pub mod albedo;
mod batch;
mod brdf;
mod disney;
mod fmbrdf;
mod lambert;
pub mod microfacet;
mod params;
mod phong;
pub mod quadrature;
pub mod sampling;
mod surface;
mod torrance_sparrow;

pub use angles::{Real, Vec3};
pub use batch::eval_batch;
#[cfg(feature = "rayon")]
pub use batch::par_eval_batch;
pub use brdf::{Brdf, BrdfSample, Rgb};
pub use disney::{Disney, DisneyParams, TINT_LUMINANCE_MIN as DISNEY_TINT_LUMINANCE_MIN};
/// FMBRDF's frame helpers, shared with its tensor twin: the body network's input features
/// (view-aligned frame of the addendum) and the clamped tan(theta) of the Smith network.
pub use fmbrdf::geometry::{body_features as fmbrdf_body_features, smith_tan as fmbrdf_smith_tan};
/// The FMBRDF normalisation rule: Gauss-Legendre nodes and the tail truncation (see [`Fmbrdf`]).
pub use fmbrdf::quadrature::{
    NODES as FMBRDF_NORMALIZATION_NODES, TAIL as FMBRDF_NORMALIZATION_TAIL,
};
pub use fmbrdf::weights::file_bytes as fmbrdf_weights_file;
pub use fmbrdf::{Fmbrdf, FmbrdfParams};
pub use lambert::{Lambert, LambertParams};
pub use params::ParamError;
pub use phong::{RealisticPhong, RealisticPhongParams};
pub use surface::{FnSurface, SurfaceBrdf};
pub use torrance_sparrow::{TorranceSparrow, TorranceSparrowParams};
