"""Shared fixtures: a miniature sweep (one scene of the embedded spot mesh at 48 px, six
models fitted 150 steps; rp, ts and fmbrdf for the Mitsuba plugin's parametric kinds, a few
seconds)
made once per session by the workspace's xtask binary.

The binary is ``$NEURAL_BRDF_XTASK``, else ``target/debug/xtask`` of the workspace (built by
``cargo test --workspace`` or ``cargo build -p xtask``). Without it the tests that need a scene
are skipped, except in CI (``CI=true``), where a missing binary is a failure.
"""

import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]

PROFILE = """\
name = "python-tests"
description = "the Python package's tests: one scene, six models, 150 steps"
[data]
meshes = ["embedded:spot"]
materials = ["blue-acrylic"]
size = 48
views = 4
lights = 12
[run]
seed = 7
[run.model]
width = 16
[run.features.lbo]
k_max = 32
first = 16
blocks = 1
block_len = 8
[run.train]
profile = "quick"
iterations = 150
batch_size = 1024
warmup_steps = 10
checkpoint_every = 50
log_every = 10
validate_every = 25
patience = 50
[run.eval]
energy_pairs = 4
reciprocity_pairs = 200
[sweep]
models = ["disney", "single_mlp", "additive_shared_enhanced", "rp", "ts", "fmbrdf"]
"""


def _xtask():
    exe = os.environ.get("NEURAL_BRDF_XTASK") or str(ROOT / "target" / "debug" / "xtask")
    if os.path.exists(exe):
        return exe
    msg = f"no xtask binary at {exe} (cargo build -p xtask, or set NEURAL_BRDF_XTASK)"
    if os.environ.get("CI") == "true":
        pytest.fail(msg)
    pytest.skip(msg)


@pytest.fixture(scope="session")
def sweep(tmp_path_factory):
    """The output folder of the miniature sweep: ``scenes/``, ``runs/``, ``tables/``."""
    exe = _xtask()
    base = tmp_path_factory.mktemp("mini sweep")
    profile = base / "mini.toml"
    profile.write_text(PROFILE)
    out = base / "out"
    done = subprocess.run(
        [exe, "reproduce-tables", "--profile", str(profile), "--out", str(out), "--jobs", "1"],
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
        env=dict(os.environ, RUST_BACKTRACE="0", RUST_LIB_BACKTRACE="0"),
    )
    if done.returncode != 0:
        pytest.fail(f"the miniature sweep failed:\n{done.stderr[-3000:]}")
    return out


@pytest.fixture(scope="session")
def scene_dir(sweep):
    scenes = [p for p in (sweep / "scenes").iterdir() if (p / "manifest.json").exists()]
    assert len(scenes) == 1, scenes
    return scenes[0]


@pytest.fixture(scope="session")
def run_dirs(sweep):
    """Run directories by model kind."""
    runs = {}
    for p in (sweep / "runs").rglob("config.toml"):
        text = p.read_text()
        for line in text.splitlines():
            if line.startswith("kind = "):
                runs.setdefault(line.split('"')[1], p.parent)
    return runs
