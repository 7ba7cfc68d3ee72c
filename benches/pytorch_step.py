#!/usr/bin/env python3
"""PyTorch baseline of the brdf-neural training step bench, for every model kind.

The same step as `cargo bench -p brdf-neural --bench train_step` (`BRDF_BENCH_ALL_MODELS=1` for
all nine kinds): one training step at batch 32768 of the model in its Rust default configuration
(`ModelConfig::new(kind)`, with the reciprocity mapping for Single MLP and Enh. Add. Shared, as
`configs()` there): forward, radiance f * w with a per-sample weight w (E * shadow * cos), loss
mean((f w - target)^2), backward, Adam (lr 1e-4, eps 1e-5: burn's default). The models are
those of `neural_brdfs.reference_torch` (imported from this checkout's sources, no build
needed), initialised with PyTorch's default Linear init of the concatenated layout.

Inputs: random spatial features in [-1, 1] (160 per sample), random upper-hemisphere unit l, v
(z = max(u, 1e-3), as the Rust bench draws them), w ~ U(0, 3), target ~ U(0, 1).
**Timed:** zero_grad; the forward from the prepared inputs (`NeuralBrdf.forward_prepared`: the
concatenation [spatial, angle features] where a network takes both, the networks, the output
heads; for parametric kinds the parameter maps and the analytic BRDF, and for FMBRDF c(alpha,
beta), the Lambda network (by default by segments as in Rust, with the breakpoint sort and
search on the device) and the body network); the loss; backward; Adam; a device sync on CUDA.
**Not timed** (Rust computes them on the CPU when it builds the batch): drawing the inputs,
the angle encodings or the parametric pair geometry (`NeuralBrdf.prepare`), the spatial rows'
NaN / clamp pass, and the upload.

`--kind single_mlp` (default) is the network of this script's previous single-kind version:
188 inputs (160 spatial + 28 angle features), six linear layers of width 128, the raw input
re-entering layer 3 (0-based), softplus output, with the same seed, draw order and initial
weights (layer 3's [128, 316] init split into its [128, 128] weight and the [128, 188] skip
projection, the same function); its spatial rows, w and target are the same draws, only the
28 angle columns are now the features of random directions instead of uniform noise.

Parameter counts (model-spec's layer tables, `crates/model-spec/src/lib.rs`), checked at start:
RP 108,039, TS 108,039, FMBRDF 107,912 (with its 2 global scalars), Disney 108,684, Single MLP
(mapping) 114,691, Add. Sep. 187,398, Add. Shared 160,134, Enh. Add. Sep. 187,785, Enh. Add.
Shared (mapping) 161,417; PyTorch's counts match every one.

Usage: python3 benches/pytorch_step.py [--kind K|all] [--batch 32768] [--threads 2]
       [--reps 20] [--bf16] [--device cpu|cuda] [--tf32] [--cuda-graph]
       [--fm-lambda segments|dense] [--machine]
`--kind` takes a configuration name, a paper row name or a Rust `ModelKind` Debug name (what
train_step.rs passes). Prints, per kind, the median and mean step time in ms, samples/s and
the parameter count; `--machine` prints only
`median_ms <value>` (one kind) or `<kind> median_ms <value>` lines (`all`). `--bf16` runs
forward and loss under `torch.autocast` with bfloat16 (oneDNN on the CPU, AVX512-BF16 / AMX
where present; f32 master weights and Adam). `--device cuda` runs on the GPU (each step ends
with `torch.cuda.synchronize()`); there f32 products are IEEE f32 unless `--tf32`.
`--cuda-graph` (CUDA only) captures the whole step in a `torch.cuda.CUDAGraph` after warm-up and
times its replay (PyTorch's whole-network capture recipe: static inputs, warm-up on a side
stream, which the capture then uses too, grads set to None before capture so backward allocates
them from the graph's pool and each replay writes them anew, which is the captured step's
zero_grad; Adam with capturable=True; autocast without its cache). The captured forward has no
host synchronisation (FMBRDF's segment search runs on the device). Not run yet: this machine
has no GPU.
"""

import argparse
import contextlib
import math
import pathlib
import re
import statistics
import sys
import time

import torch

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "crates" / "py-neural-brdfs" / "python" / "neural_brdfs"))
import reference_numpy as ref  # noqa: E402  (standalone copies: no native module needed)
import reference_torch as rt  # noqa: E402
import reference_torch_parametric as par  # noqa: E402

