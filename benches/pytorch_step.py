#!/usr/bin/env python3
"""PyTorch baseline of the brdf-neural training step bench (Single MLP, CPU).

The same step as `cargo bench -p brdf-neural --bench train_step` (model `single_mlp`):
Single MLP with the reciprocity mapping: 160 spatial + 28 angle inputs = 188, six linear layers
of width 128 with ReLU, the raw input concatenated to the input of layer 3 (0-based), softplus
output (RGB); loss = MSE(f * w, target) with a per-sample weight w (E * shadow * cos);
backward; Adam (lr 1e-4). Batch 32768 by default. Inputs are random (the angle features'
computation is not part of the timed step in either implementation).

Usage: python3 benches/pytorch_step.py [--batch 32768] [--threads 2] [--reps 20] [--bf16]
       [--device cpu|cuda] [--tf32] [--machine]
Prints the median and mean step time in ms and samples/s. `--bf16` runs forward and loss under
`torch.autocast("cpu", dtype=torch.bfloat16)` (bf16 matrix products through oneDNN, which uses
AVX512-BF16 where the CPU has it; f32 master weights and Adam): what a mixed-precision path
buys on this CPU. `--device cuda` runs the step on the GPU (each step ends with
`torch.cuda.synchronize()`, so the host clock times the device's work); there f32 matrix products
are IEEE f32 unless `--tf32` lets cuBLAS round their operands to TF32 on the tensor cores, and
`--bf16` autocasts on CUDA instead.
"""

import contextlib

import argparse
import statistics
import time

import torch
import torch.nn as nn
import torch.nn.functional as F


class SingleMlp(nn.Module):
    def __init__(self, d_in=188, width=128, layers=6, skip=3, d_out=3):
        super().__init__()
        self.skip = skip
        dims = []
        for k in range(layers):
            i = d_in if k == 0 else width + (d_in if k == skip else 0)
            o = d_out if k == layers - 1 else width
            dims.append((i, o))
        self.layers = nn.ModuleList(nn.Linear(i, o) for i, o in dims)

    def forward(self, x):
        h = x
        last = len(self.layers) - 1
        for k, layer in enumerate(self.layers):
            if k == self.skip:
                h = torch.cat([h, x], dim=-1)
            h = layer(h)
            if k < last:
                h = F.relu(h)
        return F.softplus(h)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--batch", type=int, default=32768)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--reps", type=int, default=20)
    p.add_argument("--bf16", action="store_true", help="bf16 autocast (mixed precision)")
    p.add_argument("--device", default="cpu", help="cpu or cuda")
    p.add_argument("--tf32", action="store_true", help="CUDA: allow TF32 matrix products")
    p.add_argument("--machine", action="store_true", help="print only 'median_ms <value>'")
    a = p.parse_args()
    torch.set_num_threads(a.threads)
    dev = torch.device(a.device)
    cuda = dev.type == "cuda"
    torch.backends.cuda.matmul.allow_tf32 = a.tf32
    torch.backends.cudnn.allow_tf32 = a.tf32
    torch.manual_seed(1)
    model = SingleMlp().to(dev)
    opt = torch.optim.Adam(model.parameters(), lr=1e-4, eps=1e-5)
    x = (torch.rand(a.batch, 188) * 2 - 1).to(dev)
    w = (torch.rand(a.batch, 1) * 3).to(dev)
    target = torch.rand(a.batch, 3).to(dev)

    def precision():
        if a.bf16:
            return torch.autocast(dev.type, dtype=torch.bfloat16)
        return contextlib.nullcontext()

    def sync():
        if cuda:
            torch.cuda.synchronize()

    def step():
        opt.zero_grad(set_to_none=True)
        with precision():
            loss = ((model(x).float() * w - target) ** 2).mean()
        loss.backward()
        opt.step()
        sync()

    for _ in range(10 if cuda else 3):
        step()
    times = []
    for _ in range(a.reps):
        t = time.perf_counter()
        step()
        times.append(time.perf_counter() - t)
    n_params = sum(q.numel() for q in model.parameters())
    med = statistics.median(times)
    if a.machine:
        print(f"median_ms {med * 1e3:.3f}")
        return
    mode = "bf16 autocast" if a.bf16 else ("tf32" if a.tf32 and cuda else "f32")
    where = torch.cuda.get_device_name(dev) if cuda else "cpu"
    print(
        f"pytorch {torch.__version__} {where} {mode} "
        f"threads {torch.get_num_threads()} batch {a.batch} "
        f"params {n_params}: median {med * 1e3:.1f} ms, mean {statistics.mean(times) * 1e3:.1f} ms, "
        f"{a.batch / med:.0f} samples/s"
    )


if __name__ == "__main__":
    main()
