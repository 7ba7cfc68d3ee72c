//! Times the LBO eigen-solve on a mesh and checks the result.
//!
//! ```text
//! cargo run --release -p mesh-encoding --example lbo_bench -- <mesh> [k] [--block B]
//!     [--threads T] [--reference eigenvalues.txt] [--dump-mtx DIR] [--out eigenvalues.txt]
//! ```
//! `<mesh>` is a path or a name under `$NEURAL_BRDF_DATA/meshes` (default
//! `../shared/data/meshes`), `k` the number of pairs including the constant one (default 513),
//! `--threads` the solver's threads (default 1; 0 = faer's global setting).
//! `--reference` compares with eigenvalues (one a line) from another solver; `--dump-mtx` writes
//! `L` and `M` as Matrix Market files for such a cross-check (for example scipy's
//! `eigsh(L, k, M, sigma=0)`); `--out` writes the eigenvalues.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use mesh_encoding::lbo::{EigenSettings, LboMatrices, smallest_eigenpairs};
use mesh_encoding::load_mesh;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut positional = Vec::new();
    let mut settings = EigenSettings::default();
    let mut reference = None;
    let mut dump = None;
    let mut out = None;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--block" => settings.block_size = it.next().ok_or("--block needs a value")?.parse()?,
            "--maxf" => {
                settings.max_basis_factor = it.next().ok_or("--maxf needs a value")?.parse()?
            }
            "--slice" => settings.slice_size = it.next().ok_or("--slice needs a value")?.parse()?,
            "--threads" => {
                settings.threads = it.next().ok_or("--threads needs a value")?.parse()?
            }
            "--tol" => settings.tolerance = it.next().ok_or("--tol needs a value")?.parse()?,
            "--reference" => reference = Some(PathBuf::from(it.next().ok_or("--reference")?)),
            "--dump-mtx" => dump = Some(PathBuf::from(it.next().ok_or("--dump-mtx")?)),
            "--out" => out = Some(PathBuf::from(it.next().ok_or("--out")?)),
            _ => positional.push(a.clone()),
        }
    }
    let name = positional.first().ok_or("usage: lbo_bench <mesh> [k]")?;
    let k: usize = positional.get(1).map(|s| s.parse()).transpose()?.unwrap_or(513);
    let path = resolve(name);

    let t0 = Instant::now();
    let loaded = load_mesh(&path, &Default::default())?;
    let t_load = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let matrices = LboMatrices::from_mesh(&loaded.mesh)?;
    let t_assemble = t1.elapsed().as_secs_f64();
    println!(
        "mesh {} : {} vertices, {} triangles (load {t_load:.2} s, assemble {t_assemble:.3} s)",
        path.display(),
        matrices.vertex_count(),
        loaded.mesh.triangle_count()
    );
    if let Some(dir) = &dump {
        std::fs::create_dir_all(dir)?;
        write_mtx(&dir.join("L.mtx"), &matrices)?;
        let mut f = std::io::BufWriter::new(std::fs::File::create(dir.join("M.txt"))?);
        for m in &matrices.mass {
            writeln!(f, "{m:.17e}")?;
        }
        println!("wrote {}/L.mtx and M.txt", dir.display());
    }
    let (pairs, report) = smallest_eigenpairs(&matrices, k, &settings)?;
    let total = t1.elapsed().as_secs_f64();
    println!(
        "k = {k}, block {}: solve {:.2} s (factor {:.2} s), basis {}, {} Ritz checks; \
         assemble+solve {total:.2} s",
        settings.block_size,
        report.total_seconds,
        report.factor_seconds,
        report.basis_size,
        report.ritz_checks
    );
    println!(
        "phases: factor {:.2} s, block solves {:.2} s, orthogonalisation {:.2} s, Rayleigh-Ritz \
         {:.2} s, inertia check {:.2} s ({:?})",
        report.factor_seconds,
        report.solve_seconds,
        report.orthogonalize_seconds,
        report.ritz_seconds,
        report.check_seconds,
        report.inertia
    );
    let res = pairs.relative_residuals(&matrices);
    let max_res = res.iter().copied().fold(0.0, f64::max);
    println!(
        "max relative residual {max_res:.2e}, max |Phi^T M Phi - I| {:.2e}",
        pairs.orthonormality_error(&matrices.mass)
    );
    let v = &pairs.values;
    println!("lambda[0..4] = {:?}, lambda[k-1] = {:.10e}", &v[..4.min(k)], v[k - 1]);
    if let Some(out) = &out {
        let mut f = std::io::BufWriter::new(std::fs::File::create(out)?);
        for x in v {
            writeln!(f, "{x:.17e}")?;
        }
    }
    if let Some(reference) = &reference {
        let text = std::fs::read_to_string(reference)?;
        let r: Vec<f64> = text.split_whitespace().map(|s| s.parse()).collect::<Result<_, _>>()?;
        let scale = v[k - 1].abs();
        let mut worst: f64 = 0.0;
        for (i, (a, b)) in v.iter().zip(&r).enumerate() {
            // Relative to the eigenvalue itself, except the (near-)zero first one.
            let rel = (a - b).abs() / b.abs().max(1e-6 * scale);
            if rel > worst {
                worst = rel;
                println!(
                    "  worst so far: i = {i}, ours {a:.12e}, reference {b:.12e}, rel {rel:.2e}"
                );
            }
        }
        println!(
            "max relative eigenvalue difference vs reference: {worst:.2e} ({} values)",
            r.len().min(k)
        );
    }
    Ok(())
}

fn resolve(name: &str) -> PathBuf {
    let p = PathBuf::from(name);
    if p.exists() {
        return p;
    }
    let data = std::env::var_os("NEURAL_BRDF_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"));
    let with_ext = if name.contains('.') { name.to_string() } else { format!("{name}.obj") };
    data.join("meshes").join(with_ext)
}

fn write_mtx(path: &Path, m: &LboMatrices) -> std::io::Result<()> {
    let l = m.stiffness.as_ref();
    let n = m.vertex_count();
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(f, "%%MatrixMarket matrix coordinate real general")?;
    writeln!(f, "{n} {n} {}", l.compute_nnz())?;
    for j in 0..n {
        for (i, v) in l.row_idx_of_col(j).zip(l.val_of_col(j)) {
            writeln!(f, "{} {} {v:.17e}", i + 1, j + 1)?;
        }
    }
    Ok(())
}
