"""tumble's benchmarks against MuJoCo (issue 2).

Run from the repository root:

    python -m benchmarks.run [--quick] [--only NAME] [--csv [DIR]] [--repeat N] [--machine NAME]

``tumbling``     one body, I = diag(1, 2, 3), ω₀ = (0.01, 5, 0.01), no gravity, 20 000 steps of 1 ms: steps/s and
                 the drift of energy and angular momentum, per integrator, tumble and MuJoCo side by side.
``many_bodies``  4096 free spheres under gravity in one world, no collisions: body-steps per second; then the same
                 scene at 1 000, 10 000 and 100 000 bodies, 10⁷ body-steps a call (the cost per body should be flat).
``cold_start``   ``import tumble`` and the first ``step``/``simulate`` in a fresh process, Numba cache cold
                 and warm.
``pile``, ``pyramid``, ``cubes``, ``big_pyramid``
                 contact scenes, tumble against MuJoCo and PyBullet (``benchmarks/contact.py``); ``big_pyramid``
                 (5050 boxes, tumble only) runs only when asked for with ``--only``.
``contact_steps``
                 a box on a plane and the 27-box pile stepped from Python, beside the same steps inside one
                 ``simulate`` and MuJoCo's ``mj_step`` loop (``benchmarks/contact_steps.py``).
``articulation_chain``
                 the 20-link pendulum chain in generalised coordinates (``tumble.Articulation``, RK4 and symplectic)
                 beside MuJoCo's Euler and RK4, 10 s at dt = 1 ms (``benchmarks/articulation.py``).
``world_chain``  a 20-link chain of world hinge joints released horizontal, 10 s: steps/s, joint gaps and energy,
                 tumble against PyBullet and MuJoCo (``benchmarks/joints.py``).
``quadrotor``    a Crazyflie flying the figure eight at 100 and 500 Hz with the SE(3) controller every step,
                 tumble against RotorPy (``benchmarks/quadrotor.py``).
``build``        building worlds of 1k to 100k free bodies and 1k to 10k joints (a chain, a grid) through the API
                 and from scene files, beside MuJoCo compiling the same bodies from MJCF (``benchmarks/build.py``).
``first_run``    cold runs with an empty Numba cache: the flagship in one process and after ``tumble warmup --jobs 2``,
                 a sphere on a plane (``benchmarks/first_run.py``; only with ``--only``, about five minutes).
``model_files``  loading MJCF: Gymnasium's humanoid and a 100-link chain, tumble's reader and builder beside MuJoCo's
                 compiler (``benchmarks/model_files.py``).
``mjcf_contacts`` Gymnasium's ant with contacts and its motors driven, in a tumble World and in MuJoCo at its 0.01 s
                 step (``benchmarks/model_files.py``).
``robots``       Gymnasium's hopper, walker2d, half_cheetah, ant and humanoid as articulations with contacts at their
                 own timesteps, in ``simulate`` and in a Python step loop that sets ``ctrl``, beside MuJoCo
                 (``benchmarks/robots.py``).
``batch``        many copies at once: 4096 copies of a tumbling body and 1024 copies of a 10-box pile in a
                 ``tumble.Batch`` beside ``mujoco.rollout`` with the same copies and threads (``benchmarks/batch.py``).
``envs``         Gymnasium environments: tumble/CartPole and tumble/DoublePendulum beside InvertedPendulum-v5 and
                 InvertedDoublePendulum-v5, and the five locomotion tasks beside their -v5 MuJoCo envs, one env
                 and vector envs of 1, 64 and 1024 copies (``benchmarks/envs.py``).
``ensemble``     64 members of the box pile through ``tumble.ensemble.run`` on a local process pool and a Dask
                 LocalCluster with 1 and 2 workers, beside a serial loop: the scaling efficiency
                 (``benchmarks/ensembles.py``).
``broad_phase``  world bounds and sort-and-sweep pairs alone, on a pile and a scatter of 1k and 5k shapes
                 (``benchmarks/broad_phase.py``; tumble only: no peer exposes its broad phase).

Every timing is the best of ``--repeat`` runs after a first call that is reported apart (it includes the
JIT compile or the load from Numba's disk cache). Both engines run in the same process, so compare the
ratios, not the absolute figures, across machines. ``--csv`` writes ``DIR/<machine>/<name>.csv`` (DIR
defaults to ``benchmarks/results``) plus ``machine.csv`` with the commit, versions, CPU and thread count.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import platform
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numba
import numpy as np

import tumble
from tumble.dynamics import integrate

from . import (
    articulation,
    batch,
    broad_phase,
    build,
    contact,
    contact_steps,
    ensembles,
    envs,
    first_run,
    joints,
    model_files,
    peers,
    quadrotor,
    robots,
)

__all__ = [
    "BENCHMARKS",
    "FULL",
    "OPTIONAL",
    "QUICK",
    "Sizes",
    "bench_cold_start",
    "bench_many_bodies",
    "bench_tumbling",
    "check_targets",
    "cold_start_script",
    "format_table",
    "machine_info",
    "main",
]

REPO = Path(__file__).resolve().parent.parent
DT = 1e-3
INERTIA = (1.0, 2.0, 3.0)
OMEGA0 = (0.01, 5.0, 0.01)
TUMBLE_INTEGRATORS = ("auto", "rk4", "symplectic", "euler")
MUJOCO_INTEGRATORS = ("Euler", "RK4")
SEED = 0


@dataclass(frozen=True)
class Sizes:
    """How big each benchmark is; :data:`FULL` for the report, :data:`QUICK` for the smoke test."""

    tumbling_steps: int = 20_000
    record_every: int = 100
    bodies: int = 4096
    body_steps: int = 1000
    mujoco_seconds: float = 2.0  # wall time of one timed MuJoCo run in ``many_bodies``
    scaling_bodies: tuple[int, ...] = (1_000, 10_000, 100_000)  # ``many_bodies`` again at these sizes
    scaling_body_steps: int = 10_000_000  # body-steps per call at each of them
    repeat: int = 7
    cold_start: bool = True
    cold_start_bodies: int = 64
    pile_boxes: int = 1000  # contact benchmarks (benchmarks/contact.py)
    pile_seconds: float = 3.0
    pyramid_base: int = 20
    pyramid_seconds: float = 10.0
    cubes_boxes: tuple[int, ...] = (64, 512)
    cubes_seconds: float = 3.0
    big_pyramid_base: int = 100
    big_pyramid_seconds: float = 2.0
    chain_links: int = 20  # world-joint chain (benchmarks/joints.py)
    chain_seconds: float = 10.0
    quadrotor_seconds: float = 10.0  # simulated time of each quadrotor flight (benchmarks/quadrotor.py)
    rotorpy_seconds: float = 10.0  # at most this much for RotorPy's own flights
    build_bodies: tuple[int, ...] = (1_000, 10_000, 100_000)  # worlds built (benchmarks/build.py)
    build_joints: tuple[int, ...] = (1_000, 10_000)
    broad_phase_shapes: tuple[int, ...] = (1_000, 5_000)  # benchmarks/broad_phase.py
    contact_step_calls: int = 2000  # steps of the box on a plane (the pile: a tenth) (benchmarks/contact_steps.py)


FULL = Sizes()
QUICK = Sizes(
    tumbling_steps=200, record_every=100, bodies=64, body_steps=50, mujoco_seconds=0.02, repeat=1,
    cold_start=False, cold_start_bodies=8, scaling_bodies=(16, 64), scaling_body_steps=3200, pile_boxes=27,
    pile_seconds=0.2, pyramid_base=4, pyramid_seconds=0.2,
    cubes_boxes=(8, 27), cubes_seconds=0.2, big_pyramid_base=6, big_pyramid_seconds=0.2, chain_links=4,
    chain_seconds=0.2, quadrotor_seconds=0.2, rotorpy_seconds=0.2, build_bodies=(100, 400), build_joints=(100, 400),
    broad_phase_shapes=(50,), contact_step_calls=20,
)  # fmt: skip


def _timed(function: Callable, *args, **kwargs) -> tuple[float, object]:
    start = time.perf_counter()
    result = function(*args, **kwargs)
    return time.perf_counter() - start, result


# --- machine -----------------------------------------------------------------------------------------


def _commit() -> str:
    try:
        out = subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"], cwd=REPO, capture_output=True, text=True, timeout=10
        )
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return out.stdout.strip() or "unknown"


def _cpu_model() -> str:
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine() or "unknown"


def _mujoco_version() -> str:
    try:
        import mujoco
    except ImportError:
        return "not installed"
    return mujoco.__version__


def machine_info() -> dict[str, object]:
    """Commit, versions, CPU and threads: what a result depends on."""
    try:
        usable = len(os.sched_getaffinity(0))
    except AttributeError:
        usable = os.cpu_count()
    return {
        "commit": _commit(),
        "date": time.strftime("%Y-%m-%d %H:%M:%S %Z"),
        "host": socket.gethostname() or "local",
        "cpu": _cpu_model(),
        "cores": usable,
        "numba_threads": numba.get_num_threads(),
        "tumble_threads": integrate.threads(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "numba": numba.__version__,
        "mujoco": _mujoco_version(),
        "tumble": tumble.__version__,
    }


# --- measurements shared by both engines -------------------------------------------------------------


def _drifts(quat: np.ndarray, omega_body: np.ndarray) -> tuple[float, float]:
    """``(max|E − E0|/E0, max|L − L0|/|L0|)`` of the tumbling body from frames (T, 4) and (T, 3).

    The same formula for both engines: E = ½ ωᵀ I ω from the body-frame spin, L = R I ω in the world frame.
    """
    energy = peers.rotational_energy(INERTIA, omega_body)
    angmom = peers.angular_momentum_world(quat, INERTIA, omega_body)
    e_drift = float(np.max(np.abs(energy - energy[0])) / energy[0])
    l_drift = float(np.max(np.linalg.norm(angmom - angmom[0], axis=1)) / np.linalg.norm(angmom[0]))
    return e_drift, l_drift


def _chunks(steps: int, every: int) -> list[int]:
    return [every] * (steps // every) + ([steps % every] if steps % every else [])


# --- 1. tumbling body --------------------------------------------------------------------------------


def _tumbling_world(integrator: str) -> tumble.World:
    world = tumble.World(gravity=(0.0, 0.0, 0.0), integrator=integrator)
    world.add_body(None, mass=1.0, inertia=np.diag(INERTIA), angular_velocity=OMEGA0)
    world.state  # build the model now, outside the timed region  # noqa: B018
    return world


def _tumble_simulate(integrator: str, sizes: Sizes) -> dict:
    steps, every = sizes.tumbling_steps, sizes.record_every
    # The first call has the timed call's size: a long run of one body takes the parallel kernel.
    first, _ = _timed(_tumbling_world(integrator).simulate, steps * DT, DT, record_every=every)
    best = math.inf
    for _ in range(sizes.repeat):
        world = _tumbling_world(integrator)
        elapsed, traj = _timed(world.simulate, steps * DT, DT, record_every=every)
        best = min(best, elapsed)
    e_drift, l_drift = _drifts(traj.orientation[:, 0], traj.angular_velocity_body()[:, 0])
    return _tumbling_row("tumble", integrator, "simulate", steps, best, first, e_drift, l_drift)


def _tumble_step_loop(integrator: str, sizes: Sizes) -> dict:
    steps, every = sizes.tumbling_steps, sizes.record_every
    first, _ = _timed(_tumbling_world(integrator).step, DT)
    best = math.inf
    for _ in range(sizes.repeat):
        world = _tumbling_world(integrator)
        body = world.bodies[0]
        step = world.step
        quats, omegas = [body.orientation], [body.angular_velocity_body]
        elapsed = 0.0
        for n in _chunks(steps, every):
            start = time.perf_counter()
            for _ in range(n):
                step(DT)
            elapsed += time.perf_counter() - start
            quats.append(body.orientation)
            omegas.append(body.angular_velocity_body)
        best = min(best, elapsed)
    e_drift, l_drift = _drifts(np.array(quats), np.array(omegas))
    return _tumbling_row("tumble", integrator, "step() loop", steps, best, first, e_drift, l_drift)


def _mujoco_tumbling_reset(model, data) -> None:
    import mujoco

    mujoco.mj_resetData(model, data)
    peers.set_free_body_angvel(model, data, [OMEGA0])  # identity orientation: body frame == world frame


def _mujoco_step_loop(integrator: str, sizes: Sizes) -> dict:
    import mujoco

    steps, every = sizes.tumbling_steps, sizes.record_every
    model, data = peers.load(peers.tumbling_body_mjcf(integrator, DT, 1.0, INERTIA))
    _mujoco_tumbling_reset(model, data)
    first, _ = _timed(mujoco.mj_step, model, data)
    best = math.inf
    for _ in range(sizes.repeat):
        _mujoco_tumbling_reset(model, data)
        frames = [peers.free_body_arrays(model, data.qpos, data.qvel)]
        elapsed = 0.0
        for n in _chunks(steps, every):
            start = time.perf_counter()
            for _ in range(n):
                mujoco.mj_step(model, data)
            elapsed += time.perf_counter() - start
            frames.append(peers.free_body_arrays(model, data.qpos, data.qvel))
        best = min(best, elapsed)
    quat = np.array([f[0][0] for f in frames])
    omega = np.array([f[1][0] for f in frames])
    e_drift, l_drift = _drifts(quat, omega)
    return _tumbling_row("MuJoCo", integrator, "mj_step loop", steps, best, first, e_drift, l_drift)


def _mujoco_rollout(integrator: str, sizes: Sizes) -> dict | None:
    """The whole run in one call of MuJoCo's C rollout (the fair match for ``world.simulate``)."""
    import mujoco

    try:
        from mujoco import rollout
    except ImportError:
        return None
    steps, every = sizes.tumbling_steps, sizes.record_every
    model, data = peers.load(peers.tumbling_body_mjcf(integrator, DT, 1.0, INERTIA))
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    _mujoco_tumbling_reset(model, data)
    initial = np.empty((1, mujoco.mj_stateSize(model, spec)))
    mujoco.mj_getState(model, data, initial[0], spec)
    out = np.empty((1, steps, initial.shape[1]))
    first, _ = _timed(rollout.rollout, model, data, initial, nstep=steps, state=out)
    best = math.inf
    for _ in range(sizes.repeat):
        elapsed, _ = _timed(rollout.rollout, model, data, initial, nstep=steps, state=out)
        best = min(best, elapsed)
    # Row k of ``out`` is the state after k + 1 steps; read every ``every``-th back through an MjData.
    scratch = mujoco.MjData(model)
    frames = []
    for row in [initial[0], *out[0, every - 1 :: every]]:
        mujoco.mj_setState(model, scratch, row, spec)
        frames.append(peers.free_body_arrays(model, scratch.qpos, scratch.qvel))
    quat = np.array([f[0][0] for f in frames])
    omega = np.array([f[1][0] for f in frames])
    e_drift, l_drift = _drifts(quat, omega)
    return _tumbling_row("MuJoCo", integrator, "rollout", steps, best, first, e_drift, l_drift)


