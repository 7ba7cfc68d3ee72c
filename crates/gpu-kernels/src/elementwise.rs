//! The ReLU's backward pass: the upstream gradient where the layer's input was positive or
//! NaN, 0 elsewhere (as `brdf_neural::linear_op::relu` on the CPU).

use cubecl::prelude::*;

/// Units per cube.
pub const UNITS: u32 = 256;

/// `out[i] = grad[i]` where `!(x[i] <= 0)`, else 0.
#[cube(launch, launch_unchecked)]
pub(crate) fn relu_backward(x: &[f32], grad: &[f32], out: &mut [f32], len: u32) {
    let i = ABSOLUTE_POS_X;
    if i < len {
        let xi = x[i as usize];
        let mut g = grad[i as usize];
        if xi <= 0.0 {
            g = 0.0;
        }
        out[i as usize] = g;
    }
}

/// Launches `relu_backward` over `len` elements.
///
/// # Safety
/// Each handle must hold `len` floats.
pub unsafe fn launch_relu_backward(
    client: &Client,
    x: cubecl::server::Handle,
    grad: cubecl::server::Handle,
    out: cubecl::server::Handle,
    len: u32,
) {
    unsafe {
        crate::checks::launch!(
            relu_backward,
            client,
            CubeCount::Static(len.div_ceil(UNITS), 1, 1),
            CubeDim::new_1d(UNITS),
            BufferArg::from_raw_parts(x, len as usize),
            BufferArg::from_raw_parts(grad, len as usize),
            BufferArg::from_raw_parts(out, len as usize),
            len,
        );
    }
}
