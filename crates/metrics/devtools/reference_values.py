"""Development cross-check (not run in CI): reference values of scikit-image and NVIDIA's
flip-evaluator for the deterministic test images of the metrics crate's tests.

pip install scikit-image flip-evaluator; python3 reference_values.py
The images are built exactly as crates/metrics/src/testimg.rs builds them; the FLIP maps are
written to /tmp/flip_ref_*.f32 for the full per-pixel comparison of examples/flip_parity.rs.
"""
import numpy as np

M = 0xFFFFFFFF


def h32(x):
    x &= M
    x ^= x >> 16
    x = (x * 0x7FEB352D) & M
    x ^= x >> 15
    x = (x * 0x846CA68B) & M
    x ^= x >> 16
    return x


def val(x, y, c, seed):
    return h32(x + 1000 * y + 1000000 * c + seed * 7919) / 4294967296.0


def ldr_pair(w, h, seed):
    ref = np.zeros((h, w, 3)); test = np.zeros((h, w, 3))
    for y in range(h):
        for x in range(w):
            for c in range(3):
                s = ((x * 3 + y * 5 + c * 7) % 17) / 16.0
                r = 0.6 * s + 0.4 * val(x, y, c, seed)
                t = min(1.0, max(0.0, r + 0.2 * (val(x, y, c, seed + 1) - 0.5)))
                ref[y, x, c] = r; test[y, x, c] = t
    return ref.astype(np.float32), test.astype(np.float32)


def hdr_pair(w, h, seed, gain):
    ref = np.zeros((h, w, 3)); test = np.zeros((h, w, 3))
    for y in range(h):
        for x in range(w):
            for c in range(3):
                v = val(x, y, c, seed)
                r = 0.05 + (x + y) / (w + h) + gain * v * v * v
                t = r * (0.7 + 0.6 * val(x, y, c, seed + 1))
                ref[y, x, c] = r; test[y, x, c] = t
    return ref.astype(np.float32), test.astype(np.float32)


if __name__ == "__main__":
    from skimage.metrics import structural_similarity
    import flip_evaluator as fe
    for (w, h, seed) in [(24, 17, 3), (32, 32, 11)]:
        ref, test = ldr_pair(w, h, seed)
        s, full = structural_similarity(test.astype(np.float64), ref.astype(np.float64), channel_axis=-1, data_range=1.0,
                                        gaussian_weights=True, sigma=1.5, use_sample_covariance=False, full=True)
        mask = np.array([[ (x + 2 * y) % 3 != 0 for x in range(w)] for y in range(h)])
        crop = np.zeros_like(mask); crop[5:h-5, 5:w-5] = True
        masked = full[mask & crop].mean()
        print(f"SSIM {w}x{h} seed {seed}: {s!r}  masked (x+2y)%3!=0: {masked!r}")
    for (w, h, seed, gain) in [(24, 17, 5, 4.0), (40, 31, 9, 4.0), (33, 27, 2, 300.0), (160, 120, 21, 3000.0)]:
        ref, test = hdr_pair(w, h, seed, gain)
        m, mean, params = fe.evaluate(ref, test, "HDR", applyMagma=False)
        m = np.asarray(m).reshape(h, w)
        print(f"FLIP {w}x{h} seed {seed}: mean {mean!r} params {params}")
        for (x, y) in [(0, 0), (7, 3), (w - 1, h - 1), (w // 2, h // 2)]:
            print(f"   map[{x},{y}] = {m[y, x]!r}")
        m.astype(np.float32).tofile(f"/tmp/flip_ref_{w}x{h}_{seed}.f32")
