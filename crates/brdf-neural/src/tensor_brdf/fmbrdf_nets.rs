//! FMBRDF's two pretrained helper networks as fixed (non-trainable) tensors: the Smith Lambda
//! network and the intensity branch of the body-reflection network (spec addendum), with the
//! official weights from `brdf_analytic::Fmbrdf::network_tensors()`.
//!
//! They are plain tensors, not parameters: the optimiser never sees them, but gradients flow
//! through them to their inputs (alpha, beta, eta, kappa).

use burn::module::Module;
use burn::tensor::activation::{relu, softplus};
use burn::tensor::{Device, Tensor, TensorData};

/// One dense layer y = x W^T + b stored as W^T `[in, out]` and b `[1, out]`.
#[derive(Module, Debug)]
pub struct FixedLinear {
    /// W transposed, `[in, out]`.
    pub weight: Tensor<2>,
    /// Bias, `[1, out]`.
    pub bias: Tensor<2>,
}

impl FixedLinear {
    fn forward(&self, x: Tensor<2>) -> Tensor<2> {
        x.matmul(self.weight.clone()) + self.bias.clone()
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

    /// The Smith Lambda of tan(theta) values.
    ///
    /// # Shapes
    /// - tan: `[n, 1]`; alpha, beta: `[1, 1]`
    /// - output: `[n, 1]`, >= 0
    pub fn lambda(&self, tan: Tensor<2>, alpha: Tensor<2>, beta: Tensor<2>) -> Tensor<2> {
        let n = tan.dims()[0];
        let x = Tensor::cat(
            vec![alpha.clone().expand([n, 1]), beta.expand([n, 1]), tan.clone(), tan * alpha],
            1,
        );
        self.lambda.iter().fold(x, |h, layer| relu(layer.forward(h)))
    }

    /// The body-reflection intensity I_b.
    ///
    /// # Shapes
    /// - geometry: `[n, 6]` (see [`super::FmbrdfGeometry::body`]); params: `[n, 4]`
    ///   (eta, alpha, beta, kappa)
    /// - output: `[n, 1]`, >= 0
    pub fn body(&self, geometry: Tensor<2>, params: Tensor<2>) -> Tensor<2> {
        let mut h =
            relu(geometry.matmul(self.body_geometry.clone()) + self.body_params.forward(params));
        let last = self.body.len() - 1;
        for (k, layer) in self.body.iter().enumerate() {
            h = layer.forward(h);
            if k < last {
                h = relu(h);
            }
        }
        softplus(h, 1.0)
    }
}
