//! The light files of a DiLiGenT capture (`light_directions.txt`, `light_intensities.txt`, split
//! from the input at its first NUL byte) through `Capture::open`, beside the real ball capture's
//! other files (copied once from `../shared/data/diligent/pmsData/ballPNG`, or
//! `$NEURAL_BRDF_DATA`; the target does nothing without them).
#![no_main]

use std::path::PathBuf;
use std::sync::OnceLock;

fn capture_dir() -> Option<&'static PathBuf> {
    static DIR: OnceLock<Option<PathBuf>> = OnceLock::new();
    DIR.get_or_init(|| {
        let root = std::env::var_os("NEURAL_BRDF_DATA")
            .map(PathBuf::from)
            .unwrap_or_else(|| PathBuf::from("../shared/data"));
        let src = root.join("diligent/pmsData/ballPNG");
        let dir = PathBuf::from(format!("/dev/shm/nbrdf-fuzz-lights-{}", std::process::id()));
        std::fs::create_dir_all(&dir).ok()?;
        for e in std::fs::read_dir(&src).ok()? {
            let e = e.ok()?;
            let to = dir.join(e.file_name());
            std::fs::copy(e.path(), &to).ok()?;
            let mut perm = std::fs::metadata(&to).ok()?.permissions();
            #[allow(clippy::permissions_set_readonly_false)]
            perm.set_readonly(false);
            std::fs::set_permissions(&to, perm).ok()?;
        }
        Some(dir)
    })
    .as_ref()
}

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let Some(dir) = capture_dir() else { return };
    let cut = data.iter().position(|&b| b == 0).unwrap_or(data.len());
    let (directions, intensities) = (&data[..cut], data.get(cut + 1..).unwrap_or(&[]));
    if std::fs::write(dir.join("light_directions.txt"), directions).is_ok()
        && std::fs::write(dir.join("light_intensities.txt"), intensities).is_ok()
    {
        let _ = dataset_diligent::pms_dir::Capture::open(dir, &stdx::Limits::DEFAULT);
    }
});
