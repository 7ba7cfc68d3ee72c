//! The extension trait [`LinearKernels`], its flex implementation (the `cpu-kernels` crate
//! through [`crate::flex_linear`]), its CubeCL implementation (the `gpu-kernels` crate through
//! `crate::cube_linear`, which burn's fusion runs as one custom operation each) and its
//! autodiff implementation (one graph node per layer).

#[cfg(feature = "flex")]
use crate::precision::MatmulPrecision;
use crate::products::Products;
#[cfg(feature = "flex")]
use burn::backend::Flex;
use burn::backend::autodiff::NodeId;
use burn::backend::autodiff::checkpoint::base::Checkpointer;
use burn::backend::autodiff::checkpoint::strategy::CheckpointStrategy;
use burn::backend::autodiff::grads::Gradients;
use burn::backend::autodiff::ops::{Backward, Ops, OpsKind};
use burn::backend::ops::ActivationOps;
use burn::backend::tensor::FloatTensor;
use burn::backend::{Autodiff, Backend, Dispatch, backend_extension};
#[cfg(any(feature = "wgpu", feature = "cuda"))]
use burn::tensor::Shape;
use burn::tensor::Tensor;

/// The CPU kernels' spelling of a batch's products: the precision, and for bf16 whether AMX
/// tiles are taken where available.
#[cfg(feature = "flex")]
fn kernel_precision(p: Products) -> cpu_kernels::Precision {
    match p.precision {
        MatmulPrecision::F32 => cpu_kernels::Precision::F32,
        MatmulPrecision::Bf16 => cpu_kernels::Precision::Bf16 { amx: p.bf16_amx },
        MatmulPrecision::F16 => cpu_kernels::Precision::F16,
    }
}

/// The shape of `a b` for 2-d `a` and `b` (what fusion records before the product runs).
#[cfg(any(feature = "wgpu", feature = "cuda"))]
fn product_shape(a: &Shape, b: &Shape) -> Shape {
    Shape::new([a[0], b[1]])
}

/// The shape of `a bᵀ`.
#[cfg(any(feature = "wgpu", feature = "cuda"))]
fn product_shape_bt(a: &Shape, b: &Shape) -> Shape {
    Shape::new([a[0], b[0]])
}

/// The shape of `aᵀ b`.
#[cfg(any(feature = "wgpu", feature = "cuda"))]
fn product_shape_at(a: &Shape, b: &Shape) -> Shape {
    Shape::new([a[1], b[1]])
}

/// The shape of a column sum of `a`.
#[cfg(any(feature = "wgpu", feature = "cuda"))]
fn column_shape(a: &Shape) -> Shape {
    Shape::new([a[1]])
}

/// A linear layer's forward and gradient products, for backends with kernels of their own.
/// (burn 0.22.1's extension macro does not route an `Option` of a tensor, hence a separate
/// operation for layers without bias.) The `fusion` attributes give each output's type and
/// shape, which burn's fusion records before it runs the operation.
#[backend_extension(
    Flex: cfg(feature = "flex"),
    Cube: cfg(any(feature = "wgpu", feature = "cuda")),
    Fusion: cfg(any(feature = "wgpu", feature = "cuda")),
    Autodiff
)]
pub trait LinearKernels: Backend {
    /// `x W + b` for x `[rows, d_in]`, W `[d_in, d_out]`, b `[d_out]`.
    #[fusion(dtype = x, shape = product_shape(x, weight))]
    fn kernel_linear(
        x: FloatTensor<Self>,
        weight: FloatTensor<Self>,
        bias: FloatTensor<Self>,
        products: Products,
    ) -> FloatTensor<Self>;

    /// `relu(x W + b)`, a hidden layer: the same values as [`LinearKernels::kernel_linear`]
    /// followed by [`LinearKernels::kernel_relu`].
    #[fusion(dtype = x, shape = product_shape(x, weight))]
    fn kernel_linear_relu(
        x: FloatTensor<Self>,
        weight: FloatTensor<Self>,
        bias: FloatTensor<Self>,
        products: Products,
    ) -> FloatTensor<Self>;

    /// `x W`, a layer without bias.
    #[fusion(dtype = x, shape = product_shape(x, weight))]
    fn kernel_linear_no_bias(
        x: FloatTensor<Self>,
        weight: FloatTensor<Self>,
        products: Products,
    ) -> FloatTensor<Self>;

    /// The input gradient `dY Wᵀ`.
    #[fusion(dtype = output_grad, shape = product_shape_bt(output_grad, weight))]
    fn kernel_linear_x_backward(
        weight: FloatTensor<Self>,
        output_grad: FloatTensor<Self>,
        products: Products,
    ) -> FloatTensor<Self>;

