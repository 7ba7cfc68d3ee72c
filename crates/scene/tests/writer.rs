//! The one scene writer on its own (no generator, no importer): a quad under a light from above
//! and one from below is written, read back and checked: statistics counted from the flags and
//! the mask, splits, samples, and the atomic directory (nothing left beside it).

use mesh_encoding::TriMesh;
use mesh_encoding::glam::{Mat3, Vec3};
use raycast_precompute::{Camera, LightState, View, ViewPrecompute};
use scene::manifest::{LightInfo, ViewInfo};
use scene::{
    MaterialSpec, PairImages, Progress, SceneConfig, SceneContents, SceneDataset, SceneSettings,
    Split, flag, write_scene,
};
use test_support::TempDir;

fn rows(m: Mat3) -> [[f32; 3]; 3] {
    [m.row(0).to_array(), m.row(1).to_array(), m.row(2).to_array()]
}

fn quad() -> TriMesh {
    let p = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
    TriMesh::new(p.map(|(x, y)| Vec3::new(x, y, 0.0)).to_vec(), vec![[0, 1, 2], [0, 2, 3]]).unwrap()
}

/// A white Lambertian quad: lit pixels render albedo / pi * E cos.
fn pair(li: usize, g: &ViewPrecompute) -> scene::Result<PairImages> {
    let n_pix = (g.width * g.height) as usize;
    let mut img = PairImages {
        observed: vec![[0.0; 3]; n_pix],
        brdf: vec![[0.0; 3]; n_pix],
        clean: None,
        flags: vec![0; n_pix],
    };
    for k in 0..g.len() {
        let p = g.pixels[k] as usize;
        img.flags[p] = match g.visibility.get(k, li) {
            LightState::Lit => {
                let f = [1.0 / std::f32::consts::PI; 3];
                let w = scene::shading::light_weight(
                    [1.0; 3],
                    g.normals[k].to_array(),
                    g.lights[li].direction().expect("directional").to_array(),
                );
                img.observed[p] = scene::shading::shade(f, w.unwrap_or([0.0; 3]));
                img.brdf[p] = f;
                flag::LIT | flag::GT_VALID
            }
            LightState::Shadowed => flag::SHADOWED,
            LightState::BackFacing => flag::BACK_FACING,
        };
    }
    Ok(img)
}

