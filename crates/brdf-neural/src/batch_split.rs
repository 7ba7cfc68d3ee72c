//! Splitting a weight gradient's sum over the batch into parts (split-K), for GPU backends.
//!
//! A linear layer's weight gradient is `Xᵀ G`: a `[d_in, d_out]` result (128 x 128 for a
//! hidden layer) whose every element is a sum over the whole batch (32,768 rows at the paper's
//! budget). A matrix-product kernel without split-K (CubeCL's, as of 0.11) parallelizes over the
//! output only: 16,384 sums, each walking all 32,768 rows, too little parallel work for a large
//! GPU; split into 64 parts and summed, the product ran several times faster on an H200
//! (`benches/README.md`).
//!
//! For a batch whose [`Products::parts`] exceeds 1, the network's linear layers compute
//! `y = X W + b` as a batched product over `parts` blocks of rows, `y_p = X_p W + b`, with `W`
//! broadcast: the
//! forward value is the same product (backends fold a broadcast right operand into one
//! product), and burn's autodiff turns the broadcast into `parts` independent products
//! `X_pᵀ G_p` and one sum over the parts, the split-K schedule that cuBLAS picks for such shapes.
//! Only the summation order of the weight gradients changes. Batches that `parts` does not
//! divide, or with fewer than [`MIN_ROWS`] rows a part, keep the plain product.
//!
//! The split is part of the batch's [`Products`], like the precision; the default (1 part)
//! is the plain product, which keeps the CPU fits bit-identical to before. A training loop on
//! a GPU asks for [`crate::products::gpu_parts`] ([`Products::training`]).

use crate::products::Products;
use burn::nn::Linear;
use burn::tensor::Tensor;

/// The fewest rows a part may have; smaller parts would make the sum over the parts the cost.
pub const MIN_ROWS: usize = 256;

/// `layer` applied to `x` (`[rows, d_in]` to `[rows, d_out]`), split into
/// [`Products::parts`]; unsplit, through [`crate::linear_op::linear`] with `products`.
pub(crate) fn linear(layer: &Linear, x: Tensor<2>, products: Products) -> Tensor<2> {
    let parts = products.parts;
    let [rows, d_in] = x.dims();
    if !splits(&x, products) {
        // The weight first: lazily initialised parameters draw their values at their first
        // `val()`, in the order burn's `Linear::forward` reads them.
        let weight = layer.weight.val();
        let bias = layer.bias.as_ref().map(|b| b.val());
        return crate::linear_op::linear(x, weight, bias, products);
    }
    let weight = layer.weight.val();
    let d_out = weight.dims()[1];
    let y = x
        .reshape([parts, rows / parts, d_in])
        .matmul(weight.unsqueeze::<3>())
        .reshape([rows, d_out]);
    match &layer.bias {
        Some(bias) => y + bias.val().unsqueeze::<2>(),
        None => y,
    }
}

/// Whether [`linear`] splits `x`'s rows into [`Products::parts`] (see the module docs).
fn splits(x: &Tensor<2>, products: Products) -> bool {
    let (parts, rows) = (products.parts, x.dims()[0]);
    // The gpu-kernels split the weight gradients inside their own kernel.
    let own_kernels = crate::linear_op::uses_gpu_kernels(x, products.gpu.linear);
    !(parts <= 1 || !rows.is_multiple_of(parts) || rows / parts < MIN_ROWS || own_kernels)
}

/// `relu(layer(x))`, a hidden layer: unsplit and with a bias, through
/// [`crate::linear_op::linear_relu`] (the bias and the ReLU inside the product); otherwise
/// [`linear`] followed by [`crate::linear_op::relu`]. The same values either way.
pub(crate) fn linear_relu(layer: &Linear, x: Tensor<2>, products: Products) -> Tensor<2> {
    if splits(&x, products) || layer.bias.is_none() {
        return crate::linear_op::relu(linear(layer, x, products));
    }
    // The weight first, as in `linear`.
    let weight = layer.weight.val();
    let bias = layer.bias.as_ref().map(|b| b.val()).expect("checked above");
    crate::linear_op::linear_relu(x, weight, bias, products)
}

#[cfg(test)]
mod tests {
    use super::*;
    use burn::nn::LinearConfig;
    use burn::tensor::{Distribution, Tolerance};

    #[test]
    fn split_layers_give_the_plain_values_and_gradients() {
        let device = crate::device::cpu().autodiff();
        let layer = LinearConfig::new(5, 3).init(&device);
        let x = Tensor::<2>::random([1_024, 5], Distribution::Normal(0.0, 1.0), &device);
        let run = |parts: usize| {
            let products = Products { parts, ..Products::F32 };
            let y = linear(&layer, x.clone(), products);
            let grads = (y.clone() * y.clone()).sum().backward();
            let gw = layer.weight.val().grad(&grads).expect("weight gradient");
            let gb = layer.bias.as_ref().unwrap().val().grad(&grads).expect("bias gradient");
            (y.inner(), gw, gb)
        };
        let (y1, gw1, gb1) = run(1);
        let (y4, gw4, gb4) = run(4);
        y4.into_data().assert_approx_eq::<f32>(&y1.into_data(), Tolerance::default());
        gw4.into_data().assert_approx_eq::<f32>(&gw1.into_data(), Tolerance::default());
        gb4.into_data().assert_approx_eq::<f32>(&gb1.into_data(), Tolerance::default());
        // Too few rows a part: the plain product, to the bit.
        let (y8, gw8, _) = run(8);
        assert_eq!(y8.into_data(), run(1).0.into_data());
        assert_eq!(gw8.into_data(), run(1).1.into_data());
    }
}
