//! `linear` (y = x W + b) with the bias added in the matrix product's store (patch 8; see
//! vendor/README.md).
//!
//! burn's default `linear` is a matrix product followed by a broadcast add: one more pass over
//! the output, read and written (16 MB each way for a [32768, 128] activation). Here the bias is
//! added to each block of output rows while the product's kernel still has it in cache:
//! [`matmul_bias`](super::matmul::matmul_bias) for f32 (the f32 gemm, or the bf16 kernels when
//! the thread asked for bf16 products). The values are the product's, then the same f32 add.
//! Leading dimensions of x fold into the rows, as in burn's default; anything the fused path does
//! not take (other dtypes, narrow outputs, split-k products) runs as product plus add.

use alloc::vec::Vec;
use burn_backend::ops::FloatTensorOps;
use burn_std::Shape;

use crate::ops::matmul::{matmul, matmul_bias};
use crate::{Flex, FlexTensor};

/// `x W (+ b)` for x `[..., d_in]`, W `[d_in, d_out]`, b `[d_out]`: `[..., d_out]`.
pub fn linear(x: FlexTensor, weight: FlexTensor, bias: Option<FlexTensor>) -> FlexTensor {
    let x_shape = x.layout().shape().clone();
    let w_shape = weight.layout().shape().clone();
    let nd = x_shape.num_dims();
    assert!(nd >= 1 && w_shape.num_dims() == 2, "linear: x must be at least 1D, weight 2D");
    let (d_in, d_out) = (w_shape[0], w_shape[1]);
    assert_eq!(x_shape[nd - 1], d_in, "linear: x's last dimension must match the weight's rows");
    let rows: usize = (0..nd - 1).map(|i| x_shape[i]).product();
    let x2 = if nd == 2 { x } else { x.reshape(Shape::from(alloc::vec![rows, d_in])) };
    let y = match bias {
        Some(bias) => match matmul_bias(&x2, &weight, &bias) {
            Some(y) => y,
            None => {
                let bias = bias.reshape(Shape::from(alloc::vec![1, d_out]));
                Flex::float_add(matmul(x2, weight), bias)
            }
        },
        None => matmul(x2, weight),
    };
    if nd == 2 {
        return y;
    }
    let dims: Vec<usize> = (0..nd - 1).map(|i| x_shape[i]).chain([d_out]).collect();
    y.reshape(Shape::from(dims))
}