FMBRDF_WEIGHTS = ROOT / "crates" / "brdf-analytic" / "assets" / "fmbrdf" / "fmbrdf_weights.bin"
KINDS = ("single_mlp", "additive_separate", "additive_shared", "additive_separate_enhanced",
         "additive_shared_enhanced", "rp", "ts", "disney", "fmbrdf")
#: The Rust bench's configurations switch these two to the reciprocity mapping.
MAPPING = ("single_mlp", "additive_shared_enhanced")
#: Trainable scalars of each kind in the bench configuration (model-spec's table).
EXPECTED_PARAMS = {"rp": 108_039, "ts": 108_039, "fmbrdf": 107_912, "disney": 108_684,
                   "single_mlp": 114_691, "additive_separate": 187_398,
                   "additive_shared": 160_134, "additive_separate_enhanced": 187_785,
                   "additive_shared_enhanced": 161_417}
CLASSES = {"single_mlp": rt.SingleMlp, "additive_separate": rt.AdditiveSeparate,
           "additive_separate_enhanced": rt.AdditiveSeparate,
           "additive_shared": rt.AdditiveShared, "additive_shared_enhanced": rt.AdditiveShared}


def kind_arg(name):
    """``--kind``: ``all``, a configuration name, a paper row name ("Enh. Add. Sep.") or a Rust
    ``ModelKind`` Debug name ("AdditiveSeparateEnhanced", as train_step.rs names the kinds it
    adds with ``BRDF_BENCH_ALL_MODELS``)."""
    if name == "all":
        return name
    snake = re.sub(r"(?<=[a-z0-9])(?=[A-Z])", "_", name.strip()).lower()
    for candidate in (name, snake):
        try:
            return ref.kind_name(candidate)
        except ValueError:
            pass
    raise argparse.ArgumentTypeError(f"unknown model kind {name!r} (one of {', '.join(KINDS)}, "
                                     f"or all)")


def config_of(kind):
    """``ModelConfig::new(kind)`` (reciprocity mapping for the two kinds of MAPPING)."""
    angles = ref.AngleConfig(reciprocity="mapping" if kind in MAPPING else "none")
    return ref.ModelConfig(kind=kind, angles=angles)


def init_concatenated(model):
    """PyTorch's default init of each network written with concatenations: layer k an
    nn.Linear over [h, raw input (skip), late input], created in order, its weight's column
    blocks copied into ``layers.k``, ``skip`` and ``late`` (the same function)."""
    for mlp in (m for m in model.modules() if isinstance(m, rt.Mlp)):
        s = mlp.spec
        for k, layer in enumerate(mlp.layers):
            parts = [layer.weight]
            if k == s.skip_into:
                parts.append(mlp.skip.weight)
            if mlp.late is not None and k == s.late_into:
                parts.append(mlp.late.weight)
            full = torch.nn.Linear(sum(p.shape[1] for p in parts), layer.weight.shape[0])
            with torch.no_grad():
                for p, w in zip(parts, torch.split(full.weight, [p.shape[1] for p in parts], 1)):
                    p.copy_(w)
                layer.bias.copy_(full.bias)


def directions(n, gen):
    """Random upper-hemisphere unit vectors: z = max(u, 1e-3), phi = 2 pi u'."""
    z = torch.rand(n, generator=gen).clamp(min=1e-3)
    phi = torch.rand(n, generator=gen) * (2 * math.pi)
    s = torch.sqrt(1 - z * z)
    return torch.stack([s * torch.cos(phi), s * torch.sin(phi), z], dim=1)


def build(kind, a, dev):
    """(model, x, features, w, target, parameter count) of one kind, inputs prepared."""
    config = config_of(kind)
    table = rt.SpatialTable("lbo", torch.zeros((0, config.spatial_dim)),
                            torch.zeros((0, 3), dtype=torch.int64))
    if kind in par.OUTPUTS:
        model = par.ParametricBrdf(config, table, fmbrdf_weights=str(FMBRDF_WEIGHTS),
                                   lambda_mode=a.fm_lambda)
    else:
        model = CLASSES[kind](config, table)
    torch.manual_seed(1)  # the previous script's: its six Linear layers first
    init_concatenated(model)
    n_params = sum(q.numel() for q in model.parameters())
    if n_params != EXPECTED_PARAMS[kind]:
        sys.exit(f"{__file__}: {kind} has {n_params} parameters, model-spec's table says "
                 f"{EXPECTED_PARAMS[kind]}")
    model.to(dev)
    # The previous script's draws: x [batch, 188] (here its spatial columns), then w, target.
    extra = 0 if kind in par.OUTPUTS else config.angles.dim
    spatial = (torch.rand(a.batch, config.spatial_dim + extra) * 2 - 1)[:, :config.spatial_dim]
    w = (torch.rand(a.batch, 1) * 3).to(dev)
    target = torch.rand(a.batch, 3).to(dev)
    gen = torch.Generator().manual_seed(2)
    l, v = directions(a.batch, gen), directions(a.batch, gen)
    x, features = model.prepare(spatial.to(dev), l.to(dev), v.to(dev))
    return model.train(True), x, features, w, target, n_params


