"""Every example runs headless with few steps; its summary line is pinned (a regex, with why it last changed)."""

from __future__ import annotations

import importlib.util
import inspect
import re
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

PINNED = {
    # Exact parabola and RK4 energy conservation (pinned at the first version).
    "basic/hello_world.py": r"final: t=1\.00 s, z=1\.0950 m, energy drift \de-(09|1\d)",
    # 5 s of the T-handle at 12 rad/s: the first flip is at 2.16 s; energy and |L| conserved (first version).
    "basic/dzhanibekov.py": r"final: 1 flips in 5\.0 s, energy drift \d\.\de-1\d, \|L\| drift \d\.\de-1[4-6]",
    # Lagrange's equations through SymPy (first versions): exact elliptic period, virtual work, chaos with E kept.
    "lagrange/pendulum.py": r"final: period 2\.367842 s \(exact 2\.367842 s, error \de-1\d\), "
    r"energy drift \de-(09|1\d)",
    "lagrange/slider_crank.py": r"final: 12 crank angles balanced, max torque error \de-1\d N m",
    "lagrange/double_pendulum.py": r"final: 5\.0 s of chaotic swinging, energy drift \de-(09|1\d)",
    # World joints (issue 4, first versions): a motor door sweeps a box to its 110° stop; a slider–crank loop on
    # its closed form; a ragdoll falls down eight steps (chaotic: only the start, the time and the outcome pinned).
    "joints/door.py": r"final: door at 110\.0° \(stop 110°\), 1\.000 rad/s before the box, box pushed 1\.\d\d m, "
    r"hinge gap 0\.\d\d mm",
    "joints/slider_crank.py": r"final: 2\.00 turns at 6\.28\d rad/s, piston within 0\.\d\d mm of "
    r"r cos θ \+ √\(l² − r² sin² θ\)",
    "joints/ragdoll.py": r"final: pelvis from 2\.61 m to 0\.[0-4]\d m in 3\.0 s, no body centre under a tread, "
    r"joint gaps \d\.\d mm now",
    # The quadrotor through three gates (issue 19, first version: 5.5 cm RMS, 10.3 cm at most).
    "vehicles/gates.py": r"final: 3 of 3 gates passed in 8\.3 s, [4-6]\.\d cm RMS off the path, "
    r"(9|1[01])\.\d cm at most",
    # Issue 29 (first versions): a bang-bang state feedback balances every copy of the vector env; PPO's summary
    # (stable-baselines3, skipped where it is not installed: not in CI).
    "rl/cartpole_vector.py": r"final: 256 copies for 600 steps, 0 fell, 256 episodes reached the 500-step limit",
    "rl/train_cartpole_sb3.py": r"final: \d+ episodes, mean return of the last 20: \d+\.\d",
    # Issue 48: with a tiny budget both engines see the same episodes, so PPO learns the same policy from each.
    "rl/train_hopper_sb3.py": r"final: the same (\d+) episodes on both engines, mean return of the last 20 \d+, "
    r"trained policy \d+ over 10 episodes",
    # Issue 30 (first version): 15 members on a process pool, each within a step's slide of Coulomb's law.
    "ensembles/friction_sweep.py": r"final: 15 of 15 members done in 1\.00 s each, largest difference from "
    r"Coulomb's law 0\.\d\d mm",
}
STEPS = {
    "basic/hello_world.py": 100,
    "basic/dzhanibekov.py": 5000,
    "lagrange/pendulum.py": 400,
    "lagrange/slider_crank.py": 12,
    "lagrange/double_pendulum.py": 500,
    "joints/door.py": 150,
    "joints/slider_crank.py": 120,
    "joints/ragdoll.py": 180,
    "vehicles/gates.py": 4150,
    "rl/cartpole_vector.py": 600,
    "rl/train_cartpole_sb3.py": 16384,
    "rl/train_hopper_sb3.py": 4096,
    "ensembles/friction_sweep.py": 240,
}
# optional packages, skipped where missing
NEEDS = {"rl/train_cartpole_sb3.py": "stable_baselines3", "rl/train_hopper_sb3.py": "stable_baselines3"}


def load(relative: str):
    spec = importlib.util.spec_from_file_location(relative.replace("/", "_")[:-3], EXAMPLES / relative)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_every_example_is_pinned():
    found = {p.relative_to(EXAMPLES).as_posix() for p in EXAMPLES.rglob("*.py")}
    assert found == set(PINNED)


@pytest.mark.parametrize("relative", sorted(PINNED))
def test_example_summary(relative, tmp_path):
    if relative in NEEDS:
        pytest.importorskip(NEEDS[relative])
    module = load(relative)
    assert module.__doc__ and "Run:" in module.__doc__
    kwargs = {"out": tmp_path} if "out" in inspect.signature(module.main).parameters else {}
    summary = module.main(steps=STEPS[relative], render=False, **kwargs)
    assert re.fullmatch(PINNED[relative], summary), summary


def test_demo_writes_its_plot(tmp_path, monkeypatch):
    module = load("basic/dzhanibekov.py")
    monkeypatch.setattr(module, "OUT", tmp_path)
    module.main(steps=3000, render=True)
    assert (tmp_path / "dzhanibekov.png").stat().st_size > 10_000


def test_gates_example_writes_its_replay_and_plots(tmp_path, monkeypatch):
    module = load("vehicles/gates.py")
    monkeypatch.setattr(module, "OUT", tmp_path)
    assert module.main(steps=1500, render=True).startswith("final: 1 of 3 gates passed in 3.0 s")
    assert (tmp_path / "gates.png").stat().st_size > 20_000 and (tmp_path / "gates.html").stat().st_size > 50_000
