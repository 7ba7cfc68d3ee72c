//! The GPU backends run the same model code as the CPU and agree with it.
//!
//! Built only with a GPU feature (`wgpu` or `cuda`), and run where a device exists. Without a
//! GPU, Mesa's software Vulkan driver (lavapipe, Debian's `mesa-vulkan-drivers`) is one:
//!
//! ```sh
//! sudo apt-get install mesa-vulkan-drivers
//! cargo test -p brdf-neural --features wgpu --test gpu_backend
//! ```
//!
//! With burn's autotune on (the GPU features), the first use of each problem shape benchmarks
//! the candidate kernels: on lavapipe (2 cores) the whole file took 744 s the first time.
//!
//! `BRDF_GPU_BACKEND=cuda` (with `--features cuda`) runs the same tests on CUDA. Every model
//! kind is initialised on the CPU, copied to the GPU and evaluated there: the BRDF values and the
//! gradients of a loss must match the CPU's to 1e-4 (relative). A Single MLP trained for 30
//! Adam steps on both backends from the same start must follow the same loss curve to 1e-3, on
//! the GPU also with its linear layers' batch split into parts as the trainer does there
//! ([`brdf_neural::batch_split`]).
//!
//! `NEURAL_BRDF_GPU_LINEAR=ours` runs the whole file with the linear layers on this workspace's
//! `gpu-kernels` instead of burn's ([`brdf_neural::gpu_linear`]); a test checks that the layers
//! take the kernels the variable names.
#![cfg(any(feature = "wgpu", feature = "cuda"))]

mod common;

use brdf_neural::device::{Backend, BackendDevice};
use brdf_neural::precision::{MatmulPrecision, PrecisionSupport};
use brdf_neural::products::Products;
use brdf_neural::{BrdfBatch, BrdfModel, ModelConfig, ModelKind, SpatialTable};
use burn::module::Module;
use burn::tensor::{Device, Tensor, TensorData};
use common::{OwnedSamples, parameters, rng, samples, small, train_with, values};
use test_support::assert_close_scaled;

/// The backend under test: `BRDF_GPU_BACKEND`, else wgpu when built, else cuda.
fn gpu() -> Backend {
    match std::env::var("BRDF_GPU_BACKEND") {
        Ok(name) => brdf_neural::device::parse_backend(&name).expect("BRDF_GPU_BACKEND"),
        Err(_) if cfg!(feature = "wgpu") => Backend::Wgpu,
        Err(_) => Backend::Cuda,
    }
}

/// f_r of `model` on `s`, and the gradient of sum(f_r^2) with respect to every parameter.
fn forward_and_gradients(
    model: &BrdfModel,
    c: &ModelConfig,
    s: &OwnedSamples,
    device: &Device,
) -> (Vec<f32>, Vec<Vec<f32>>) {
    let out = model.forward(&BrdfBatch::new(c, &s.view(), None, device).unwrap());
    let f = values(out.f.clone());
    let grads = out.f.square().sum().backward();
    let g = burn::optim::GradientsParams::from_grads(grads, model);
    let mut per_param = Vec::new();
    struct Collect<'a>(&'a burn::optim::GradientsParams, &'a mut Vec<Vec<f32>>);
    impl burn::module::ModuleVisitor for Collect<'_> {
        fn visit_float<const D: usize>(&mut self, p: &burn::module::Param<Tensor<D>>) {
            if let Some(g) = self.0.get::<D>(p.id) {
                self.1.push(values(g));
            }
        }
    }
    model.visit(&mut Collect(&g, &mut per_param));
    (f, per_param)
}

