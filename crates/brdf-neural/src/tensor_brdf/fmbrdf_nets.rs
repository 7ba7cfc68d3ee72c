//! FMBRDF's two pretrained helper networks as fixed (non-trainable) tensors: the Smith Lambda
//! network and the intensity branch of the body-reflection network (spec addendum), with the
//! official weights from `brdf_analytic::Fmbrdf::network_tensors()`.
//!
//! They are plain tensors, not parameters: the optimiser never sees them, but gradients flow
//! through them to their inputs (alpha, beta, eta, kappa).

use super::lambda_segments::Segments;
use crate::products::Products;
use burn::module::Module;
use burn::tensor::activation::{relu, softplus};
use burn::tensor::{Device, Int, Tensor, TensorData};

/// One dense layer y = x W^T + b stored as W^T `[in, out]` and b `[1, out]`.
#[derive(Module, Debug)]
pub struct FixedLinear {
    /// W transposed, `[in, out]`.
    pub weight: Tensor<2>,
    /// Bias, `[1, out]`.
    pub bias: Tensor<2>,
}

impl FixedLinear {
    fn forward(&self, x: Tensor<2>, products: Products) -> Tensor<2> {
        let [_, n] = self.bias.dims();
        let bias = self.bias.clone().reshape([n]);
        crate::linear_op::linear(x, self.weight.clone(), Some(bias), products)
    }

    /// `relu(self.forward(x))`, the bias and the ReLU inside the product
    /// ([`crate::linear_op::linear_relu`]): the same values and gradients.
    fn forward_relu(&self, x: Tensor<2>, products: Products) -> Tensor<2> {
        let [_, n] = self.bias.dims();
        let bias = self.bias.clone().reshape([n]);
        crate::linear_op::linear_relu(x, self.weight.clone(), bias, products)
    }
}

/// The two helper networks.
#[derive(Module, Debug)]
pub struct FmbrdfNets {
    /// Smith Lambda network, 4 -> 300 -> 100 -> 50 -> 1, ReLU after every layer.
    pub lambda: Vec<FixedLinear>,
    /// Body network layer 1 restricted to the six geometry inputs (n''_x, n''_y, n''_z, l''_x,
    /// l''_z, n''.l''), `[6, 200]`.
    pub body_geometry: Tensor<2>,
    /// Body network layer 1 restricted to (eta, alpha, beta, kappa), `[4, 200]`, with its bias.
    pub body_params: FixedLinear,
    /// Body network layers 2 to 4 (200 -> 100 -> 100 -> 1), ReLU between, softplus at the end.
    pub body: Vec<FixedLinear>,
}

/// Geometry columns of the body network's 11 inputs (l''_y, column 4, is always 0).
const BODY_GEOMETRY_COLUMNS: [usize; 6] = [0, 1, 2, 3, 5, 10];
/// Parameter columns: eta, alpha, beta, kappa.
const BODY_PARAM_COLUMNS: [usize; 4] = [6, 7, 8, 9];

impl FmbrdfNets {
    /// Uploads the shipped weights to `device`.
    pub fn new(device: &Device) -> Self {
        let raw: Vec<(&str, &[usize], &[f32])> =
            brdf_analytic::Fmbrdf::<f32>::network_tensors().collect();
        let find = |name: &str| {
            raw.iter()
                .find(|(n, _, _)| *n == name)
                .unwrap_or_else(|| panic!("FMBRDF weights lack {name}"))
        };
        // PyTorch weight [out, in] -> W^T [in, out], keeping only `cols` of the inputs.
        let transposed = |name: &str, cols: Option<&[usize]>| {
            let (_, shape, w) = find(name);
            let (n_out, n_in) = (shape[0], shape[1]);
            let cols: Vec<usize> = cols.map_or_else(|| (0..n_in).collect(), <[usize]>::to_vec);
            let mut wt = Vec::with_capacity(cols.len() * n_out);
            for &i in &cols {
                wt.extend((0..n_out).map(|o| w[o * n_in + i]));
            }
            Tensor::<2>::from_data(TensorData::new(wt, [cols.len(), n_out]), device)
        };
        let bias = |name: &str| {
            let (_, shape, b) = find(name);
            Tensor::<2>::from_data(TensorData::new(b.to_vec(), [1, shape[0]]), device)
        };
        let layer = |prefix: &str| FixedLinear {
            weight: transposed(&format!("{prefix}.weight"), None),
            bias: bias(&format!("{prefix}.bias")),
        };
        Self {
            lambda: (1..=4).map(|k| layer(&format!("shadowing.fc{k}"))).collect(),
            body_geometry: transposed("body_reflection.fc_I1.weight", Some(&BODY_GEOMETRY_COLUMNS)),
            body_params: FixedLinear {
                weight: transposed("body_reflection.fc_I1.weight", Some(&BODY_PARAM_COLUMNS)),
                bias: bias("body_reflection.fc_I1.bias"),
            },
            body: (2..=4).map(|k| layer(&format!("body_reflection.fc_I{k}"))).collect(),
        }
    }

