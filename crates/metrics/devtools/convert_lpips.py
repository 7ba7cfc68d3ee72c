"""Convert the official LPIPS AlexNet weights to the metrics crate's file format (see
crates/metrics/src/lpips/weights.rs). Needs torch; run on a machine with the two files:

  alexnet-owt-7be5be79.pth  from https://download.pytorch.org/models/alexnet-owt-7be5be79.pth
  alex.pth                  from https://github.com/richzhang/PerceptualSimilarity/raw/master/lpips/weights/v0.1/alex.pth

python3 convert_lpips.py alexnet-owt-7be5be79.pth alex.pth alex_v0.1.lpipsw
"""
import struct, sys
import torch

alex = torch.load(sys.argv[1], map_location="cpu")
lin = torch.load(sys.argv[2], map_location="cpu")
tensors = {}
for k, idx in enumerate([0, 3, 6, 8, 10]):
    tensors[f"conv{k + 1}.weight"] = alex[f"features.{idx}.weight"]
    tensors[f"conv{k + 1}.bias"] = alex[f"features.{idx}.bias"]
    tensors[f"lin{k}.weight"] = lin[f"lin{k}.model.1.weight"]
with open(sys.argv[3], "wb") as f:
    f.write(b"LPIPSW1\0" + struct.pack("<I", len(tensors)))
    for name in sorted(tensors):
        t = tensors[name].float().contiguous()
        f.write(struct.pack("<I", len(name)) + name.encode())
        f.write(struct.pack("<I", t.dim()) + b"".join(struct.pack("<I", d) for d in t.shape))
        f.write(t.numpy().astype("<f4").tobytes())
