"""Articulation benchmark: a 20-link pendulum chain, tumble against MuJoCo in the same process (issue 4).

Run from the repository root:

    python -m benchmarks.articulation [--quick] [--repeat N] [--links N] [--seconds S]

The chain: ``--links`` (20) capsules of radius 1 cm and 0.1 m between hinges (the capsules' cylinders are 0.1 m
long, their axes along the links), 0.1 kg each, hinged about the horizontal y axis, released from rest lying
horizontal along +x, base at z = 2 m; no contacts, no damping. tumble builds it and MuJoCo gets the same model
as an MJCF string: capsule geoms (contacts disabled) with explicit ``inertial`` elements carrying tumble's
masses and inertias, so both integrate the same equations. Both run ``--seconds`` (10 s) at dt = 1 ms.

Rows: tumble ``symplectic`` and ``rk4``, each as ``step()`` in a Python loop and as one ``simulate`` call (the
step loop inside the kernel); MuJoCo ``Euler`` and ``RK4``, each as ``mj_step`` in a Python loop and as one
``mujoco.rollout`` call (its C loop, the match for ``simulate``). Columns: ``steps_per_s`` and ``us_per_step``
(best of ``--repeat`` timed runs), ``first_call_ms`` (the first call, apart: JIT compile or Numba cache load),
``energy_drift`` = max |E - E0| / |E0| over the run, from states recorded every :data:`RECORD_EVERY` steps
(tumble's energies for tumble, MuJoCo's ``mj_energyPos``/``mj_energyVel`` for MuJoCo); ``energy_drift_2s`` the
same over the first 2 s only; and ``x_mujoco_rk4``, steps/s over that of the faster MuJoCo RK4 row. The chain
released horizontal is chaotic: both engines' RK4 (the same scheme) agree to 1e-10 rad for 2 s, then round-off
grows into different motions, and the drift over 10 s depends on which whip-cracks each motion meets. The
2 s column compares like with like. The potential energy is zero at z = 0, 2 m below the base: the
lowest any point of the chain can reach, so E0 = 39.24 J (all potential) and E stays positive.
"""

from __future__ import annotations

import argparse
import math
import time
from dataclasses import dataclass, replace

import numpy as np

from tumble.articulation import Articulation, Revolute
from tumble.shapes import Capsule

__all__ = ["FULL", "QUICK", "ChainSizes", "bench_chain", "chain_articulation", "chain_mjcf", "main"]

RADIUS = 0.01  # [m]
SPACING = 0.1  # [m] between hinges: the capsule's cylinder length
MASS = 0.1  # [kg]
HEIGHT = 2.0  # [m] of the base above the potential zero
DT = 1e-3
RECORD_EVERY = 10  # energy samples every 10 ms: the drift's maximum over a run of 10 000 steps
SAME_UNTIL = 2.0  # [s]: the engines' RK4 trajectories agree to 1e-10 rad until then; chaos separates them after
ALONG_X = (math.cos(math.pi / 4), 0.0, math.sin(math.pi / 4), 0.0)  # a capsule's z axis turned onto +x


@dataclass(frozen=True)
class ChainSizes:
    """How big the benchmark is: :data:`FULL` for the report, :data:`QUICK` for the smoke test."""

    links: int = 20
    seconds: float = 10.0
    repeat: int = 3


FULL = ChainSizes()
QUICK = ChainSizes(links=5, seconds=0.05, repeat=1)


def chain_articulation(links: int) -> Articulation:
    """The benchmark chain in tumble, at rest, lying along +x from the base."""
    art = Articulation(gravity=(0.0, 0.0, -9.81), base_position=(0.0, 0.0, HEIGHT), name=f"chain{links}")
    capsule = Capsule(RADIUS, SPACING)
    parent = None
    for i in range(links):
        parent = art.add_link(Revolute((0.0, 1.0, 0.0)), parent=parent, position=(0.0 if i == 0 else SPACING, 0.0, 0.0),
                              shape=capsule, mass=MASS, shape_position=(SPACING / 2, 0.0, 0.0),
                              shape_orientation=ALONG_X)  # fmt: skip
    return art


def _vec(values) -> str:
    return " ".join(repr(float(v)) for v in values)