def _tumbling_row(engine, integrator, mode, steps, seconds, first, e_drift, l_drift) -> dict:
    return {
        "engine": engine,
        "integrator": integrator,
        "mode": mode,
        "steps": steps,
        "steps_per_s": steps / seconds,
        "us_per_step": 1e6 * seconds / steps,
        "first_call_ms": 1e3 * first,
        "energy_drift": e_drift,
        "angmom_drift": l_drift,
    }


def bench_tumbling(sizes: Sizes = FULL) -> list[dict]:
    """Benchmark 1: one tumbling body, every tumble integrator and MuJoCo Euler/RK4.

    ``x_mujoco_rk4`` is steps/s over that of the faster of MuJoCo's two RK4 runs (rollout, mj_step loop).
    """
    rows = [_tumble_simulate(name, sizes) for name in TUMBLE_INTEGRATORS]
    rows += [_tumble_step_loop(name, sizes) for name in TUMBLE_INTEGRATORS]
    if peers.have_mujoco():
        for name in MUJOCO_INTEGRATORS:
            row = _mujoco_rollout(name, sizes)
            rows += [row] if row is not None else []
            rows.append(_mujoco_step_loop(name, sizes))
        reference = max(r["steps_per_s"] for r in rows if r["engine"] == "MuJoCo" and r["integrator"] == "RK4")
        for r in rows:
            r["x_mujoco_rk4"] = r["steps_per_s"] / reference
    return rows


