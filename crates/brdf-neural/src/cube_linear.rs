//! The glue between burn's CubeCL tensors and the `gpu-kernels` crate: [`LinearKernels`] for
//! `CubeBackend` (burn-cubecl's unfused backend; the extension macro lowers each operation into
//! one custom operation of burn's fusion, which calls these when it executes).
//!
//! The kernels take row-major f32 matrices: an operand with other strides is first made
//! contiguous (burn's own kernel), and a tensor of another float type, or a shape past the
//! kernels' grid limits, takes burn's own operations instead, so every input has an answer.
//! A layer's products run in the precision and on the tile and split length of the batch's
//! products ([`Products`]): f32, or
//! [`MatmulPrecision::Bf16`] on tensor cores (`gpu_kernels::gemm_cmma`; CUDA on Ampere or
//! later; [`PrecisionSupport::check`](crate::precision::PrecisionSupport::check) refuses bf16
//! on wgpu, whose WGSL has no such instructions). A CUDA device without them runs the products in f32, and says so once.

use crate::linear_op::LinearKernels;
use crate::precision::MatmulPrecision;
use crate::products::Products;
use burn::backend::ops::{ActivationOps, FloatTensorOps};
use burn::backend::tensor::FloatTensor;
use burn::tensor::{DType, Shape};
use burn_cubecl::CubeBackend;
use burn_cubecl::tensor::CubeTensor;
use gpu_kernels::linear::{self as kernels, Matrix};
use gpu_kernels::plan::{Precision, Tuning};
use std::sync::Once;

type B = CubeBackend;

/// The kernels' spelling of `p` on `client`'s device: bf16 where it has tensor cores for it,
/// else f32 (with a warning, once a process).
fn kernel_precision(client: &cubecl::prelude::Client, p: MatmulPrecision) -> Precision {
    match p {
        MatmulPrecision::F32 => Precision::F32,
        MatmulPrecision::Bf16 if kernels::bf16_supported(client) => Precision::Bf16,
        MatmulPrecision::Bf16 => {
            static WARNED: Once = Once::new();
            WARNED.call_once(|| {
                eprintln!(
                    "warning: matmul_precision = \"bf16\" on a GPU without bf16 tensor cores \
                     (CubeCL's cmma; CUDA on Ampere or later): the products run in f32"
                )
            });
            Precision::F32
        }
        // Refused before a GPU batch is built (`PrecisionSupport::check`).
        MatmulPrecision::F16 => Precision::F32,
    }
}

/// The kernels' tile and split length of a batch's products.
fn tuning(products: Products) -> Tuning {
    crate::gpu_linear::kernel_tuning(products.gpu)
}

/// The tensor as a row-major matrix (made contiguous first where it is not), or `None` for a
/// type other than f32 or a shape that is not 2-d.
fn matrix(t: CubeTensor) -> Option<(CubeTensor, Matrix)> {
    if t.dtype != DType::F32 || t.meta.shape().num_dims() != 2 {
        return None;
    }
    let t = if t.is_contiguous() { t } else { burn_cubecl::kernel::into_contiguous(t) };
    let [rows, cols] = t.meta.shape().dims::<2>();
    let m = Matrix {
        handle: t.handle.clone(),
        rows: u32::try_from(rows).ok()?,
        cols: u32::try_from(cols).ok()?,
    };
    Some((t, m))
}

/// A kernel's output as a tensor on `like`'s device.
fn tensor(like: &CubeTensor, m: Matrix, shape: Shape) -> CubeTensor {
    CubeTensor::new_contiguous(
        like.client.clone(),
        like.device.clone(),
        shape,
        m.handle,
        DType::F32,
    )
}

/// `b` `[n]` seen as `[1, n]`, for burn's broadcast add.
fn row(b: FloatTensor<B>) -> FloatTensor<B> {
    let n = b.meta.shape()[0];
    B::float_reshape(b, Shape::new([1, n]))
}

/// `x W + b`, or `relu(x W + b)` when `relu`, on the kernels (the ReLU in the product's
/// epilogue), else on burn's own operations.
fn with_bias(
    x: FloatTensor<B>,
    weight: FloatTensor<B>,
    bias: FloatTensor<B>,
    relu: bool,
    products: Products,
) -> FloatTensor<B> {
    if let (Some((xt, xm)), Some((_, wm)), Some((_, bm))) =
        (matrix(x.clone()), matrix(weight.clone()), matrix(row(bias.clone())))
        && let p = kernel_precision(&xt.client, products.precision)
        && let Ok(y) =
            kernels::forward(&xt.client, &xm, &wm, Some(&bm.handle), relu, p, tuning(products))
    {
        let shape = Shape::new([y.rows as usize, y.cols as usize]);
        return tensor(&xt, y, shape);
    }
    let y = B::float_add(B::float_matmul(x, weight), row(bias));
    if relu { <B as ActivationOps<B>>::relu(y) } else { y }
}