    /// The weight gradient `Xᵀ dY`.
    #[fusion(dtype = output_grad, shape = product_shape_at(x, output_grad))]
    fn kernel_linear_weight_backward(
        x: FloatTensor<Self>,
        output_grad: FloatTensor<Self>,
        products: Products,
    ) -> FloatTensor<Self>;

    /// The bias gradient: `dY` `[rows, d_out]` summed over the rows.
    #[fusion(dtype = output_grad, shape = column_shape(output_grad))]
    fn kernel_linear_bias_backward(output_grad: FloatTensor<Self>) -> FloatTensor<Self>;

    /// `max(x, 0)`.
    #[fusion(dtype = x, shape = x)]
    fn kernel_relu(x: FloatTensor<Self>) -> FloatTensor<Self>;

    /// The gradient of [`LinearKernels::kernel_relu`] at `x` for the upstream gradient `grad`:
    /// `grad` where `x > 0` (or NaN), 0 elsewhere. `x` may be the ReLU's input or its output:
    /// the two are positive (or NaN) at the same elements.
    #[fusion(dtype = grad, shape = grad)]
    fn kernel_relu_backward(x: FloatTensor<Self>, grad: FloatTensor<Self>) -> FloatTensor<Self>;
}

#[cfg(feature = "flex")]
impl LinearKernels for Flex {
    fn kernel_linear(
        x: FloatTensor<Self>,
        weight: FloatTensor<Self>,
        bias: FloatTensor<Self>,
        products: Products,
    ) -> FloatTensor<Self> {
        crate::flex_linear::linear(x, weight, Some(bias), kernel_precision(products))
    }

    fn kernel_linear_relu(
        x: FloatTensor<Self>,
        weight: FloatTensor<Self>,
        bias: FloatTensor<Self>,
        products: Products,
    ) -> FloatTensor<Self> {
        crate::flex_linear::linear_relu(x, weight, bias, kernel_precision(products))
    }

    fn kernel_linear_no_bias(
        x: FloatTensor<Self>,
        weight: FloatTensor<Self>,
        products: Products,
    ) -> FloatTensor<Self> {
        crate::flex_linear::linear(x, weight, None, kernel_precision(products))
    }

    fn kernel_linear_x_backward(
        weight: FloatTensor<Self>,
        output_grad: FloatTensor<Self>,
        products: Products,
    ) -> FloatTensor<Self> {
        crate::flex_linear::linear_x_backward(weight, output_grad, kernel_precision(products))
    }

    fn kernel_linear_weight_backward(
        x: FloatTensor<Self>,
        output_grad: FloatTensor<Self>,
        products: Products,
    ) -> FloatTensor<Self> {
        crate::flex_linear::linear_weight_backward(x, output_grad, kernel_precision(products))
    }

    fn kernel_linear_bias_backward(output_grad: FloatTensor<Self>) -> FloatTensor<Self> {
        crate::flex_linear::linear_bias_backward(output_grad)
    }

    fn kernel_relu(x: FloatTensor<Self>) -> FloatTensor<Self> {
        <Flex as ActivationOps<Flex>>::relu(x)
    }

    fn kernel_relu_backward(x: FloatTensor<Self>, grad: FloatTensor<Self>) -> FloatTensor<Self> {
        crate::flex_linear::relu_backward(x, grad)
    }
}

/// The backward pass of one linear layer with a bias ([`LinearBackward`], also for a layer
/// ending in a ReLU) or without ([`LinearNoBiasBackward`]): x and W are checkpointed only where
/// the other one needs a gradient, as in burn's own `linear`.
#[derive(Debug)]
struct LinearBackward;
/// See [`LinearBackward`].
#[derive(Debug)]
struct LinearNoBiasBackward;

/// The checkpointed x and W of a layer, and how its products are computed.
type LinearState = (Option<NodeId>, Option<NodeId>, Products);

/// Registers the gradients of x and W (where their nodes are tracked) for `grad`.
fn register_x_and_weight<B: LinearKernels>(
    [node_x, node_weight]: [Option<NodeId>; 2],
    (x_state, weight_state, products): LinearState,
    grad: &B::FloatTensorPrimitive,
    grads: &mut Gradients,
    checkpointer: &mut Checkpointer,
) {
    let x = x_state.map(|id| checkpointer.retrieve_node_output::<B::FloatTensorPrimitive>(id));
    let weight =
        weight_state.map(|id| checkpointer.retrieve_node_output::<B::FloatTensorPrimitive>(id));
    if let (Some(id), Some(weight)) = (node_x, weight) {
        grads.register::<B>(id, B::kernel_linear_x_backward(weight, grad.clone(), products));
    }
    if let (Some(id), Some(x)) = (node_weight, x) {
        grads.register::<B>(id, B::kernel_linear_weight_backward(x, grad.clone(), products));
    }
}