def time_kind(kind, a, dev):
    """Median and mean step time (s) and the parameter count of one kind."""
    cuda = dev.type == "cuda"
    model, x, features, w, target, n_params = build(kind, a, dev)
    opt = torch.optim.Adam(model.parameters(), lr=1e-4, eps=1e-5,
                           capturable=a.cuda_graph)

    def precision():
        if a.bf16:
            return torch.autocast(dev.type, dtype=torch.bfloat16, cache_enabled=not a.cuda_graph)
        return contextlib.nullcontext()

    def sync():
        if cuda:
            torch.cuda.synchronize()

    def loss_backward_adam():
        with precision():
            f = model.forward_prepared(x, features)["f"]
            loss = ((f.float() * w - target) ** 2).mean()
        loss.backward()
        opt.step()

    def step():
        opt.zero_grad(set_to_none=True)
        loss_backward_adam()
        sync()

    warm = 10 if cuda else 3
    if a.cuda_graph:
        side = torch.cuda.Stream()
        side.wait_stream(torch.cuda.current_stream())
        with torch.cuda.stream(side):
            for _ in range(warm):
                opt.zero_grad(set_to_none=True)
                loss_backward_adam()
        torch.cuda.current_stream().wait_stream(side)
        graph = torch.cuda.CUDAGraph()
        opt.zero_grad(set_to_none=True)
        with torch.cuda.graph(graph, stream=side):  # the warm-up's stream (its handles)
            loss_backward_adam()

        def step():  # noqa: F811  (the captured step, replayed)
            graph.replay()
            sync()

    for _ in range(warm):
        step()
    times = []
    for _ in range(a.reps):
        t = time.perf_counter()
        step()
        times.append(time.perf_counter() - t)
    return statistics.median(times), statistics.mean(times), n_params


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--kind", default="single_mlp", type=kind_arg,
                   help="a model kind (configuration, paper or Rust name) or all")
    p.add_argument("--batch", type=int, default=32768)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--reps", type=int, default=20)
    p.add_argument("--bf16", action="store_true", help="bf16 autocast (mixed precision)")
    p.add_argument("--device", default="cpu", help="cpu or cuda")
    p.add_argument("--tf32", action="store_true", help="CUDA: allow TF32 matrix products")
    p.add_argument("--cuda-graph", action="store_true",
                   help="CUDA: capture the step in a CUDA graph and time its replay")
    p.add_argument("--fm-lambda", default="segments", choices=("segments", "dense"),
                   help="FMBRDF's Lambda network: by segments (as Rust) or dense")
    p.add_argument("--machine", action="store_true",
                   help="print only 'median_ms <value>' ('<kind> median_ms <value>' for all)")
    a = p.parse_args()
    torch.set_num_threads(a.threads)
    dev = torch.device(a.device)
    cuda = dev.type == "cuda"
    if a.cuda_graph and not cuda:
        p.error("--cuda-graph needs --device cuda")
    if a.batch < 1 or a.reps < 1:
        p.error("--batch and --reps must be positive")
    torch.backends.cuda.matmul.allow_tf32 = a.tf32
    torch.backends.cudnn.allow_tf32 = a.tf32
    kinds = KINDS if a.kind == "all" else (a.kind,)
    mode = "bf16 autocast" if a.bf16 else ("tf32" if a.tf32 and cuda else "f32")
    mode += ", CUDA graph" if a.cuda_graph else ""
    where = torch.cuda.get_device_name(dev) if cuda else "cpu"
    for kind in kinds:
        med, mean, n_params = time_kind(kind, a, dev)
        if a.machine:
            print(f"{kind} median_ms {med * 1e3:.3f}" if a.kind == "all"
                  else f"median_ms {med * 1e3:.3f}", flush=True)
            continue
        print(f"pytorch {torch.__version__} {where} {mode} threads {torch.get_num_threads()} "
              f"batch {a.batch} kind {kind} params {n_params}: median {med * 1e3:.1f} ms, "
              f"mean {mean * 1e3:.1f} ms, {a.batch / med:.0f} samples/s", flush=True)


if __name__ == "__main__":
    main()
