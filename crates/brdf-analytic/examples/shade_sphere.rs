//! A minimal renderer that uses `brdf-analytic` alone: shades a unit sphere seen head-on under
//! one directional light with each analytic model and writes one binary PPM per model.
//!
//! `cargo run --release -p brdf-analytic --example shade_sphere -- [OUT_DIR] [SIZE]`
//!
//! Radiance L = f(l, v) E cos(theta_l) with E = pi, displayed through the sRGB OETF (clamped).

use brdf_analytic::*;
use std::io::Write;

fn srgb(c: f32) -> u8 {
    let c = c.clamp(0.0, 1.0);
    let s = if c <= 0.003_130_8 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
    (s * 255.0 + 0.5) as u8
}

fn render(brdf: &dyn Brdf<f32>, size: usize, light_world: [f32; 3]) -> Vec<u8> {
    let mut rgb = vec![0u8; size * size * 3];
    let view = [0.0, 0.0, 1.0]; // orthographic camera looking down -z
    for y in 0..size {
        for x in 0..size {
            let px = (x as f32 + 0.5) / size as f32 * 2.0 - 1.0;
            let py = 1.0 - (y as f32 + 0.5) / size as f32 * 2.0;
            let r2 = px * px + py * py;
            if r2 >= 1.0 {
                continue;
            }
            let n = [px, py, (1.0 - r2).sqrt()];
            let frame = angles::Frame::from_normal(n);
            let (l, v) = (frame.to_local(light_world), frame.to_local(view));
            let f = brdf.eval(l, v);
            let e_cos = std::f32::consts::PI * l[2].max(0.0);
            for c in 0..3 {
                rgb[(y * size + x) * 3 + c] = srgb(f[c] * e_cos);
            }
        }
    }
    rgb
}

fn main() -> std::io::Result<()> {
    let mut args = std::env::args().skip(1);
    let out = std::path::PathBuf::from(args.next().unwrap_or_else(|| "out/spheres".into()));
    let size: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(256);
    std::fs::create_dir_all(&out)?;
    let light = angles::vec3::normalize_or_zero([0.5_f32, 0.6, 0.8]);
    let models: Vec<(&str, Box<dyn Brdf<f32>>)> = vec![
        ("lambert", Box::new(Lambert::new(LambertParams::default()))),
        ("realistic-phong", Box::new(RealisticPhong::new(RealisticPhongParams::default()))),
        ("torrance-sparrow", Box::new(TorranceSparrow::new(TorranceSparrowParams::default()))),
        ("disney", Box::new(Disney::new(DisneyParams::default()))),
        ("fmbrdf", Box::new(Fmbrdf::new(FmbrdfParams::default()))),
    ];
    for (name, m) in &models {
        let img = render(m.as_ref(), size, light);
        let path = out.join(format!("{name}.ppm"));
        let tmp = out.join(format!(".{name}.ppm.tmp"));
        let mut f = std::fs::File::create(&tmp)?;
        write!(f, "P6\n{size} {size}\n255\n")?;
        f.write_all(&img)?;
        drop(f);
        std::fs::rename(&tmp, &path)?;
        println!("wrote {}", path.display());
    }
    Ok(())
}
