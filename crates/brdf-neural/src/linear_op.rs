//! The models' linear layers, `y = x W + b`, as a burn backend extension ([`LinearKernels`]):
//! on the flex CPU backend the three products of a layer (forward, input gradient, weight
//! gradient) run on this workspace's kernels (`cpu-kernels`, through the private module
//! `flex_linear`); on a GPU they run on `gpu-kernels` (through `cube_linear`) where
//! [`crate::gpu_linear`] says so, else, as on every other backend, [`linear`] is burn's own
//! `linear`.
//!
//! burn's extension mechanism (`#[backend_extension]`) routes the operation through burn's
//! dispatch layer to the backend that holds the tensors, so burn itself stays unpatched. Its
//! autodiff half is written here: [`LinearKernels`] for `Autodiff<B>` records one graph node per
//! layer whose backward pass calls the backend's input-gradient and weight-gradient kernels and
//! burn's bias gradient, the same three gradients as burn's own `linear`.
//!
//! How the products are computed ([`Products`]: the precision, and for bf16 on the CPU whether
//! AMX tiles are taken) is an argument of the operation, kept in the graph node for the
//! backward pass: a bf16 training step computes its forward and backward products in bf16, and
//! nothing else in the process changes precision.

use crate::products::Products;
use burn::tensor::Tensor;
#[cfg(any(feature = "flex", feature = "wgpu", feature = "cuda"))]
pub use kernels::LinearKernels;

/// `x W + b` for x `[rows, d_in]`, W `[d_in, d_out]`, b `[d_out]`, its products as `products`
/// says on the flex backend (f32 elsewhere:
/// [`PrecisionSupport::check`](crate::precision::PrecisionSupport::check) refuses bf16 on
/// other backends); burn's `linear` on every other backend.
pub fn linear(
    x: Tensor<2>,
    weight: Tensor<2>,
    bias: Option<Tensor<1>>,
    products: Products,
) -> Tensor<2> {
    #[cfg(feature = "flex")]
    if x.device().inner() == burn::tensor::Device::flex() {
        return kernels::linear(x, weight, bias, products);
    }
    #[cfg(any(feature = "wgpu", feature = "cuda"))]
    if uses_gpu_kernels(&x, products.gpu.linear) {
        return kernels::linear(x, weight, bias, products);
    }
    let _ = products;
    burn::tensor::module::linear(x, weight, bias)
}

/// `relu(x W + b)`, a hidden layer: the same values and gradients as [`linear`] followed by
/// [`relu`], with the bias and the ReLU applied inside the product on the flex backend (no
/// pass of its own over the output, whose buffer the backward pass keeps for the mask).
pub fn linear_relu(
    x: Tensor<2>,
    weight: Tensor<2>,
    bias: Tensor<1>,
    products: Products,
) -> Tensor<2> {
    #[cfg(feature = "flex")]
    if x.device().inner() == burn::tensor::Device::flex() {
        return kernels::linear_relu(x, weight, bias, products);
    }
    #[cfg(any(feature = "wgpu", feature = "cuda"))]
    if uses_gpu_kernels(&x, products.gpu.linear) {
        return kernels::linear_relu(x, weight, bias, products);
    }
    relu(linear(x, weight, Some(bias), products))
}

/// Whether `x` is on a GPU (CubeCL) device whose linear layers run on this workspace's
/// `gpu-kernels` when a batch's products ask for `linear` ([`crate::gpu_linear`]).
pub fn uses_gpu_kernels(x: &Tensor<2>, linear: crate::gpu_linear::GpuLinear) -> bool {
    linear == crate::gpu_linear::GpuLinear::Ours && crate::device::on_gpu(x)
}

/// `max(x, 0)`, its backward pass on this workspace's kernels on the flex backend (the mask
/// applied in place to the upstream gradient, on every thread); burn's `relu` elsewhere.
pub fn relu(x: Tensor<2>) -> Tensor<2> {
    #[cfg(feature = "flex")]
    if x.device().inner() == burn::tensor::Device::flex() {
        return kernels::relu(x);
    }
    burn::tensor::activation::relu(x)
}

#[cfg(any(feature = "flex", feature = "wgpu", feature = "cuda"))]
mod kernels;