#[test]
fn a_written_scene_reads_back_with_its_statistics_and_splits() {
    let dir = TempDir::new("writer");
    let out = dir.0.join("quad");
    let mesh = quad();
    let camera =
        Camera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 30.0, 16, 16).unwrap();
    let views = vec![View { camera, lights: vec![Vec3::Z.into(), (-Vec3::Z).into()], mask: None }];
    let settings = SceneSettings {
        width: 16,
        height: 16,
        views: 1,
        train_views: 1,
        lights_per_view: 2,
        train_lights: 1,
        light_intensity: [1.0; 3],
        ..SceneSettings::default()
    };
    let config = SceneConfig {
        mesh: "quad.ply".into(),
        material: MaterialSpec::Lambert { albedo: [1.0; 3] },
        seed: 7,
        settings,
        merl_dir: None,
    };
    config.validate().unwrap();
    let light = |d: Vec3, split| LightInfo {
        direction: d.to_array(),
        intensity: [1.0; 3],
        split,
        source_index: None,
        position: None,
    };
    let view_infos = vec![ViewInfo {
        split: Split::Train,
        k: rows(camera.k),
        r: rows(camera.r),
        t: camera.t.to_array(),
        lights: vec![light(Vec3::Z, Split::Train), light(-Vec3::Z, Split::Test)],
    }];
    let contents = SceneContents {
        config: &config,
        generator: "scene writer test".into(),
        label: "analytic (Lambert)".into(),
        mesh: &mesh,
        views: &views,
        view_infos,
        clean_renders: false,
    };
    let mask = |_: usize, g: &ViewPrecompute| {
        let mut m = vec![0u8; (g.width * g.height) as usize];
        g.pixels.iter().for_each(|&p| m[p as usize] = 255);
        m
    };
    let progress = Progress { label: "test", visible: false };
    let written = write_scene(&out, contents, mask, |_, li, g| pair(li, g), progress).unwrap();
    let stats = &written.manifest.stats;
    // The quad fills the 16 x 16 image: every pixel lit from above, back-facing from below.
    assert_eq!(stats.foreground_pixels, 256);
    assert_eq!(
        (stats.lit_samples, stats.back_facing_samples, stats.shadowed_samples),
        (256, 256, 0)
    );
    assert_eq!((stats.invalid_gt_samples, stats.saturated_samples), (0, 0));
    assert!(!written.manifest.files.iter().any(|f| f.path.starts_with("clean/")));

    let ds = SceneDataset::open(&out).unwrap();
    assert_eq!(ds.manifest, written.manifest);
    assert_eq!(ds.pairs(Split::Train), [(0, 0)]);
    assert!(ds.pairs(Split::Test).is_empty(), "a training view has no test pairs");
    let train = ds.samples(Split::Train).unwrap();
    assert_eq!(train.len(), 256);
    assert!(train.gt_valid.iter().all(|&v| v));
    // A head-on light on a white Lambertian: radiance 1 / pi everywhere.
    let expect = 1.0 / std::f32::consts::PI;
    assert!(train.observed.iter().all(|o| o.iter().all(|&c| (c - expect).abs() < 1e-6)));
    // Only the scene directory beside it: no temporary directory left behind.
    let names: Vec<_> =
        std::fs::read_dir(&dir.0).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(names, ["quad"]);
    corrupted_scene_files_give_errors_not_panics(&out, &dir.0);
}

/// No reader may allocate more than 1 GiB at once (a header claiming 2^40 pixels is an error).
#[global_allocator]
static ALLOC: test_support::corrupt::CappedAlloc = test_support::corrupt::CappedAlloc(1 << 30);

/// Issue 19: corrupted copies of the written scene's files (manifest, EXR image, flags PNG,
/// mesh PLY) read through their readers give errors, never a panic.
fn corrupted_scene_files_give_errors_not_panics(scene: &std::path::Path, tmp: &std::path::Path) {
    let find = |sub: &str, ext: &str| -> Vec<u8> {
        let dir = scene.join(sub);
        let file = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .find(|p| p.extension().is_some_and(|e| e == ext))
            .unwrap_or_else(|| panic!("no .{ext} in {}", dir.display()));
        std::fs::read(file).unwrap()
    };
    let manifest = std::fs::read(scene.join(scene::MANIFEST_FILE)).unwrap();
    let mesh = std::fs::read_dir(scene)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "ply"))
        .map(|p| std::fs::read(p).unwrap())
        .expect("the scene's mesh");
    let scratch = |name: &str| tmp.join(name);
    type Reader = fn(&std::path::Path) -> bool;
    let targets: [(&str, Vec<u8>, &str, Reader); 4] = [
        ("scene-manifest", manifest, "manifest.json", |p| scene::Manifest::read(p).is_ok()),
        ("scene-exr", find("images", "exr"), "image.exr", |p| {
            scene::images::read_exr_rgb(p, &stdx::Limits::DEFAULT).is_ok()
        }),
        ("scene-flags-png", find("flags", "png"), "flags.png", |p| {
            scene::images::read_png_gray(p, &stdx::Limits::DEFAULT).is_ok()
        }),
        ("scene-mesh-ply", mesh, "mesh.ply", |p| scene::mesh_file::load(p).is_ok()),
    ];
    for (target, seed, name, reader) in targets {
        let path = scratch(name);
        test_support::corrupt::fuzz_loader(target, &[seed], 1500, |b| {
            std::fs::write(&path, b).unwrap();
            let _ = reader(&path);
        });
    }
}