def chain_mjcf(art: Articulation, integrator: str, dt: float = DT) -> str:
    """The same chain for MuJoCo: nested bodies, hinge about y, capsule geoms, tumble's inertias."""
    bodies, closing = [], []
    for link in art.links:
        mp = link.mass_properties
        full = (
            mp.inertia[0, 0],
            mp.inertia[1, 1],
            mp.inertia[2, 2],
            mp.inertia[0, 1],
            mp.inertia[0, 2],
            mp.inertia[1, 2],
        )
        bodies.append(
            f'<body pos="{_vec(link.position)}"><joint type="hinge" axis="0 1 0"/>'
            f'<geom type="capsule" fromto="0 0 0 {SPACING!r} 0 0" size="{RADIUS!r}" contype="0" conaffinity="0"/>'
            f'<inertial pos="{_vec(mp.com)}" mass="{mp.mass!r}" fullinertia="{_vec(full)}"/>'
        )
        closing.append("</body>")
    return (
        f'<mujoco><option timestep="{dt!r}" gravity="0 0 -9.81" integrator="{integrator}">'
        '<flag contact="disable" energy="enable"/></option>'
        f'<worldbody><body pos="0 0 {HEIGHT!r}">{"".join(bodies)}{"".join(closing)}</body></worldbody></mujoco>'
    )


def _row(engine, integrator, mode, steps, seconds, first, energy) -> dict:
    return {
        "engine": engine,
        "integrator": integrator,
        "mode": mode,
        "steps": steps,
        "steps_per_s": steps / seconds,
        "us_per_step": 1e6 * seconds / steps,
        "first_call_ms": 1e3 * first,
        "energy_drift": _drift(energy),
        "energy_drift_2s": _drift(energy[: round(SAME_UNTIL / (DT * RECORD_EVERY)) + 1]),
    }


def _drift(energy) -> float:
    energy = np.asarray(energy)
    return float(np.max(np.abs(energy - energy[0])) / abs(energy[0]))


# --- tumble ------------------------------------------------------------------------------------------


def _tumble_simulate(integrator: str, sizes: ChainSizes) -> dict:
    steps = round(sizes.seconds / DT)
    start = time.perf_counter()
    chain_articulation(sizes.links).simulate(DT, DT, integrator=integrator)
    first = time.perf_counter() - start
    best, trajectory = math.inf, None
    for _ in range(sizes.repeat):
        art = chain_articulation(sizes.links)
        start = time.perf_counter()
        trajectory = art.simulate(steps * DT, DT, integrator=integrator, record_every=RECORD_EVERY)
        best = min(best, time.perf_counter() - start)
    return _row("tumble", integrator, "simulate", steps, best, first, trajectory.energy)


def _tumble_step_loop(integrator: str, sizes: ChainSizes) -> dict:
    steps = round(sizes.seconds / DT)
    start = time.perf_counter()
    chain_articulation(sizes.links).step(DT, integrator=integrator)
    first = time.perf_counter() - start
    best, energy = math.inf, []
    for _ in range(sizes.repeat):
        art = chain_articulation(sizes.links)
        step = art.step
        energy, elapsed = [art.energy()], 0.0
        for done in range(0, steps, RECORD_EVERY):
            n = min(RECORD_EVERY, steps - done)
            start = time.perf_counter()
            for _ in range(n):
                step(DT, integrator=integrator)
            elapsed += time.perf_counter() - start
            energy.append(art.energy())
        best = min(best, elapsed)
    return _row("tumble", integrator, "step() loop", steps, best, first, energy)


# --- MuJoCo ------------------------------------------------------------------------------------------


def _mujoco_energy(model, data) -> float:
    import mujoco

    mujoco.mj_forward(model, data)  # with the energy flag on, this fills data.energy (potential, kinetic)
    return float(data.energy[0] + data.energy[1])


def _mujoco_chain(integrator: str, sizes: ChainSizes):
    """The chain in MuJoCo twice: ``(model, data)`` with energy off for timing (MuJoCo would compute it every
    step), and ``(meter, probe)`` with it on to measure the energy of a copied state."""
    import mujoco

    xml = chain_mjcf(chain_articulation(sizes.links), integrator)
    model, meter = mujoco.MjModel.from_xml_string(xml), mujoco.MjModel.from_xml_string(xml)
    model.opt.enableflags &= ~int(mujoco.mjtEnableBit.mjENBL_ENERGY)
    return model, mujoco.MjData(model), meter, mujoco.MjData(meter)