# --- 2. many free bodies -----------------------------------------------------------------------------


def _many_bodies_world(n: int) -> tumble.World:
    world = tumble.World()  # default gravity (0, 0, -9.81)
    omega = peers.random_angular_velocities(n, SEED)
    for position, w in zip(peers.grid_positions(n), omega, strict=True):
        world.add_body(tumble.Sphere(0.05), mass=1.0, position=position, angular_velocity=w, collision_mask=0)
    world.state  # noqa: B018
    return world


@dataclass
class _Contender:
    """One configuration of the many-bodies benchmark: ``run()`` takes ``steps`` steps and returns seconds."""

    row: dict
    run: Callable[[], float]
    best: float = math.inf


def _tumble_contender(world: tumble.World, integrator: str, threads: int, steps: int, build_s: float) -> _Contender:
    def run() -> float:
        world.integrator = integrator
        with integrate.using_threads(threads):
            elapsed, _ = _timed(world.simulate, steps * DT, DT, record_every=steps)
        if not np.all(np.isfinite(world.state.body_pos)):
            raise RuntimeError(f"tumble {integrator}: non-finite positions in the many-bodies run")
        return elapsed

    row = _many_row("tumble", integrator, "no contacts", threads, world.state.body_count, steps, build_s)
    return _Contender(row, run)


