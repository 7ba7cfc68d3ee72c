//! Robustness of the capture readers: corrupted copies of `capture.toml`, `transforms.json`,
//! `lights.json` and COLMAP's `cameras.txt` / `images.txt` give errors naming the file, never a
//! panic or an unbounded allocation.

use dataset_capture::cameras::read_transforms;
use dataset_capture::{CaptureConfig, Lights, colmap};
use std::path::Path;
use test_support::TempDir;
use test_support::corrupt::{CappedAlloc, fuzz_loader};

/// No reader may allocate more than 1 GiB at once.
#[global_allocator]
static ALLOC: CappedAlloc = CappedAlloc(1 << 30);

const TRANSFORMS: &str = r#"{"w": 64, "h": 48, "fl_x": 50.5, "fl_y": 50.5, "cx": 32, "cy": 24,
  "camera_model": "PINHOLE",
  "frames": [
    {"file_path": "images/a.exr", "mask_path": "masks/a.png",
     "transform_matrix": [[1, 0, 0, 0.5], [0, 0.6, -0.8, -2], [0, 0.8, 0.6, 1.5], [0, 0, 0, 1]]},
    {"file_path": "images/b", "camera_angle_x": 0.9,
     "transform_matrix": [[0, -1, 0, 0], [1, 0, 0, 0], [0, 0, 1, 3]]}]}"#;

const LIGHTS: &str = r#"{"lights": [
  {"image": "images/a.exr", "type": "point", "position": [0.8, -1.2, 2.0], "intensity": [4, 4, 3.5]},
  {"image": "images/b", "type": "directional", "direction": [0, 0.3, 0.95],
   "intensity": [1, 1, 1], "split": "test"}]}"#;

const CAPTURE: &str = "cameras = \"sparse\"\nmesh = \"mesh.ply\"\nmask_dir = \"masks\"\n\
    test_every = 3\n[images]\nresponse = \"gamma\"\ngamma = 2.4\nscale = 1.5\nsaturation = 0.98\n\
    [check]\nmin_iou = 0.85\n";

const CAMERAS: &str =
    "# Camera list\n1 PINHOLE 64 48 50 51 32 24\n2 SIMPLE_PINHOLE 64 48 50 32 24\n";

const IMAGES: &str = "# Image list\n1 0.9 0.1 0.2 0.3 0.5 -1 2.5 1 a.png\n12 40 80.5 3\n\
    2 1 0 0 0 0 0 3 2 b c.png\n\n";

#[test]
fn corrupted_capture_files_give_errors_not_panics() {
    let tmp = TempDir::new("fuzz-capture-files");
    let file = tmp.0.join("transforms.json");
    fuzz_loader("transforms_json", &[TRANSFORMS.as_bytes().to_vec()], 1500, |b| {
        std::fs::write(&file, b).unwrap();
        if let Err(e) = read_transforms(&file) {
            assert!(e.to_string().contains("transforms.json"), "{e}");
        }
    });
    let file = tmp.0.join("lights.json");
    fuzz_loader("lights_json", &[LIGHTS.as_bytes().to_vec()], 1500, |b| {
        std::fs::write(&file, b).unwrap();
        if let Err(e) = Lights::read(&file) {
            assert!(e.to_string().contains("lights.json"), "{e}");
        }
    });
    fuzz_loader("capture_toml", &[CAPTURE.as_bytes().to_vec()], 1500, |b| {
        let _ = CaptureConfig::parse(Path::new("/c"), &String::from_utf8_lossy(b));
    });
    let sparse = tmp.0.join("sparse");
    std::fs::create_dir_all(&sparse).unwrap();
    for (name, seed, other, other_text) in [
        ("cameras.txt", CAMERAS, "images.txt", IMAGES),
        ("images.txt", IMAGES, "cameras.txt", CAMERAS),
    ] {
        std::fs::write(sparse.join(other), other_text).unwrap();
        let file = sparse.join(name);
        fuzz_loader(name, &[seed.as_bytes().to_vec()], 1500, |b| {
            std::fs::write(&file, b).unwrap();
            if let Err(e) = colmap::read(&sparse, Path::new("images"), None) {
                assert!(e.to_string().contains(".txt"), "{e}");
            }
        });
    }
}

#[test]
fn the_seeds_themselves_read() {
    let tmp = TempDir::new("capture-seeds");
    std::fs::write(tmp.0.join("transforms.json"), TRANSFORMS).unwrap();
    let frames = read_transforms(&tmp.0.join("transforms.json")).unwrap();
    assert_eq!(frames.len(), 2);
    assert_eq!(frames[1].k[0][0], 50.5); // the file's fl_x comes before any camera_angle_x
    std::fs::write(tmp.0.join("lights.json"), LIGHTS).unwrap();
    assert_eq!(Lights::read(&tmp.0.join("lights.json")).unwrap().len(), 2);
    let c = CaptureConfig::parse(Path::new("/c"), CAPTURE).unwrap();
    assert_eq!((c.test_every, c.check.min_iou), (3, 0.85));
    let sparse = tmp.0.join("sparse");
    std::fs::create_dir_all(&sparse).unwrap();
    std::fs::write(sparse.join("cameras.txt"), CAMERAS).unwrap();
    std::fs::write(sparse.join("images.txt"), IMAGES).unwrap();
    assert_eq!(colmap::read(&sparse, Path::new("images"), None).unwrap().len(), 2);
}
