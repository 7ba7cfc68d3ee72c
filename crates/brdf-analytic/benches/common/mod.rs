//! What the analytic benches share: the "all lobes" Disney material (subsurface, sheen and clear
//! coat on), so that `eval` and `sample` time the same model.

use brdf_analytic::DisneyParams;

/// A Disney material with every lobe active.
pub fn disney_all_lobes() -> DisneyParams<f32> {
    DisneyParams {
        base_color: [0.6, 0.3, 0.2],
        metallic: 0.3,
        subsurface: 0.5,
        specular: 0.7,
        roughness: 0.35,
        specular_tint: 0.4,
        sheen: 0.6,
        sheen_tint: 0.5,
        clearcoat: 0.8,
        clearcoat_gloss: 0.7,
        gamma_base_color: true,
    }
}