def _mujoco_contender(sizes: Sizes, disable_contact: bool) -> _Contender:
    import mujoco

    n = sizes.bodies
    xml = peers.free_bodies_mjcf(peers.grid_positions(n), integrator="Euler", timestep=DT,
                                 disable_contact=disable_contact)  # fmt: skip
    build_s, (model, data) = _timed(peers.load, xml)
    peers.set_free_body_angvel(model, data, peers.random_angular_velocities(n, SEED))
    probe, _ = _timed(lambda: [mujoco.mj_step(model, data) for _ in range(5)])
    steps = max(5, round(sizes.mujoco_seconds / (probe / 5)))

    def run() -> float:
        start = time.perf_counter()
        for _ in range(steps):
            mujoco.mj_step(model, data)
        elapsed = time.perf_counter() - start
        if not np.all(np.isfinite(data.qpos)):
            raise RuntimeError("MuJoCo: non-finite positions in the many-bodies run")
        return elapsed

    config = "contact disabled" if disable_contact else "contype=0"
    row = _many_row("MuJoCo", "Euler", config, 1, n, steps, build_s)
    row["first_call_s"] = probe / 5  # the first steps (MuJoCo compiles nothing at run time)
    return _Contender(row, run)


def _many_row(engine, integrator, config, threads, bodies, steps, build_s) -> dict:
    return {
        "engine": engine,
        "integrator": integrator,
        "config": config,
        "threads": threads,
        "bodies": bodies,
        "steps": steps,
        "build_s": build_s,
    }


