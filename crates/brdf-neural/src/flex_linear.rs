//! The linear layer's three products on burn-flex tensors, computed by the `cpu-kernels` crate:
//! the glue between flex's buffers (a byte buffer, a shape, strides and an offset) and the
//! kernels' strided matrices. Only [`crate::linear_op`] calls it.
//!
//! | product | operands | kernels' path for a hidden layer at batch 2^15 |
//! | --- | --- | --- |
//! | forward `y = x W + b` | x [rows, d_in], W [d_in, d_out] | bias fused into the gemm's blocks of rows; bf16 on request |
//! | forward of a hidden layer `y = relu(x W + b)` | as above | bias and ReLU fused into the gemm's blocks of rows; bf16 on request |
//! | input gradient `dY Wᵀ` | dY [rows, d_out], Wᵀ a transposed view | gemm; bf16 on request |
//! | weight gradient `Xᵀ dY` | Xᵀ a transposed view, dY [rows, d_out] | split-k (k = rows); bf16 on request |
//!
//! The bias gradient (a sum of dY over the rows) stays flex's own reduction. Outputs are
//! allocated without zeroing (every element is written by the kernels) and 16-byte aligned, so
//! flex never copies them to realign. Tensors that are not f32 matrices take flex's own
//! operations, as burn's default `linear` would.

use burn::backend::Flex;
use burn::backend::ops::{FloatTensorOps, ModuleOps};
use burn::tensor::{Bytes, DType, Shape};
use burn_flex::{FlexTensor, Layout};
use cpu_kernels::{Epilogue, MatRef, Precision};

/// The matrix view of a 2-D f32 tensor, or `None` when it is not one.
fn mat(t: &FlexTensor) -> Option<(usize, usize, MatRef)> {
    let layout = t.layout();
    let shape = layout.shape();
    if t.dtype() != DType::F32 || shape.num_dims() != 2 {
        return None;
    }
    let strides = layout.strides();
    let data: &[f32] = t.storage();
    // An empty tensor may have no storage to point into; its offset is then never read.
    let ptr = data.as_ptr().wrapping_add(layout.start_offset());
    Some((shape[0], shape[1], MatRef { ptr, rs: strides[0], cs: strides[1] }))
}

/// A contiguous m x n f32 tensor whose every element `write` writes, allocated without zeroing
/// when its size is a whole number of 16-byte words (zeroing a [32768, 128] activation is a
/// 16 MB memset per product, a visible share of a training step), and 16-byte aligned, so
/// that flex never copies it to realign.
///
/// # Safety
/// `write` must write all m n elements it is given.
unsafe fn output(m: usize, n: usize, write: impl FnOnce(*mut f32)) -> FlexTensor {
    let shape = Shape::new([m, n]);
    if !(m * n).is_multiple_of(4) {
        let mut t = FlexTensor::empty(shape, DType::F32);
        write(t.storage_mut::<f32>().as_mut_ptr());
        return t;
    }
    let mut buf: Vec<u128> = Vec::with_capacity(m * n / 4);
    write(buf.as_mut_ptr().cast::<f32>());
    // SAFETY: all m n floats, m n / 4 words, were written (the caller's contract).
    unsafe { buf.set_len(m * n / 4) };
    FlexTensor::new(Bytes::from_elems(buf), Layout::contiguous(shape), DType::F32)
}

/// `lhs rhs (+ bias)`, then the ReLU when `relu`, through the kernels, or `None` when an
/// operand is not an f32 matrix of matching shape (or the bias is not n contiguous f32 values).
fn product(
    lhs: &FlexTensor,
    rhs: &FlexTensor,
    bias: Option<&FlexTensor>,
    relu: bool,
    precision: Precision,
) -> Option<FlexTensor> {
    let (m, k, a) = mat(lhs)?;
    let (k2, n, b) = mat(rhs)?;
    if k != k2 {
        return None;
    }
    let bias_values: Option<&[f32]> = match bias {
        None => None,
        Some(bias) => {
            let shape = bias.layout().shape();
            if bias.dtype() != DType::F32 || shape.num_dims() != 1 || shape[0] != n {
                return None;
            }
            let (b0, b1) = bias.layout().contiguous_offsets()?;
            Some(&bias.storage::<f32>()[b0..b1])
        }
    };
    // SAFETY: `mat` checked the shapes against the tensors' layouts, which flex keeps inside
    // their buffers; `output` hands the kernel m n fresh floats, all of which it writes.
    let epilogue = Epilogue { bias: bias_values, relu };
    Some(unsafe {
        output(m, n, |out| cpu_kernels::matmul(m, n, k, a, b, out, epilogue, precision))
    })
}