#[test]
fn every_model_kind_gives_the_cpus_values_and_gradients_on_the_gpu() {
    let cpu = brdf_neural::device::cpu_training();
    let gpu_device = gpu().training_device().expect("GPU backend built");
    for kind in ModelKind::ALL {
        let c = small(kind);
        let model = BrdfModel::init_seeded(&c, &cpu, 11, None).unwrap();
        let on_gpu = model.clone().fork(&gpu_device);
        assert_eq!(parameters(&on_gpu), parameters(&model), "{kind:?}: copied parameters");
        let s = samples(&mut rng(3), 257, c.spatial_dim);
        let (f_cpu, g_cpu) = forward_and_gradients(&model, &c, &s, &cpu);
        let (f_gpu, g_gpu) = forward_and_gradients(&on_gpu, &c, &s, &gpu_device);
        assert_close_scaled(&format!("{kind:?} f_r"), &f_gpu, &f_cpu, 1e-4);
        assert_eq!(g_gpu.len(), g_cpu.len(), "{kind:?}: gradient count");
        for (i, (g, w)) in g_gpu.iter().zip(&g_cpu).enumerate() {
            assert_close_scaled(&format!("{kind:?} gradient {i}"), g, w, 1e-4);
        }
    }
}

/// Four batches of 512 samples with a smooth target of the light direction.
fn curve_data(c: &ModelConfig, seed: u64) -> Vec<(OwnedSamples, Vec<f32>)> {
    let mut r = rng(seed);
    (0..4)
        .map(|_| {
            let s = samples(&mut r, 512, c.spatial_dim);
            let t: Vec<f32> =
                s.l.iter().flat_map(|l| [0.3 * l[2], 0.2, 0.1 + 0.5 * l[0]]).collect();
            (s, t)
        })
        .collect()
}

/// The loss curves of 30 Adam steps on `data` on the CPU and on the GPU from the same start
/// (initial weights of seed `init`), both with `precision` products, the GPU's with its linear
/// layers' batch split into `parts`; and the model trained on the GPU.
fn loss_curves(
    c: &ModelConfig,
    data: &[(OwnedSamples, Vec<f32>)],
    init: u64,
    (parts, precision): (usize, MatmulPrecision),
) -> (Vec<f32>, Vec<f32>, BrdfModel) {
    let cpu = brdf_neural::device::cpu_training();
    let gpu_device = gpu().training_device().unwrap();
    let model = BrdfModel::init_seeded(c, &cpu, init, None).unwrap();
    let on_gpu = model.clone().fork(&gpu_device);
    let on_cpu = Products { precision, parts: 1, ..Products::F32 };
    let (_, l_cpu) = train_with(model, c, data, (30, 3e-3), &cpu, on_cpu);
    let on_gpu_products = Products { precision, parts, ..Products::F32 };
    let (trained, l_gpu) = train_with(on_gpu, c, data, (30, 3e-3), &gpu_device, on_gpu_products);
    assert!(l_cpu[29] < 0.5 * l_cpu[0], "the CPU fit learns: {l_cpu:?}");
    (l_cpu, l_gpu, trained)
}

#[test]
fn a_single_mlp_trains_along_the_same_loss_curve_on_the_gpu() {
    let c = small(ModelKind::SingleMlp);
    let data = curve_data(&c, 7);
    let (l_cpu, l_gpu, trained) = loss_curves(&c, &data, 5, (1, MatmulPrecision::F32));
    assert_close_scaled("loss curve", &l_gpu, &l_cpu, 1e-3);
    // The trained GPU model comes back to the CPU intact.
    let cpu = brdf_neural::device::cpu_training();
    let back = trained.fork(&cpu);
    let f = values(back.forward(&BrdfBatch::new(&c, &data[0].0.view(), None, &cpu).unwrap()).f);
    assert!(f.iter().all(|v| v.is_finite()));
}

#[test]
fn the_batch_split_trains_along_the_same_loss_curve_on_the_gpu() {
    let c = small(ModelKind::SingleMlp);
    // Two parts of 256 rows each: the split path (batch_split::MIN_ROWS).
    let (l_cpu, l_gpu, _) = loss_curves(&c, &curve_data(&c, 9), 6, (2, MatmulPrecision::F32));
    assert_close_scaled("loss curve with the batch split", &l_gpu, &l_cpu, 1e-3);
}

