"""Robots from MJCF at their own timestep, with contacts: tumble's articulation beside MuJoCo, in the same run
(issue 47, part 3).

Run from the repository root:

    python -m benchmarks.run --only robots

Models: Gymnasium's hopper, walker2d (v5), half_cheetah, ant and humanoid, each at its file's timestep and
integrator (MuJoCo's Euler as tumble's semi-implicit Euler), loaded by ``tumble.articulation.from_mjcf`` and by
``mujoco.MjModel.from_xml_path``, dropped from their initial pose with contacts, joint limits, armature, damping and
motors. Two ways of running ``seconds`` of simulated time:

* ``simulate``: the whole run in one call (tumble's ``Articulation.simulate`` with the controls held; MuJoCo's
  ``mj_step(model, data, nstep=N)``);
* ``step loop``: a Python loop that sets the controls every step (``art.ctrl = u; art.step(dt)``; ``data.ctrl[:] = u;
  mj_step(model, data)``), ``u = 0.4 sin(1.7 i + t)``.

Columns: ``realtime`` (simulated seconds per wall-clock second, best of ``repeat``) and ``x_mujoco`` (tumble's
real-time factor over MuJoCo's in the same mode: above 1 tumble is faster). Timings are never pass/fail tests.

Then the same at ten times the size: ``chain of N``, a chain of N capsules (a free root, hinges with ranges) lying on
a plane, every capsule free to touch every other but its neighbours (N = 10 and 100), in ``simulate``.
"""

from __future__ import annotations

import os
import time
import warnings

import numpy as np

__all__ = ["MODELS", "bench_robots"]

MODELS = ("hopper", "walker2d_v5", "half_cheetah", "ant", "humanoid")


def _assets() -> str | None:
    try:
        import gymnasium
    except ImportError:
        return None
    return os.path.join(os.path.dirname(gymnasium.__file__), "envs", "mujoco", "assets")


def _controls(count: int, t: float) -> np.ndarray:
    return 0.4 * np.sin(1.7 * np.arange(count) + t)


def _tumble(path: str):
    from tumble.articulation import from_mjcf

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return from_mjcf(path)


def _mujoco(path: str):
    import mujoco

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # half_cheetah's deprecated settotalmass
        model = mujoco.MjModel.from_xml_path(path)
    return model, mujoco.MjData(model)


def _tumble_run(path: str, seconds: float, loop: bool) -> float:
    art = _tumble(path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model, _ = _mujoco(path)
    import mujoco

    dt = model.opt.timestep
    integrator = "rk4" if model.opt.integrator == mujoco.mjtIntegrator.mjINT_RK4 else "symplectic"
    steps = round(seconds / dt)
    art.ctrl = _controls(len(art.ctrl), 0.0)
    art.step(dt, integrator=integrator)  # the kernels loaded before timing
    start = time.perf_counter()
    if loop:
        count = len(art.ctrl)
        for n in range(steps):
            art.ctrl = _controls(count, n * dt)
            art.step(dt, integrator=integrator)
    else:
        art.simulate(seconds, dt, integrator=integrator, record_every=steps)
    return time.perf_counter() - start


def _mujoco_run(path: str, seconds: float, loop: bool) -> float:
    import mujoco

    model, data = _mujoco(path)
    dt = model.opt.timestep
    steps = round(seconds / dt)
    data.ctrl[:] = _controls(model.nu, 0.0)
    start = time.perf_counter()
    if loop:
        for n in range(steps):
            data.ctrl[:] = _controls(model.nu, n * dt)
            mujoco.mj_step(model, data)
    else:
        mujoco.mj_step(model, data, nstep=steps)
    return time.perf_counter() - start


def chain_mjcf(links: int) -> str:
    """A chain of ``links`` capsules of 0.1 m, a free root 0.3 m over a plane, hinges about y limited to ±30°."""
    body = ""
    for i in reversed(range(links)):
        joint = "<freejoint/>" if i == 0 else '<joint axis="0 1 0" range="-30 30" damping="0.01"/>'
        pos = "0 0 0.3" if i == 0 else "0.1 0 0"
        body = f'<body pos="{pos}">{joint}<geom type="capsule" fromto="0 0 0 0.1 0 0" size="0.02"/>{body}</body>'
    return (f'<mujoco model="chain of {links}"><option timestep="0.002" integrator="RK4"/><worldbody>'
            f'<geom type="plane" size="10 10 1"/>{body}</worldbody></mujoco>')  # fmt: skip


def bench_robots(seconds: float = 2.0, repeat: int = 3, models=MODELS, chains=(10, 100)) -> list[dict]:
    """One row per model, engine and mode."""
    folder = _assets()
    if folder is None:
        return []
    try:
        import mujoco  # noqa: F401
    except ImportError:
        return []
    files = []
    for links in chains:
        path = os.path.join(os.environ.get("TMPDIR", "/tmp"), f"tumble_bench_chain_{links}_{os.getpid()}.xml")
        with open(path, "w") as file:
            file.write(chain_mjcf(links))
        files.append((f"chain of {links}", path))
    named = [(name, os.path.join(folder, f"{name}.xml")) for name in models] + files
    try:
        rows = _rows(named, seconds, repeat, chains=[name for name, _ in files])
    finally:
        for _, path in files:
            os.unlink(path)
    return rows


def _rows(named, seconds: float, repeat: int, chains) -> list[dict]:
    """The rows of each model; a chain runs ``simulate`` only, at most 0.5 s (the 100-capsule one is slow)."""
    rows = []
    for name, path in named:
        chain = name in chains
        run_seconds = min(seconds, 0.5) if chain else seconds
        for mode, loop in (("simulate", False),) if chain else (("simulate", False), ("step loop", True)):
            walls = {"tumble": min(_tumble_run(path, run_seconds, loop) for _ in range(repeat)),
                     "MuJoCo": min(_mujoco_run(path, run_seconds, loop) for _ in range(repeat))}  # fmt: skip
            for engine, wall in walls.items():
                rows.append({"model": name, "mode": mode, "engine": engine, "realtime": run_seconds / wall,
                             "x_mujoco": walls["MuJoCo"] / wall})  # fmt: skip
    return rows


if __name__ == "__main__":
    for row in bench_robots(seconds=1.0, repeat=1):
        print(row)