    /// The Smith Lambda of tan(theta) values, evaluated along the network's one varying input:
    /// the first layer's active units are found per segment of the t axis on the host, and the
    /// second layer's product runs once per segment instead of once per row (the derivation is
    /// in `lambda_segments.rs`). Equal to [`Self::lambda_dense`] up to f32 rounding, with the
    /// same gradients in alpha and beta; falls back to it when alpha, beta or a tan value is
    /// not finite.
    ///
    /// Reads the first layer's two `[1, 300]` coefficient rows back from the device once a call.
    ///
    /// # Shapes
    /// - tan: `[n, 1]`, with the same values in `tan_host`; alpha, beta: `[1, 1]`
    /// - output: `[n, 1]`, >= 0
    ///
    /// # Panics
    /// If `tan_host` does not hold n values.
    pub fn lambda(
        &self,
        tan: Tensor<2>,
        tan_host: &[f32],
        alpha: Tensor<2>,
        beta: Tensor<2>,
        products: Products,
    ) -> Tensor<2> {
        let n = tan.dims()[0];
        assert_eq!(tan_host.len(), n, "FmbrdfNets::lambda: tan_host length");
        // On a GPU, the dense network. The segments need the first layer's a and c on the host,
        // a wait for the GPU in every step (which the training loop must not have), and the
        // backward pass of their gather is a scatter-add of every row into at most 301. On an
        // H200 the segments made FMBRDF's step ten times slower than PyTorch's
        // (`benches/README.md`).
        if crate::device::on_gpu(&tan) {
            return self.lambda_dense(tan, alpha, beta, products);
        }
        let (first, second) = (&self.lambda[0], &self.lambda[1]);
        let row = |k: usize| first.weight.clone().narrow(0, k, 1);
        // z1 = a + t c (the first layer's input is (alpha, beta, t, t alpha)).
        let a = alpha.clone() * row(0) + beta.clone() * row(1) + first.bias.clone();
        let c = row(2) + alpha.clone() * row(3);
        let host =
            |x: &Tensor<2>| x.clone().into_data().convert::<f32>().try_into_vec::<f32>().ok();
        let segments = match (host(&a), host(&c)) {
            (Some(a), Some(c)) => Segments::of(&a, &c, tan_host),
            _ => None,
        };
        let Some(segments) = segments else {
            return self.lambda_dense(tan, alpha, beta, products);
        };
        let device = tan.device();
        let width = first.bias.dims()[1];
        let mask = Tensor::<2>::from_data(
            TensorData::new(segments.mask, [segments.count, width]),
            &device,
        );
        let index = Tensor::<1, Int>::from_data(TensorData::new(segments.of_row, [n]), &device);
        let product =
            |x: Tensor<2>| crate::linear_op::linear(x, second.weight.clone(), None, products);
        let p = product(mask.clone() * a);
        let q = product(mask * c);
        let z2 = p.select(0, index.clone()) + tan * q.select(0, index) + second.bias.clone();
        self.lambda[2..].iter().fold(relu(z2), |h, layer| layer.forward_relu(h, products))
    }

    /// The Smith Lambda of tan(theta) values, every layer a dense product over the rows (the
    /// network as trained; [`Self::lambda`] is the same function evaluated faster).
    ///
    /// # Shapes
    /// - tan: `[n, 1]`; alpha, beta: `[1, 1]`
    /// - output: `[n, 1]`, >= 0
    pub fn lambda_dense(
        &self,
        tan: Tensor<2>,
        alpha: Tensor<2>,
        beta: Tensor<2>,
        products: Products,
    ) -> Tensor<2> {
        let n = tan.dims()[0];
        let x = Tensor::cat(
            vec![alpha.clone().expand([n, 1]), beta.expand([n, 1]), tan.clone(), tan * alpha],
            1,
        );
        self.lambda.iter().fold(x, |h, layer| layer.forward_relu(h, products))
    }

