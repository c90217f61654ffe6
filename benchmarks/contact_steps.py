"""Contact worlds stepped from Python (issue 45): a ``world.step()`` loop against the same steps inside one
``simulate``, and MuJoCo's ``mj_step`` loop on the same box on a plane, in one process.

Run through ``python -m benchmarks.run --only contact_steps``.

The scenes, at 60 Hz (tumble's 8 substeps):

- a 1 m box resting on a plane (1 kg): the smallest contact world, where the cost of entering compiled code and the
  Python around it is all there is;
- ``tumble.scenes.box_pile(27)``, the 27-box pile of the shipped scenes.

Each mode starts from a fresh world stepped once (the model built, the kernels loaded), then times
``contact_step_calls`` steps (the pile: a tenth of them); the best of ``min(repeat, 5)`` runs is kept.
``x_simulate`` is the mode's time per step over that of the same steps inside one ``simulate``; ``x_mujoco`` over
``mujoco.mj_step`` called from Python on the box (the same 1/60 s step, MuJoCo's defaults otherwise).
"""

from __future__ import annotations

import time

import tumble
from tumble import scenes

__all__ = ["bench_contact_steps", "box_on_a_plane"]

DT = 1.0 / 60.0
_MJCF_BOX = f"""<mujoco><option timestep="{DT!r}"/><worldbody><geom type="plane" size="5 5 0.1"/>
<body pos="0 0 0.6"><freejoint/><geom type="box" size="0.5 0.5 0.5" mass="1"/></body></worldbody></mujoco>"""


def box_on_a_plane() -> tumble.World:
    world = tumble.World()
    world.add_static(tumble.Plane())
    world.add_body(tumble.Box((1.0, 1.0, 1.0)), mass=1.0, position=(0.0, 0.0, 0.6))
    return world


def _step_loop(world: tumble.World, steps: int) -> None:
    for _ in range(steps):
        world.step(DT)


def _inside_simulate(world: tumble.World, steps: int) -> None:
    world.simulate(steps * DT, DT, record_every=steps)


def _tumble_seconds_per_step(make, run, steps: int, repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        world = make()
        world.step(DT)
        start = time.perf_counter()
        run(world, steps)
        best = min(best, (time.perf_counter() - start) / steps)
    return best


def _mujoco_seconds_per_step(steps: int, repeat: int) -> float | None:
    try:
        import mujoco
    except ImportError:
        return None
    model = mujoco.MjModel.from_xml_string(_MJCF_BOX)
    best = float("inf")
    for _ in range(repeat):
        data = mujoco.MjData(model)
        mujoco.mj_step(model, data)
        start = time.perf_counter()
        for _ in range(steps):
            mujoco.mj_step(model, data)
        best = min(best, (time.perf_counter() - start) / steps)
    return best


def bench_contact_steps(sizes) -> list[dict]:
    """One row per scene and mode: ``us_per_step``, ``x_simulate``, ``x_mujoco`` (the box only)."""
    repeat = max(1, min(sizes.repeat, 5))
    rows = []
    mujoco_box = _mujoco_seconds_per_step(sizes.contact_step_calls, repeat)
    scenes_to_run = (("box on a plane", box_on_a_plane, sizes.contact_step_calls),
                     ("27-box pile", lambda: scenes.box_pile(27), max(1, sizes.contact_step_calls // 10)))  # fmt: skip
    for scene, make, steps in scenes_to_run:
        simulate = _tumble_seconds_per_step(make, _inside_simulate, steps, repeat)
        for mode, seconds in (("step() loop", _tumble_seconds_per_step(make, _step_loop, steps, repeat)),
                              ("simulate", simulate)):  # fmt: skip
            row = {"scene": scene, "engine": "tumble", "mode": mode, "hz": 60, "steps": steps,
                   "us_per_step": 1e6 * seconds, "x_simulate": seconds / simulate}  # fmt: skip
            if scene == "box on a plane" and mujoco_box is not None:
                row["x_mujoco"] = seconds / mujoco_box
            rows.append(row)
    if mujoco_box is not None:
        rows.append({"scene": "box on a plane", "engine": "MuJoCo", "mode": "mj_step loop", "hz": 60,
                     "steps": sizes.contact_step_calls, "us_per_step": 1e6 * mujoco_box, "x_mujoco": 1.0})  # fmt: skip
    return rows