def bench_many_bodies(sizes: Sizes = FULL) -> list[dict]:
    """Benchmark 2: ``sizes.bodies`` free spheres under gravity in one world, random spins (same seed).

    The configurations take turns, round after round (best of ``min(repeat, 5)`` rounds), so that load from
    other processes falls on all of them alike. tumble runs ``body_steps`` steps per call, MuJoCo about
    ``mujoco_seconds`` of wall time. ``x_mujoco`` is body-steps/s over MuJoCo's (Euler, ``contype=0``; MuJoCo
    steps on one thread). The tumble world keeps falling from one call to the next.
    """
    build_s, world = _timed(_many_bodies_world, sizes.bodies)
    threads = integrate.threads()
    contenders = [
        _tumble_contender(world, integrator, count, sizes.body_steps, build_s)
        for integrator in ("auto", "symplectic")
        for count in sorted({threads, 1}, reverse=True)
    ]
    # What auto costs where it runs RK4 (a body with torque, damping or an anisotropic spin): the same spheres.
    contenders.append(_tumble_contender(world, "rk4", threads, sizes.body_steps, build_s))
    if peers.have_mujoco():
        contenders += [_mujoco_contender(sizes, disable_contact=flag) for flag in (False, True)]
    for bodies in sizes.scaling_bodies:  # the same scene at other sizes, the same body-steps per call
        scaling_build_s, scaled = _timed(_many_bodies_world, bodies)
        for integrator in ("auto", "symplectic"):
            steps = max(1, sizes.scaling_body_steps // bodies)
            contender = _tumble_contender(scaled, integrator, threads, steps, scaling_build_s)
            contender.row["config"] = "no contacts, scaling"
            contenders.append(contender)
    for c in contenders:
        first = c.run()
        c.row.setdefault("first_call_s", first)
    for _ in range(max(1, min(sizes.repeat, 5))):
        for c in contenders:
            c.best = min(c.best, c.run())
    rows = []
    for c in contenders:
        rows.append({**c.row, "wall_s": c.best, "body_steps_per_s": c.row["bodies"] * c.row["steps"] / c.best})
    mujoco_rows = [r for r in rows if r["engine"] == "MuJoCo" and r["config"] == "contype=0"]
    if mujoco_rows:
        for r in rows:
            r["x_mujoco"] = r["body_steps_per_s"] / mujoco_rows[0]["body_steps_per_s"]
    return rows


# --- 3. cold start -----------------------------------------------------------------------------------

_COLD_START_SCRIPT = """
import json, time
start = time.perf_counter()
import tumble
imported = time.perf_counter()
import numpy as np


def first_step():
    world = tumble.World(gravity=(0.0, 0.0, 0.0))
    world.add_body(None, mass=1.0, inertia=np.diag([1.0, 2.0, 3.0]), angular_velocity=(0.01, 5.0, 0.01))
    world.state
    t = time.perf_counter()
    world.step(1e-3)
    return time.perf_counter() - t


def first_simulate():
    world = tumble.World()
    for i in range({bodies}):
        world.add_body(tumble.Sphere(0.05), mass=1.0, position=(0.2 * i, 0.0, 10.0),
                       angular_velocity=(1.0, 2.0, 3.0), collision_mask=0)
    world.state
    t = time.perf_counter()
    world.simulate(1.0, 1e-3, record_every=1000)
    return time.perf_counter() - t


times = {{"import_s": imported - start}}
for name in {order!r}:
    times[name + "_s"] = first_step() if name == "first_step" else first_simulate()
print(json.dumps(times))
"""

_ORDERS = {"step first": ("first_step", "first_simulate"), "simulate first": ("first_simulate", "first_step")}


def cold_start_script(bodies: int, order: str = "step first") -> str:
    """The Python source a cold-start process runs; it prints its timings as one JSON line."""
    return _COLD_START_SCRIPT.format(bodies=int(bodies), order=_ORDERS[order])


def _cold_start_process(cache_dir: str, bodies: int, order: str = "step first") -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir)
    script = cold_start_script(bodies, order)
    start = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", script], env=env, cwd=REPO, capture_output=True, text=True,
                         timeout=600)  # fmt: skip
    process_s = time.perf_counter() - start
    if out.returncode != 0:
        raise RuntimeError(f"cold-start subprocess failed ({out.returncode}):\n{out.stderr}")
    result = json.loads(out.stdout.strip().splitlines()[-1])
    result["process_s"] = process_s
    return result


def _cold_start_row(cache: str, order: str, r: dict) -> dict:
    return {
        "cache": cache,
        "order": order,
        "import_s": r["import_s"],
        "first_step_s": r["first_step_s"],
        "import_plus_step_s": r["import_s"] + r["first_step_s"],
        "first_simulate_s": r["first_simulate_s"],
        "process_s": r["process_s"],
    }