    /// The body-reflection intensity I_b.
    ///
    /// # Shapes
    /// - geometry: `[n, 6]` (see [`super::FmbrdfGeometry::body`]); params: `[n, 4]`
    ///   (eta, alpha, beta, kappa)
    /// - output: `[n, 1]`, >= 0
    pub fn body(&self, geometry: Tensor<2>, params: Tensor<2>, products: Products) -> Tensor<2> {
        let geometry =
            crate::linear_op::linear(geometry, self.body_geometry.clone(), None, products);
        let mut h = relu(geometry + self.body_params.forward(params, products));
        let last = self.body.len() - 1;
        for (k, layer) in self.body.iter().enumerate() {
            h = if k < last { layer.forward_relu(h, products) } else { layer.forward(h, products) };
        }
        softplus(h, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn values(t: Tensor<2>) -> Vec<f32> {
        t.into_data().convert::<f32>().try_into_vec::<f32>().unwrap()
    }

    /// The segment evaluation against the dense network: values, and the gradients in alpha
    /// and beta of a weighted sum, over the parameters' range and t from 0 to grazing.
    #[test]
    fn lambda_by_segments_equals_the_dense_network() {
        let device = crate::device::cpu().autodiff();
        let nets = FmbrdfNets::new(&device);
        let mut s = 7_u64;
        let mut uniform = move || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (s >> 40) as f32 / (1u64 << 24) as f32
        };
        for (alpha, beta) in [
            (0.001_f32, 0.5_f32),
            (0.05, 0.7),
            (0.3, 2.0),
            (1.0, 3.5),
            (std::f32::consts::TAU, 4.0),
        ] {
            // Mostly moderate angles, some grazing ones, and repeated and zero values.
            let mut t: Vec<f32> = (0..3_000)
                .map(|i| match i % 10 {
                    0 => 0.0,
                    1 => 1.0,
                    2 => 10.0_f32.powf(3.0 * uniform()),
                    _ => 3.0 * uniform(),
                })
                .collect();
            t.push(1e6);
            let n = t.len();
            let weight: Vec<f32> = (0..n).map(|_| uniform() - 0.3).collect();
            let run = |segments: bool| {
                let a = Tensor::<2>::from_data(TensorData::new(vec![alpha], [1, 1]), &device)
                    .require_grad();
                let b = Tensor::<2>::from_data(TensorData::new(vec![beta], [1, 1]), &device)
                    .require_grad();
                let tan = Tensor::<2>::from_data(TensorData::new(t.clone(), [n, 1]), &device);
                let w = Tensor::<2>::from_data(TensorData::new(weight.clone(), [n, 1]), &device);
                let y = if segments {
                    nets.lambda(tan, &t, a.clone(), b.clone(), Products::F32)
                } else {
                    nets.lambda_dense(tan, a.clone(), b.clone(), Products::F32)
                };
                let grads = (y.clone() * w).sum().backward();
                let ga = values(a.grad(&grads).expect("alpha gradient"))[0];
                let gb = values(b.grad(&grads).expect("beta gradient"))[0];
                (values(y.inner()), ga, gb)
            };
            let (fast, ga, gb) = run(true);
            let (dense, ga_ref, gb_ref) = run(false);
            let scale = dense.iter().fold(0.0_f32, |m, x| m.max(x.abs())).max(1e-3);
            for (i, (x, y)) in fast.iter().zip(&dense).enumerate() {
                assert!(
                    (x - y).abs() <= 2e-5 * (y.abs() + 1e-3 * scale),
                    "alpha {alpha} beta {beta} t {}: {x} vs {y}",
                    t[i]
                );
            }
            for (g, g_ref, name) in [(ga, ga_ref, "alpha"), (gb, gb_ref, "beta")] {
                assert!(g.is_finite() && g_ref.is_finite());
                assert!(
                    (g - g_ref).abs() <= 1e-4 * g_ref.abs().max(1e-3),
                    "{name} gradient at alpha {alpha} beta {beta}: {g} vs {g_ref}"
                );
            }
        }
    }

    #[test]
    fn non_finite_alpha_falls_back_to_the_dense_network() {
        let device = crate::device::cpu();
        let nets = FmbrdfNets::new(&device);
        let t = [0.5_f32, 2.0];
        let tan = Tensor::<2>::from_data(TensorData::new(t.to_vec(), [2, 1]), &device);
        let nan = Tensor::<2>::from_data(TensorData::new(vec![f32::NAN], [1, 1]), &device);
        let beta = Tensor::<2>::from_data(TensorData::new(vec![1.0_f32], [1, 1]), &device);
        let y = values(nets.lambda(tan.clone(), &t, nan.clone(), beta.clone(), Products::F32));
        let y_ref = values(nets.lambda_dense(tan, nan, beta, Products::F32));
        assert_eq!(y.len(), 2);
        assert!(y.iter().zip(&y_ref).all(|(a, b)| a.to_bits() == b.to_bits()));
    }
}