impl<B: LinearKernels> Backward<B, 3> for LinearBackward {
    /// The layer's x, W and products, and its output when the layer ends in a ReLU
    /// ([`LinearKernels::kernel_linear_relu`]): the upstream gradient is first masked where
    /// that output is not positive (the ReLU's backward, on the output the node keeps, which
    /// the next layer also keeps as its input).
    type State = (LinearState, Option<B::FloatTensorPrimitive>);

    fn backward(
        self,
        ops: Ops<Self::State, 3>,
        grads: &mut Gradients,
        checkpointer: &mut Checkpointer,
    ) {
        let [node_x, node_weight, node_bias] = ops.parents;
        let (state, relu_output) = ops.state;
        let mut grad = grads.consume::<B>(&ops.node);
        if let Some(output) = relu_output {
            grad = B::kernel_relu_backward(output, grad);
        }
        let ids = [node_x.map(|n| n.id), node_weight.map(|n| n.id)];
        register_x_and_weight::<B>(ids, state, &grad, grads, checkpointer);
        if let Some(node) = node_bias {
            grads.register::<B>(node.id, B::kernel_linear_bias_backward(grad));
        }
    }
}

impl<B: LinearKernels> Backward<B, 2> for LinearNoBiasBackward {
    type State = LinearState;

    fn backward(
        self,
        ops: Ops<Self::State, 2>,
        grads: &mut Gradients,
        checkpointer: &mut Checkpointer,
    ) {
        let grad = grads.consume::<B>(&ops.node);
        let ids = ops.parents.map(|n| n.map(|n| n.id));
        register_x_and_weight::<B>(ids, ops.state, &grad, grads, checkpointer);
    }
}

/// The backward pass of [`LinearKernels::kernel_relu`]: the upstream gradient masked where the
/// input was not positive.
#[derive(Debug)]
struct ReluBackward;

impl<B: LinearKernels> Backward<B, 1> for ReluBackward {
    type State = NodeId;

    fn backward(
        self,
        ops: Ops<Self::State, 1>,
        grads: &mut Gradients,
        checkpointer: &mut Checkpointer,
    ) {
        let x = checkpointer.retrieve_node_output::<B::FloatTensorPrimitive>(ops.state);
        let [parent] = ops.parents;
        let grad = grads.consume::<B>(&ops.node);
        if let Some(node) = parent {
            grads.register::<B>(node.id, B::kernel_relu_backward(x, grad));
        }
    }
}

/// A layer with a bias on the autodiff backend, `x W + b`, or `relu(x W + b)` when `relu`:
/// one graph node ([`LinearBackward`]) around the inner backend's kernel.
fn tracked_linear<B: LinearKernels, C: CheckpointStrategy>(
    x: FloatTensor<Autodiff<B, C>>,
    weight: FloatTensor<Autodiff<B, C>>,
    bias: FloatTensor<Autodiff<B, C>>,
    products: Products,
    relu: bool,
) -> FloatTensor<Autodiff<B, C>> {
    let forward = |x, w, b| match relu {
        true => B::kernel_linear_relu(x, w, b, products),
        false => B::kernel_linear(x, w, b, products),
    };
    let (x_tracked, weight_tracked) = (x.is_tracked(), weight.is_tracked());
    match LinearBackward
        .prepare::<C>([x.node(), weight.node(), bias.node()])
        .compute_bound()
        .stateful()
    {
        OpsKind::Tracked(mut prep) => {
            // x is needed only for the weight gradient, W only for the input gradient.
            let x_state = weight_tracked.then(|| prep.checkpoint(&x));
            let weight_state = x_tracked.then(|| prep.checkpoint(&weight));
            let y = forward(x.into_primitive(), weight.into_primitive(), bias.into_primitive());
            // A ReLU's output is kept for the mask: its buffer is shared, not copied, and the
            // next layer keeps it too.
            let kept = relu.then(|| y.clone());
            prep.finish(((x_state, weight_state, products), kept), y)
        }
        OpsKind::UnTracked(prep) => {
            prep.finish(forward(x.into_primitive(), weight.into_primitive(), bias.into_primitive()))
        }
    }
}

