"""Many copies at once: ``tumble.Batch`` against ``mujoco.rollout`` with the same copies and threads (issue 28).

Run from the repository root:

    python -m benchmarks.batch [--quick] [--repeat N]
    python -m benchmarks.run --only batch

``tumbling``  4096 copies of one free body (I = diag(1, 2, 3) kg m², ω₀ = (0.01, 5, 0.01) rad/s, no gravity),
              1000 steps of 1 ms in one ``batch.step(dt, steps)`` call, like for like (issue 49): tumble's RK4
              beside MuJoCo's RK4, tumble's symplectic (semi-implicit) Euler beside MuJoCo's Euler (semi-implicit
              too), each in one rollout call; and tumble's default (``auto``: RK4 for this body).
``isotropic`` the same with I = diag(2, 2, 2) kg m²: tumble's default flies an isotropic body in closed form (the
              row the 9-33x figures of issue 28 came from), beside MuJoCo's RK4 and Euler.
``pile``      1024 copies of a pile of 10 cubes of 0.2 m (``scenes.box_pile(10)``) dropped on a plane, 1 s: tumble
              at 60 Hz (its default, 8 substeps), MuJoCo at 60 Hz (the same step) and 240 Hz (the contact
              benchmarks' rate, where its default soft contacts hold a pile), Newton solver.

Each engine runs on 1 and 2 threads (``tumble.dynamics.integrate.using_threads``; MuJoCo's rollout with one MjData
per thread). Rows give body-steps per second and simulated copy-seconds per wall second; the ratio columns divide
tumble's by MuJoCo's with the same threads (body-steps at the same step, simulated time against MuJoCo at 240 Hz
for the pile). Every timing is the best of ``--repeat`` runs (fewer once they pass 10 s) after a first, untimed
one (compile, cache load).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

import tumble
from tumble import scenes
from tumble.dynamics import integrate

from . import peers
from .timing import best_time, show_row, sizes_from_args

__all__ = ["bench_batch", "BatchSizes", "FULL", "QUICK"]

INERTIA = (1.0, 2.0, 3.0)
ISOTROPIC = (2.0, 2.0, 2.0)
OMEGA = (0.01, 5.0, 0.01)
# tumble's integrator beside the MuJoCo integrator it is like (the same order and kind of step)
LIKE = {"rk4": "RK4", "symplectic": "Euler"}


@dataclass(frozen=True)
class BatchSizes:
    tumbling_copies: int = 4096
    tumbling_steps: int = 1000
    pile_copies: int = 1024
    pile_boxes: int = 10
    pile_seconds: float = 1.0
    repeat: int = 3


FULL = BatchSizes()
QUICK = BatchSizes(tumbling_copies=8, tumbling_steps=20, pile_copies=4, pile_boxes=3, pile_seconds=0.05, repeat=1)


def _row(scene, engine, config, hz, threads, copies, bodies, steps, seconds) -> dict:
    return {
        "scene": scene, "engine": engine, "config": config, "hz": hz, "threads": threads, "copies": copies,
        "bodies": bodies, "steps": steps, "seconds": seconds,
        "body_steps_per_s": copies * bodies * steps / seconds, "sim_s_per_s": copies * steps / hz / seconds,
    }  # fmt: skip


def tumbling_world(inertia=INERTIA, integrator="auto") -> tumble.World:
    world = tumble.World(gravity=(0.0, 0.0, 0.0), integrator=integrator)
    mass = tumble.MassProperties(1.0, (0.0, 0.0, 0.0), np.diag(inertia))
    world.add_body(mass_properties=mass, angular_velocity=OMEGA)
    return world


def _tumble_rows(scene, world, copies, hz, steps, bodies, repeat, config=None) -> list[dict]:
    rows = []
    for threads in _thread_counts():
        batch = tumble.Batch(world, copies)

        def run(batch=batch):
            batch.reset()
            batch.step(1.0 / hz, steps=steps)

        with integrate.using_threads(threads):
            seconds = best_time(run, repeat)
        label = f"Batch, {len(batch._blocks)} block(s)" if config is None else config
        rows.append(_row(scene, "tumble", label, hz, threads, copies, bodies, steps, seconds))
    return rows


def _mujoco_rows(scene, xml, copies, hz, steps, bodies, repeat, config, prepare=None) -> list[dict]:
    import mujoco
    from mujoco import rollout

    model, data = peers.load(xml)
    if prepare is not None:
        prepare(model, data)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    initial = np.empty((1, mujoco.mj_stateSize(model, spec)))
    mujoco.mj_getState(model, data, initial[0], spec)
    initial = np.repeat(initial, copies, axis=0)
    out = np.empty((copies, steps, initial.shape[1]))
    rows = []
    for threads in _thread_counts():
        datas = [mujoco.MjData(model) for _ in range(threads)]

        def run(datas=datas):
            rollout.rollout(model, datas, initial, nstep=steps, state=out, persistent_pool=True)

        seconds = best_time(run, repeat)
        rows.append(_row(scene, "MuJoCo", config, hz, threads, copies, bodies, steps, seconds))
    return rows


def _thread_counts() -> list[int]:
    import os

    return [1, 2] if (os.cpu_count() or 1) >= 2 else [1]


def bench_tumbling(sizes: BatchSizes) -> list[dict]:
    """The anisotropic body with each of tumble's integrators like MuJoCo's and its default; the isotropic one with
    tumble's default (closed-form flight); MuJoCo's RK4 and Euler beside each."""
    hz, rows = 1000, []
    runs = [("tumbling", INERTIA, integrator) for integrator in (*LIKE, "auto")] + [("isotropic", ISOTROPIC, "auto")]
    for scene, inertia, integrator in runs:
        rows += _tumble_rows(scene, tumbling_world(inertia, integrator), sizes.tumbling_copies, hz,
                             sizes.tumbling_steps, 1, sizes.repeat, integrator)  # fmt: skip
    if peers.have_mujoco():

        def spin(model, data):
            peers.set_free_body_angvel(model, data, np.array([OMEGA]))

        for scene, inertia in (("tumbling", INERTIA), ("isotropic", ISOTROPIC)):
            for integrator in ("RK4", "Euler"):
                xml = peers.tumbling_body_mjcf(integrator, 1.0 / hz, 1.0, inertia)
                rows += _mujoco_rows(scene, xml, sizes.tumbling_copies, hz, sizes.tumbling_steps, 1, sizes.repeat,
                                     integrator, spin)  # fmt: skip
    return rows


def bench_pile(sizes: BatchSizes) -> list[dict]:
    world = scenes.box_pile(sizes.pile_boxes)
    model = world.model
    dynamic = np.flatnonzero(model.body_is_dynamic)
    bodies = [world.bodies[i] for i in dynamic]
    rows = _tumble_rows("pile", world, sizes.pile_copies, 60, round(60 * sizes.pile_seconds), len(bodies),
                        sizes.repeat)  # fmt: skip
    if peers.have_mujoco():
        half = np.array([model.shapes[np.flatnonzero(model.shape_body == i)[0]].half_extents for i in dynamic])
        for hz in (60, 240):
            xml = peers.boxes_on_plane_mjcf(np.array([b.position for b in bodies]),
                                            np.array([b.orientation for b in bodies]), half,
                                            model.body_mass[dynamic], timestep=1.0 / hz, friction=0.5)  # fmt: skip
            rows += _mujoco_rows("pile", xml, sizes.pile_copies, hz, round(hz * sizes.pile_seconds), len(bodies),
                                 sizes.repeat, "Newton")  # fmt: skip
    return rows


def with_ratios(rows: list[dict]) -> list[dict]:
    """Tumble's rows with ``x_<peer>`` columns: its rate over MuJoCo's with the same scene and threads, and
    ``x_like_for_like``: over the MuJoCo integrator its own is like (``LIKE``)."""
    for row in rows:
        if row["engine"] != "tumble":
            continue
        for peer in rows:
            if peer["engine"] == "MuJoCo" and peer["scene"] == row["scene"] and peer["threads"] == row["threads"]:
                if peer["hz"] == row["hz"]:
                    row[f"x_mujoco_{peer['config']}_steps"] = row["body_steps_per_s"] / peer["body_steps_per_s"]
                    if LIKE.get(row["config"]) == peer["config"]:
                        row["x_like_for_like"] = row["body_steps_per_s"] / peer["body_steps_per_s"]
                if row["scene"] == "pile" and peer["hz"] == 240:
                    row["x_mujoco_240hz_sim_time"] = row["sim_s_per_s"] / peer["sim_s_per_s"]
    return rows


def bench_batch(sizes: BatchSizes = FULL) -> list[dict]:
    return with_ratios(bench_tumbling(sizes) + bench_pile(sizes))


def main(argv: list[str] | None = None) -> int:
    for row in bench_batch(sizes_from_args(argv, "python -m benchmarks.batch", __doc__, FULL, QUICK)):
        show_row(row)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