def bench_cold_start(sizes: Sizes = FULL) -> list[dict]:
    """Benchmark 3: a fresh interpreter per run with ``NUMBA_CACHE_DIR`` a new empty directory (cold), then
    the same directory again (warm, best of ``min(repeat, 3)``).

    Each process imports tumble, takes one ``step`` of one body and one ``simulate`` of
    ``cold_start_bodies`` bodies for 1000 steps (enough work for the parallel kernel), in that order; a last
    cold process does the ``simulate`` first, as a script that starts with a big run would.
    ``import_plus_step_s`` is what the targets judge.
    """
    bodies = sizes.cold_start_bodies
    with tempfile.TemporaryDirectory(prefix="tumble-numba-cache-") as cache_dir:
        cold = _cold_start_process(cache_dir, bodies)
        warm_runs = [_cold_start_process(cache_dir, bodies) for _ in range(max(1, min(sizes.repeat, 3)))]
    warm = min(warm_runs, key=lambda r: r["import_s"] + r["first_step_s"])
    with tempfile.TemporaryDirectory(prefix="tumble-numba-cache-") as cache_dir:
        cold_simulate_first = _cold_start_process(cache_dir, bodies, "simulate first")
    return [
        _cold_start_row("cold", "step first", cold),
        _cold_start_row("warm", "step first", warm),
        _cold_start_row("cold", "simulate first", cold_simulate_first),
    ]


# --- targets -----------------------------------------------------------------------------------------


def _find(rows: list[dict], **match) -> dict | None:
    for r in rows:
        if all(r.get(k) == v for k, v in match.items()):
            return r
    return None


def check_targets(results: dict[str, list[dict]]) -> list[dict]:
    """The issue's targets, each with the measured value and whether it is met."""
    targets = []

    def add(name, value, limit, met):
        targets.append({"target": name, "value": value, "limit": limit, "met": "yes" if met else "NO"})

    tumbling = results.get("tumbling", [])
    sim = _find(tumbling, engine="tumble", integrator="auto", mode="simulate")
    if sim is not None:
        if "x_mujoco_rk4" in sim:
            add("simulate(auto) steps/s vs MuJoCo RK4 (x)", sim["x_mujoco_rk4"], ">= 2", sim["x_mujoco_rk4"] >= 2)
        add("simulate(auto) energy drift", sim["energy_drift"], "< 1e-9", sim["energy_drift"] < 1e-9)
        add("simulate(auto) |L| drift", sim["angmom_drift"], "< 1e-12", sim["angmom_drift"] < 1e-12)
    step = _find(tumbling, engine="tumble", integrator="auto", mode="step() loop")
    if step is not None:
        add("world.step(auto) us/call", step["us_per_step"], "< 10", step["us_per_step"] < 10)
    many = results.get("many_bodies", [])
    threads = max((r["threads"] for r in many if r["engine"] == "tumble"), default=None)
    for integrator in ("auto", "symplectic"):
        row = _find(many, engine="tumble", integrator=integrator, threads=threads)
        if row is not None and "x_mujoco" in row:
            label = f"{row['bodies']} bodies, {integrator}, {threads} threads vs MuJoCo Euler (x)"
            add(label, row["x_mujoco"], ">= 10", row["x_mujoco"] >= 10)
        one = _find(many, engine="tumble", integrator=integrator, threads=1)
        if row is not None and one is not None and threads > 1:
            gain = row["body_steps_per_s"] / one["body_steps_per_s"]
            add(f"{row['bodies']} bodies, {integrator}: {threads} threads over 1 (x)", gain, ">= 1.7", gain >= 1.7)
        scaling = sorted((r for r in many if r["config"] == "no contacts, scaling" and r["integrator"] == integrator),
                         key=lambda r: r["bodies"])  # fmt: skip
        if len(scaling) > 1:
            small, large = scaling[0], scaling[-1]
            growth = small["body_steps_per_s"] / large["body_steps_per_s"]
            label = f"{integrator}: time per body-step at {large['bodies']} bodies over {small['bodies']} (x)"
            add(label, growth, "<= 1.5 (flat)", growth <= 1.5)
    targets += _contact_targets(results)
    for row in results.get("cold_start", []):
        if row["order"] != "step first":
            continue
        limit = 1.5 if row["cache"] == "warm" else 20.0
        add(f"{row['cache']} start: import + first step (s)", row["import_plus_step_s"], f"< {limit:g}",
            row["import_plus_step_s"] < limit)  # fmt: skip
    for row in results.get("quadrotor", []):
        if row["engine"] == "tumble" and row["controller"].startswith("SE3") and math.isfinite(row["x_rotorpy"]):
            add(f"quadrotor {row['rate_hz']} Hz, SE3 every step: steps/s vs RotorPy (x)", row["x_rotorpy"], ">= 100",
                row["x_rotorpy"] >= 100)  # fmt: skip
    targets += _build_targets(results.get("build", []))
    for row in results.get("ensemble", []):
        if "efficiency" in row:
            add(f"ensemble of {row['members']} members, {row['executor']}: 1 worker's time over 2 x 2 workers'",
                row["efficiency"], ">= 0.8", row["efficiency"] >= 0.8)  # fmt: skip
    return targets