impl LinearKernels for CubeBackend {
    fn kernel_linear(
        x: FloatTensor<Self>,
        weight: FloatTensor<Self>,
        bias: FloatTensor<Self>,
        products: Products,
    ) -> FloatTensor<Self> {
        with_bias(x, weight, bias, false, products)
    }

    fn kernel_linear_relu(
        x: FloatTensor<Self>,
        weight: FloatTensor<Self>,
        bias: FloatTensor<Self>,
        products: Products,
    ) -> FloatTensor<Self> {
        with_bias(x, weight, bias, true, products)
    }

    fn kernel_linear_no_bias(
        x: FloatTensor<Self>,
        weight: FloatTensor<Self>,
        products: Products,
    ) -> FloatTensor<Self> {
        if let (Some((xt, xm)), Some((_, wm))) = (matrix(x.clone()), matrix(weight.clone()))
            && let p = kernel_precision(&xt.client, products.precision)
            && let Ok(y) = kernels::forward(&xt.client, &xm, &wm, None, false, p, tuning(products))
        {
            let shape = Shape::new([y.rows as usize, y.cols as usize]);
            return tensor(&xt, y, shape);
        }
        B::float_matmul(x, weight)
    }

    fn kernel_linear_x_backward(
        weight: FloatTensor<Self>,
        output_grad: FloatTensor<Self>,
        products: Products,
    ) -> FloatTensor<Self> {
        if let (Some((_, wm)), Some((gt, gm))) =
            (matrix(weight.clone()), matrix(output_grad.clone()))
            && let p = kernel_precision(&gt.client, products.precision)
            && let Ok(dx) = kernels::x_backward(&gt.client, &wm, &gm, p, tuning(products))
        {
            let shape = Shape::new([dx.rows as usize, dx.cols as usize]);
            return tensor(&gt, dx, shape);
        }
        B::float_matmul(output_grad, B::float_transpose(weight))
    }

    fn kernel_linear_weight_backward(
        x: FloatTensor<Self>,
        output_grad: FloatTensor<Self>,
        products: Products,
    ) -> FloatTensor<Self> {
        if let (Some((xt, xm)), Some((_, gm))) = (matrix(x.clone()), matrix(output_grad.clone()))
            && let p = kernel_precision(&xt.client, products.precision)
            && let Ok(dw) = kernels::weight_backward(&xt.client, &xm, &gm, p, tuning(products))
        {
            let shape = Shape::new([dw.rows as usize, dw.cols as usize]);
            return tensor(&xt, dw, shape);
        }
        B::float_matmul(B::float_transpose(x), output_grad)
    }

    fn kernel_linear_bias_backward(output_grad: FloatTensor<Self>) -> FloatTensor<Self> {
        if let Some((gt, gm)) = matrix(output_grad.clone())
            && let Ok(db) = kernels::bias_backward(&gt.client, &gm)
        {
            let shape = Shape::new([db.cols as usize]);
            return tensor(&gt, db, shape);
        }
        let n = output_grad.meta.shape()[1];
        B::float_reshape(B::float_sum_dim(output_grad, 0), Shape::new([n]))
    }

    fn kernel_relu(x: FloatTensor<Self>) -> FloatTensor<Self> {
        <B as ActivationOps<B>>::relu(x)
    }

    fn kernel_relu_backward(x: FloatTensor<Self>, grad: FloatTensor<Self>) -> FloatTensor<Self> {
        if let (Some((_, xm)), Some((gt, gm))) = (matrix(x.clone()), matrix(grad.clone()))
            && let Ok(out) = kernels::relu_backward(&gt.client, &xm, &gm)
        {
            let shape = Shape::new([out.rows as usize, out.cols as usize]);
            return tensor(&gt, out, shape);
        }
        // burn's mask is taken from the output, max(x, 0), which is positive where x is.
        <B as ActivationOps<B>>::relu_backward(<B as ActivationOps<B>>::relu(x), grad)
    }
}
