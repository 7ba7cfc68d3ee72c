//! Robustness of the capture readers (issue 19): corrupted copies of a miniature DiLiGenT-MV
//! capture's files (MAT v5 compressed and not, 16-bit PNG images, the light-direction and
//! intensity text files) give errors naming the file, never a panic or an unbounded
//! allocation (a MAT header claiming 2^40 elements, a zlib stream that inflates without end).

mod common;

use dataset_diligent::mat5::{MatFile, write_mat5};
use dataset_diligent::pms_dir::{Capture, read_png16};
use std::path::Path;
use stdx::Limits;
use test_support::corrupt::{CappedAlloc, fuzz_loader};

/// No reader may allocate more than 1 GiB at once.
#[global_allocator]
static ALLOC: CappedAlloc = CappedAlloc(1 << 30);

#[test]
fn corrupted_mat_files_give_errors_not_panics() {
    let m: Vec<f64> = (0..12).map(f64::from).collect();
    let vars: [(&str, &[usize], &[f64]); 2] =
        [("KK", &[3, 3], &m[..9]), ("Tc_1", &[3, 1], &m[..3])];
    let seeds = vec![write_mat5(&vars, false), write_mat5(&vars, true)];
    fuzz_loader("mat5", &seeds, 4000, |b| {
        if let Err(e) = MatFile::parse(b, Path::new("fuzz.mat"), &Limits::DEFAULT) {
            assert!(e.to_string().contains("fuzz.mat"), "{e}");
        }
    });
}

#[test]
fn corrupted_capture_files_give_errors_not_panics() {
    let tmp = common::TempDir::new("fuzz-capture");
    let src = common::miniature::write(&tmp.0, 1, 3);
    let view = src.join("view_01");
    let png = std::fs::read_dir(&view)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.file_name().is_some_and(|n| n.to_string_lossy().starts_with("001")))
        .expect("the first light's image");
    let png_seed = std::fs::read(&png).unwrap();
    let scratch = tmp.0.join("scratch.png");
    fuzz_loader("png16", &[png_seed], 1000, |b| {
        std::fs::write(&scratch, b).unwrap();
        let _ = read_png16(&scratch, &Limits::DEFAULT);
    });
    for name in ["light_directions.txt", "light_intensities.txt"] {
        let file = view.join(name);
        let seed = std::fs::read(&file).unwrap();
        fuzz_loader(name, std::slice::from_ref(&seed), 1000, |b| {
            std::fs::write(&file, b).unwrap();
            let _ = Capture::open(&view, &Limits::DEFAULT);
        });
        std::fs::write(&file, seed).unwrap();
    }
    assert!(Capture::open(&view, &Limits::DEFAULT).is_ok(), "the restored capture opens");
}

/// A zlib bomb: a compressed variable whose tag declares 2^31 bytes is refused before it is
/// inflated, and one that declares 16 bytes but inflates to 16 MiB allocates only what it
/// declared (then fails to parse).
#[test]
fn compressed_variables_inflate_no_further_than_their_tag_declares() {
    let mut header = b"MATLAB 5.0 MAT-file".to_vec();
    header.resize(124, b' ');
    header.extend_from_slice(&[0x00, 0x01, b'I', b'M']);
    let file = |inner: &[u8]| {
        let z = miniz_oxide::deflate::compress_to_vec_zlib(inner, 6);
        let mut b = header.clone();
        b.extend_from_slice(&15u32.to_le_bytes());
        b.extend_from_slice(&(z.len() as u32).to_le_bytes());
        b.extend_from_slice(&z);
        b.resize(b.len().next_multiple_of(8), 0);
        b
    };
    let mut claim = 14u32.to_le_bytes().to_vec();
    claim.extend_from_slice(&(1u32 << 31).to_le_bytes());
    claim.resize(1024, 0);
    let e = MatFile::parse(&file(&claim), Path::new("claim.mat"), &Limits::DEFAULT)
        .unwrap_err()
        .to_string();
    assert!(e.contains("claim.mat") && e.contains("declares 2147483648 bytes"), "{e}");
    let mut bomb = 14u32.to_le_bytes().to_vec();
    bomb.extend_from_slice(&16u32.to_le_bytes());
    bomb.resize(16 << 20, 0);
    let e = MatFile::parse(&file(&bomb), Path::new("bomb.mat"), &Limits::DEFAULT)
        .unwrap_err()
        .to_string();
    assert!(e.contains("bomb.mat"), "{e}");
    // The bound is the caller's: a well-formed compressed variable beyond a tighter limit is
    // refused before it is inflated, naming the limit.
    let m: Vec<f64> = (0..12).map(f64::from).collect();
    let good = write_mat5(&[("M", &[3, 4], &m)], true);
    assert!(MatFile::parse(&good, Path::new("good.mat"), &Limits::DEFAULT).is_ok());
    let tight = Limits { max_alloc: 64, ..Limits::DEFAULT };
    let e = MatFile::parse(&good, Path::new("good.mat"), &tight).unwrap_err().to_string();
    assert!(e.contains("good.mat") && e.contains("more than the 64 accepted"), "{e}");
}