def _build_targets(rows: list[dict]) -> list[dict]:
    """Issue 20's: 100 000 bodies and 10 000 joints built in under 5 s each, a scene file within 2x of the API, and
    the cost per item growing no faster than linearly (the per-item time at the largest size within 1.5x of that at
    a tenth of it: garbage collection and cache misses grow a little, a quadratic build grows 10x)."""
    targets = []

    def add(name, value, limit, met):
        targets.append({"target": name, "value": value, "limit": limit, "met": "yes" if met else "NO"})

    for case, size_key, limit in (("free bodies", "bodies", 100_000), ("chain", "joints", 10_000),
                                  ("grid", "joints", 10_000)):  # fmt: skip
        api = sorted((r for r in rows if r["case"] == case and r["how"] == "API"), key=lambda r: r[size_key])
        if not api:
            continue
        largest = api[-1]
        if largest[size_key] >= 0.99 * limit:
            add(f"build {case}, {largest[size_key]} {size_key}, API (s)", largest["build_s"], "< 5",
                largest["build_s"] < 5)  # fmt: skip
        tenth = [r for r in api if 8 * r[size_key] <= largest[size_key] <= 12 * r[size_key]]
        if tenth:
            growth = largest["us_per_item"] / tenth[-1]["us_per_item"]
            add(f"build {case}: per-item time, {tenth[-1][size_key]} -> {largest[size_key]} {size_key} (x)", growth,
                "<= 1.5", growth <= 1.5)  # fmt: skip
        for row in rows:
            if row["case"] == case and row["how"] == "scene file":
                add(f"build {case}, {row[size_key]} {size_key}: scene file vs API (x)", row["x_api"], "<= 2",
                    row["x_api"] <= 2)  # fmt: skip
    return targets


def _contact_targets(results: dict[str, list[dict]]) -> list[dict]:
    """The contact issue's targets: tumble at 60 Hz against the peers at 240 Hz, on the pile and the pyramid."""
    targets = []

    def add(name, value, limit, met):
        targets.append({"target": name, "value": value, "limit": limit, "met": "yes" if met else "NO"})

    pile = _find(results.get("pile", []), engine="tumble", hz=60)
    if pile is not None:
        label = f"pile {pile['bodies']}, tumble 60 Hz"
        if "x_mujoco" in pile:
            add(f"{label}: real-time factor vs MuJoCo (x)", pile["x_mujoco"], ">= 2", pile["x_mujoco"] >= 2)
        if "x_pybullet" in pile:
            add(f"{label}: real-time factor vs PyBullet (x)", pile["x_pybullet"], ">= 5", pile["x_pybullet"] >= 5)
        add(f"{label}: max speed at the end (m/s)", pile["max_speed"], f"< {contact.SETTLED_SPEED:g} (settled)",
            pile["settled"])  # fmt: skip
        add(f"{label}: max penetration (mm)", pile["max_penetration_mm"], "< 5", pile["max_penetration_mm"] < 5)
        add(f"{label}: boxes below the ground", pile["below_ground"], "0", pile["below_ground"] == 0)
    pyramid = _find(results.get("pyramid", []), engine="tumble", hz=60)
    if pyramid is not None:
        label = f"pyramid {pyramid['bodies']}, tumble 60 Hz"
        add(f"{label}: top drift (mm)", pyramid["top_drift_mm"], "< 10", pyramid["top_drift_mm"] < 10)
        if "x_mujoco" in pyramid:
            add(f"{label}: real-time factor vs MuJoCo (x)", pyramid["x_mujoco"], ">= 2", pyramid["x_mujoco"] >= 2)
    return targets


# --- output ------------------------------------------------------------------------------------------


def _format_value(value) -> str:
    if isinstance(value, bool) or not isinstance(value, (float, np.floating)):
        return str(value)
    if not math.isfinite(value):
        return str(value)
    magnitude = abs(value)
    if magnitude == 0.0:
        return "0"
    if magnitude < 1e-3 or magnitude >= 1e9:
        return f"{value:.2e}"
    decimals = max(0, 3 - math.floor(math.log10(magnitude)))
    return f"{value:,.{decimals}f}"


def format_table(rows: list[dict]) -> str:
    """Rows as a plain-text table: columns in first-seen order, numbers right-aligned."""
    if not rows:
        return "(no rows)"
    columns = list(dict.fromkeys(k for r in rows for k in r))
    cells = [[_format_value(r[c]) if c in r else "-" for c in columns] for r in rows]
    widths = [max(len(c), *(len(row[i]) for row in cells)) for i, c in enumerate(columns)]
    numeric = [all(isinstance(r.get(c, 0), (int, float, np.number)) for r in rows) for c in columns]

    def line(values):
        cells = (v.rjust(w) if num else v.ljust(w) for v, w, num in zip(values, widths, numeric, strict=True))
        return "  ".join(cells).rstrip()

    return "\n".join([line(columns), line(["-" * w for w in widths]), *(line(row) for row in cells)])