def _mujoco_step_loop(integrator: str, sizes: ChainSizes) -> dict:
    import mujoco

    steps = round(sizes.seconds / DT)
    model, data, meter, probe = _mujoco_chain(integrator, sizes)
    start = time.perf_counter()
    mujoco.mj_step(model, data)
    first = time.perf_counter() - start
    best, energy = math.inf, []
    for _ in range(sizes.repeat):
        mujoco.mj_resetData(model, data)
        energy, elapsed = [], 0.0
        for done in range(0, steps + 1, RECORD_EVERY):
            probe.qpos[:], probe.qvel[:] = data.qpos, data.qvel
            energy.append(_mujoco_energy(meter, probe))
            n = min(RECORD_EVERY, steps - done)
            start = time.perf_counter()
            for _ in range(n):
                mujoco.mj_step(model, data)
            elapsed += time.perf_counter() - start
        best = min(best, elapsed)
    return _row("MuJoCo", integrator, "mj_step loop", steps, best, first, energy)


def _mujoco_rollout(integrator: str, sizes: ChainSizes) -> dict | None:
    import mujoco

    try:
        from mujoco import rollout
    except ImportError:
        return None
    steps = round(sizes.seconds / DT)
    model, data, meter, probe = _mujoco_chain(integrator, sizes)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    initial = np.empty((1, mujoco.mj_stateSize(model, spec)))
    mujoco.mj_getState(model, data, initial[0], spec)
    out = np.empty((1, steps, initial.shape[1]))
    start = time.perf_counter()
    rollout.rollout(model, data, initial, nstep=1)
    first = time.perf_counter() - start
    best = math.inf
    for _ in range(sizes.repeat):
        start = time.perf_counter()
        rollout.rollout(model, data, initial, nstep=steps, state=out)
        best = min(best, time.perf_counter() - start)
    energy = []
    for row in [initial[0], *out[0, RECORD_EVERY - 1 :: RECORD_EVERY]]:  # row k: the state after k + 1 steps
        mujoco.mj_setState(meter, probe, row, spec)
        energy.append(_mujoco_energy(meter, probe))
    return _row("MuJoCo", integrator, "rollout", steps, best, first, energy)


def _have_mujoco() -> bool:
    try:
        import mujoco  # noqa: F401
    except ImportError:
        return False
    return True


def bench_chain(sizes: ChainSizes = FULL) -> list[dict]:
    """Every row of the benchmark (see the module docstring)."""
    rows = []
    for integrator in ("symplectic", "rk4"):
        rows.append(_tumble_simulate(integrator, sizes))
        rows.append(_tumble_step_loop(integrator, sizes))
    if _have_mujoco():
        for integrator in ("Euler", "RK4"):
            row = _mujoco_rollout(integrator, sizes)
            rows += [row] if row is not None else []
            rows.append(_mujoco_step_loop(integrator, sizes))
        reference = max(r["steps_per_s"] for r in rows if r["engine"] == "MuJoCo" and r["integrator"] == "RK4")
        for r in rows:
            r["x_mujoco_rk4"] = r["steps_per_s"] / reference
    return rows


def _format(value) -> str:
    if isinstance(value, float):
        return f"{value:.3g}" if abs(value) < 1e-2 or abs(value) >= 1e5 else f"{value:.4g}"
    return str(value)


def format_table(rows: list[dict]) -> str:
    """Rows as a plain-text table, numbers right-aligned."""
    columns = list(dict.fromkeys(k for r in rows for k in r))
    cells = [[_format(r.get(c, "-")) for c in columns] for r in rows]
    widths = [max(len(c), *(len(row[i]) for row in cells)) for i, c in enumerate(columns)]
    numeric = [all(isinstance(r.get(c, 0), (int, float)) for r in rows) for c in columns]

    def line(values):
        return "  ".join(v.rjust(w) if num else v.ljust(w) for v, w, num in zip(values, widths, numeric, strict=True))

    return "\n".join([line(columns), line(["-" * w for w in widths]), *(line(row) for row in cells)])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.articulation", description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="a 5-link chain for 50 ms (a smoke test)")
    parser.add_argument("--repeat", type=int, help="timed repeats (the best is kept)")
    parser.add_argument("--links", type=int, help="links in the chain")
    parser.add_argument("--seconds", type=float, help="simulated time")
    args = parser.parse_args(argv)
    sizes = QUICK if args.quick else FULL
    changes = {"repeat": args.repeat, "links": args.links, "seconds": args.seconds}
    sizes = replace(sizes, **{k: v for k, v in changes.items() if v is not None})
    print(f"{sizes.links}-link chain, {sizes.seconds} s at dt = {DT} s, best of {sizes.repeat}", flush=True)
    print(format_table(bench_chain(sizes)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