/// bf16 products on the GPU (tensor cores: `--backend cuda` on Ampere or later): a Single MLP
/// trained in bf16 follows the CPU's bf16 loss curve (the same products rounded to bf16 by the
/// same rule, f32 sums in another order). On wgpu, whose shading language has no tensor-core
/// instructions, bf16 is refused, and the refusal says where it runs.
#[test]
fn bf16_trains_along_the_cpus_bf16_curve_or_is_refused() {
    let backend = gpu();
    if let Err(e) = MatmulPrecision::Bf16.check(backend) {
        let e = e.to_string();
        assert!(backend == Backend::Wgpu && e.contains("--backend cuda"), "{backend}: {e}");
        return;
    }
    let c = small(ModelKind::SingleMlp);
    let data = curve_data(&c, 11);
    let (l_cpu, l_gpu, _) = loss_curves(&c, &data, 8, (1, MatmulPrecision::Bf16));
    assert_close_scaled("bf16 loss curve", &l_gpu, &l_cpu, 1e-2);
}

/// The linear layers take the kernels a batch's products name: `gpu-kernels` for `Ours` on a
/// GPU tensor, burn's for `Burn`, and never ours on a CPU tensor.
#[test]
fn the_linear_layers_take_the_kernels_the_products_name() {
    use brdf_neural::gpu_linear::GpuLinear;
    use brdf_neural::linear_op::uses_gpu_kernels;
    let on_gpu = Tensor::<2>::zeros([4, 3], &gpu().device().unwrap());
    let on_cpu = Tensor::<2>::zeros([4, 3], &brdf_neural::device::cpu());
    assert!(uses_gpu_kernels(&on_gpu, GpuLinear::Ours));
    assert!(!uses_gpu_kernels(&on_gpu, GpuLinear::Burn));
    assert!(!uses_gpu_kernels(&on_cpu, GpuLinear::Ours));
}

#[test]
fn tensors_round_trip_through_the_gpu() {
    let d = gpu().device().unwrap();
    let v: Vec<f32> = (0..1000).map(|i| i as f32 * 0.5 - 3.0).collect();
    let t = Tensor::<2>::from_data(TensorData::new(v.clone(), [100, 10]), &d);
    assert_eq!(values(t.clone() * 2.0), v.iter().map(|x| x * 2.0).collect::<Vec<_>>());
}

/// Spatial rows selected from a table on the GPU (what the trainer does there) are the rows
/// the CPU gathers, bit for bit, and the model's output on the two batches agrees.
#[test]
fn spatial_rows_selected_on_the_gpu_are_the_gathered_rows() {
    let d = gpu().training_device().unwrap();
    let (k, points, n) = (16, 700, 4096);
    let table: Vec<f32> = (0..points * k).map(|i| (i as f32 * 0.37).sin()).collect();
    let rows: Vec<u32> = (0..n).map(|i| ((i * 131 + i / 7) % points) as u32).collect();
    let gathered: Vec<f32> =
        rows.iter().flat_map(|&p| table[p as usize * k..(p as usize + 1) * k].to_vec()).collect();
    let dir = |i: usize, s: f32| {
        let (a, b) = ((i as f32 * 0.11 + s).sin() * 0.6, (i as f32 * 0.03 - s).cos() * 0.6);
        [a, b, (1.0 - a * a - b * b).max(0.0).sqrt()]
    };
    let l: Vec<[f32; 3]> = (0..n).map(|i| dir(i, 0.4)).collect();
    let v: Vec<[f32; 3]> = (0..n).map(|i| dir(i, 1.3)).collect();
    for kind in [ModelKind::SingleMlp, ModelKind::Disney] {
        let c = ModelConfig { kind, spatial_dim: k, ..Default::default() };
        let t = SpatialTable::new(&c, &table, &d).unwrap();
        let a = BrdfBatch::from_owned(&c, gathered.clone(), &l, &v, None, &d).unwrap();
        let b = BrdfBatch::from_table(&c, &t, &rows, &l, &v, None, &d).unwrap();
        assert_eq!(values(a.spatial.clone()), values(b.spatial.clone()), "{kind:?}: rows");
        let model = BrdfModel::init(&c, &d).unwrap();
        let (fa, fb) = (values(model.forward(&a).f), values(model.forward(&b).f));
        assert_close_scaled(&format!("{kind:?}: output"), &fb, &fa, 1e-6);
    }
}