impl<B: LinearKernels, C: CheckpointStrategy> LinearKernels for Autodiff<B, C> {
    fn kernel_linear(
        x: FloatTensor<Self>,
        weight: FloatTensor<Self>,
        bias: FloatTensor<Self>,
        products: Products,
    ) -> FloatTensor<Self> {
        tracked_linear::<B, C>(x, weight, bias, products, false)
    }

    fn kernel_linear_relu(
        x: FloatTensor<Self>,
        weight: FloatTensor<Self>,
        bias: FloatTensor<Self>,
        products: Products,
    ) -> FloatTensor<Self> {
        tracked_linear::<B, C>(x, weight, bias, products, true)
    }

    fn kernel_linear_no_bias(
        x: FloatTensor<Self>,
        weight: FloatTensor<Self>,
        products: Products,
    ) -> FloatTensor<Self> {
        let (x_tracked, weight_tracked) = (x.is_tracked(), weight.is_tracked());
        match LinearNoBiasBackward
            .prepare::<C>([x.node(), weight.node()])
            .compute_bound()
            .stateful()
        {
            OpsKind::Tracked(mut prep) => {
                let x_state = weight_tracked.then(|| prep.checkpoint(&x));
                let weight_state = x_tracked.then(|| prep.checkpoint(&weight));
                let (x, w) = (x.into_primitive(), weight.into_primitive());
                let y = B::kernel_linear_no_bias(x, w, products);
                prep.finish((x_state, weight_state, products), y)
            }
            OpsKind::UnTracked(prep) => {
                let (x, w) = (x.into_primitive(), weight.into_primitive());
                prep.finish(B::kernel_linear_no_bias(x, w, products))
            }
        }
    }

    fn kernel_relu(x: FloatTensor<Self>) -> FloatTensor<Self> {
        // As burn's own relu: the input is kept for the backward pass.
        match ReluBackward.prepare::<C>([x.node()]).compute_bound().stateful() {
            OpsKind::Tracked(mut prep) => {
                let state = prep.checkpoint(&x);
                prep.finish(state, B::kernel_relu(x.into_primitive()))
            }
            OpsKind::UnTracked(prep) => prep.finish(B::kernel_relu(x.into_primitive())),
        }
    }

    fn kernel_relu_backward(_x: FloatTensor<Self>, _grad: FloatTensor<Self>) -> FloatTensor<Self> {
        unreachable!("the ReLU gradient is computed on the inner backend")
    }

    fn kernel_linear_bias_backward(_output_grad: FloatTensor<Self>) -> FloatTensor<Self> {
        unreachable!("the bias gradient is computed on the inner backend")
    }

    fn kernel_linear_x_backward(
        _weight: FloatTensor<Self>,
        _output_grad: FloatTensor<Self>,
        _products: Products,
    ) -> FloatTensor<Self> {
        unreachable!("the input gradient is computed on the inner backend")
    }

    fn kernel_linear_weight_backward(
        _x: FloatTensor<Self>,
        _output_grad: FloatTensor<Self>,
        _products: Products,
    ) -> FloatTensor<Self> {
        unreachable!("the weight gradient is computed on the inner backend")
    }
}

/// [`super::relu`] on a flex device, through the extension.
#[cfg(feature = "flex")]
pub(super) fn relu(x: Tensor<2>) -> Tensor<2> {
    Tensor::from_dispatch(<Dispatch as LinearKernels>::kernel_relu(x.into_dispatch()))
}

/// [`super::linear_relu`] through the extension, which burn routes to the backend of the
/// tensors.
pub(super) fn linear_relu(
    x: Tensor<2>,
    weight: Tensor<2>,
    bias: Tensor<1>,
    products: Products,
) -> Tensor<2> {
    let (x, weight, bias) = (x.into_dispatch(), weight.into_dispatch(), bias.into_dispatch());
    Tensor::from_dispatch(<Dispatch as LinearKernels>::kernel_linear_relu(
        x, weight, bias, products,
    ))
}

/// [`super::linear`] through the extension, which burn routes to the backend of the tensors
/// (`Autodiff<Flex>`, `Flex`, `Autodiff<Cube>` or `Cube`).
pub(super) fn linear(
    x: Tensor<2>,
    weight: Tensor<2>,
    bias: Option<Tensor<1>>,
    products: Products,
) -> Tensor<2> {
    let (x, weight) = (x.into_dispatch(), weight.into_dispatch());
    Tensor::from_dispatch(match bias {
        Some(b) => {
            <Dispatch as LinearKernels>::kernel_linear(x, weight, b.into_dispatch(), products)
        }
        None => <Dispatch as LinearKernels>::kernel_linear_no_bias(x, weight, products),
    })
}