def write_csv(path: Path, rows: list[dict]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    columns = list(dict.fromkeys(k for r in rows for k in r))
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=columns)
        writer.writeheader()
        for r in rows:
            writer.writerow({k: (repr(float(v)) if isinstance(v, (float, np.floating)) else v) for k, v in r.items()})


BENCHMARKS: dict[str, Callable[[Sizes], list[dict]]] = {
    "tumbling": bench_tumbling,
    "many_bodies": bench_many_bodies,
    "cold_start": bench_cold_start,
    "pile": contact.bench_pile,
    "contact_steps": contact_steps.bench_contact_steps,
    "pyramid": contact.bench_pyramid,
    "cubes": contact.bench_cubes,
    "big_pyramid": contact.bench_big_pyramid,
    "world_chain": joints.bench_world_chain,
    "articulation_chain": lambda sizes: articulation.bench_chain(
        articulation.FULL if sizes.repeat > 1 else articulation.QUICK
    ),
    "quadrotor": quadrotor.bench_quadrotor,
    "build": build.bench_build,
    "broad_phase": broad_phase.bench_broad_phase,
    "batch": lambda sizes: batch.bench_batch(batch.FULL if sizes.repeat > 1 else batch.QUICK),
    "envs": lambda sizes: envs.bench_envs(envs.FULL if sizes.repeat > 1 else envs.QUICK),
    "ensemble": lambda sizes: ensembles.bench_ensemble(ensembles.FULL if sizes.repeat > 1 else ensembles.QUICK),
    "first_run": first_run.bench_first_run,
    "model_files": lambda sizes: model_files.bench_model_files(
        chain_links=100 if sizes.repeat > 1 else 5, repeat=max(1, min(sizes.repeat, 5))
    ),
    "mjcf_contacts": lambda sizes: model_files.bench_mjcf_contacts(
        seconds=5.0 if sizes.repeat > 1 else 0.1, repeat=max(1, min(sizes.repeat, 3))
    ),
    "robots": lambda sizes: robots.bench_robots(
        seconds=5.0 if sizes.repeat > 1 else 0.05, repeat=max(1, min(sizes.repeat, 5))
    ),
}
OPTIONAL = ("big_pyramid", "first_run")  # slow: run only when asked for with --only


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.run", description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="tiny sizes, no cold start (a smoke test)")
    parser.add_argument("--only", choices=sorted(BENCHMARKS), action="append", help="run only this benchmark")
    parser.add_argument("--csv", nargs="?", const="benchmarks/results", metavar="DIR",
                        help="write DIR/<machine>/<name>.csv (DIR: benchmarks/results)")  # fmt: skip
    parser.add_argument("--repeat", type=int, help="timed repeats (best is kept)")
    parser.add_argument("--machine", help="name of the results folder (default: the host name, else 'local')")
    args = parser.parse_args(argv)

    sizes = QUICK if args.quick else FULL
    if args.repeat is not None:
        sizes = Sizes(**{**sizes.__dict__, "repeat": max(1, args.repeat)})
    names = args.only or [n for n in BENCHMARKS if n not in OPTIONAL and (sizes.cold_start or n != "cold_start")]

    info = machine_info()
    print("machine:", ", ".join(f"{k}={v}" for k, v in info.items()), flush=True)
    results: dict[str, list[dict]] = {}
    for name in names:
        print(f"\n== {name} ==", flush=True)
        elapsed, rows = _timed(BENCHMARKS[name], sizes)
        results[name] = rows
        print(format_table(rows))
        print(f"({elapsed:.1f} s)", flush=True)
    targets = check_targets(results)
    if targets:
        print("\n== targets ==")
        print(format_table(targets))

    if args.csv is not None:
        folder = Path(args.csv) / (args.machine or info["host"] or "local")
        for name, rows in results.items():
            write_csv(folder / f"{name}.csv", rows)
        if targets:
            write_csv(folder / "targets.csv", _merged_targets(folder / "targets.csv", targets))
        write_csv(folder / "machine.csv", [{"key": k, "value": v} for k, v in info.items()])
        print(f"\nwrote {folder}/")
    return 0


def _merged_targets(path: Path, targets: list[dict]) -> list[dict]:
    """The targets just checked, after those of earlier runs of other benchmarks (a run with ``--only`` keeps them)."""
    fresh = {t["target"] for t in targets}
    earlier = []
    if path.is_file():
        with path.open(newline="") as f:
            earlier = [row for row in csv.DictReader(f) if row["target"] not in fresh]
    return earlier + targets


if __name__ == "__main__":
    raise SystemExit(main())