/// `x W + b` for x `[rows, d_in]`, W `[d_in, d_out]`, b `[d_out]`.
pub(crate) fn linear(
    x: FlexTensor,
    weight: FlexTensor,
    bias: Option<FlexTensor>,
    precision: Precision,
) -> FlexTensor {
    product(&x, &weight, bias.as_ref(), false, precision)
        .unwrap_or_else(|| <Flex as ModuleOps<Flex>>::linear(x, weight, bias))
}

/// `relu(x W + b)`, a hidden layer, with the bias and the ReLU applied inside the product: the
/// same bits as [`linear`] followed by flex's `relu`, without the ReLU's pass over the output.
pub(crate) fn linear_relu(
    x: FlexTensor,
    weight: FlexTensor,
    bias: FlexTensor,
    precision: Precision,
) -> FlexTensor {
    product(&x, &weight, Some(&bias), true, precision).unwrap_or_else(|| {
        let z = <Flex as ModuleOps<Flex>>::linear(x, weight, Some(bias));
        <Flex as burn::backend::ops::ActivationOps<Flex>>::relu(z)
    })
}

/// The input gradient `dY Wᵀ`.
pub(crate) fn linear_x_backward(
    weight: FlexTensor,
    output_grad: FlexTensor,
    precision: Precision,
) -> FlexTensor {
    let weight_t = Flex::float_swap_dims(weight, 0, 1);
    product(&output_grad, &weight_t, None, false, precision)
        .unwrap_or_else(|| Flex::float_matmul(output_grad, weight_t))
}

/// The weight gradient `Xᵀ dY`.
pub(crate) fn linear_weight_backward(
    x: FlexTensor,
    output_grad: FlexTensor,
    precision: Precision,
) -> FlexTensor {
    let x_t = Flex::float_swap_dims(x, 0, 1);
    product(&x_t, &output_grad, None, false, precision)
        .unwrap_or_else(|| Flex::float_matmul(x_t, output_grad))
}

/// The bias gradient: `dY` summed over its rows (`cpu_kernels::elementwise::sum_rows`, on
/// every thread); flex's own for anything but a contiguous f32 matrix.
pub(crate) fn linear_bias_backward(output_grad: FlexTensor) -> FlexTensor {
    let layout = output_grad.layout();
    let shape = layout.shape();
    if output_grad.dtype() == DType::F32
        && shape.num_dims() == 2
        && let Some((start, end)) = layout.contiguous_offsets()
    {
        let (rows, cols) = (shape[0], shape[1]);
        let data: &[f32] = &output_grad.storage()[start..end];
        let sums = cpu_kernels::elementwise::sum_rows(data, rows, cols);
        return FlexTensor::new(
            Bytes::from_elems(sums),
            Layout::contiguous(Shape::new([cols])),
            DType::F32,
        );
    }
    <Flex as ModuleOps<Flex>>::linear_bias_backward(output_grad)
}

/// The ReLU gradient at `x`: `grad` masked in place where `x` is not positive (kept for NaN),
/// on every thread, when `grad` is an f32 buffer of `x`'s layout that nothing else holds;
/// flex's own `relu_backward` otherwise (the same values).
pub(crate) fn relu_backward(x: FlexTensor, mut grad: FlexTensor) -> FlexTensor {
    if x.dtype() == DType::F32
        && grad.dtype() == DType::F32
        && grad.layout().shape() == x.layout().shape()
        && grad.is_unique()
        && let (Some((0, g_end)), Some((x0, x1))) =
            (grad.layout().contiguous_offsets(), x.layout().contiguous_offsets())
    {
        let xs: &[f32] = &x.storage()[x0..x1];
        cpu_kernels::elementwise::relu_backward_in_place(&mut grad.storage_mut()[..g_end], xs);
        return grad;
    }
    <Flex as burn::backend::ops::ActivationOps<Flex>>::relu_backward(x, grad)
}
