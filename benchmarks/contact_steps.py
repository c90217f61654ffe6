"""Worlds stepped from Python (issues 45 and 46): a ``world.step()`` loop against the same steps inside one
``simulate``, and against MuJoCo's ``mj_step`` loop called from Python on the same model, in one process.

Run through ``python -m benchmarks.run --only contact_steps``.

The scenes, at 60 Hz (tumble's 8 substeps where contacts are) unless said:

- one free body (a 0.3 × 0.2 × 0.1 m box of 1 kg, spinning, no ground): where the cost of entering compiled code and
  the Python around it is all there is;
- a 1 m box resting on a plane (1 kg): the smallest contact world;
- ``tumble.scenes.box_pile(27)``, the 27-box pile of the shipped scenes;
- Gymnasium's ant (``ant.xml`` of its MuJoCo assets, loaded by ``tumble.load_mjcf``) at its own timestep (0.01 s),
  its eight controls set every step (``world.ctrl``; MuJoCo's ``data.ctrl``) to a fixed pattern that changes sign
  with the step. Its ``simulate`` row holds the controls of the first step (``simulate`` takes no controls).

MuJoCo steps the same model: tumble's ``World.to_mjcf`` of the free body, the box and the pile, written at the same
timestep; the ant from its own file. Each mode starts from a fresh world stepped once (the model built, the kernels
loaded), then times ``contact_step_calls`` steps (the pile and the ant: a tenth of them); the best of
``min(repeat, 5)`` runs is kept. ``x_simulate`` is a row's time per step over that of the same scene's steps inside
one ``simulate``; ``x_mujoco`` over MuJoCo's ``mj_step`` loop on the scene.
"""

from __future__ import annotations

import os
import time
import warnings

import numpy as np

import tumble
from tumble import scenes

from .model_files import humanoid_path

__all__ = ["ant_path", "bench_contact_steps", "box_on_a_plane", "one_free_body"]

DT = 1.0 / 60.0


def one_free_body() -> tumble.World:
    world = tumble.World()
    world.add_body(tumble.Box((0.3, 0.2, 0.1)), mass=1.0, angular_velocity=(1.0, 2.0, 3.0))
    return world


def box_on_a_plane() -> tumble.World:
    world = tumble.World()
    world.add_static(tumble.Plane())
    world.add_body(tumble.Box((1.0, 1.0, 1.0)), mass=1.0, position=(0.0, 0.0, 0.6))
    return world


def ant_path() -> str | None:
    """Gymnasium's ant.xml, or None without Gymnasium."""
    path = humanoid_path()
    return None if path is None else os.path.join(os.path.dirname(path), "ant.xml")


def _ant() -> tumble.World:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the reader's notes on what a World does not simulate
        return tumble.load_mjcf(ant_path())


_ANT_DT = 0.01
_ANT_CTRL = np.sin(np.arange(8) * 1.7)


def _ant_ctrl(step: int) -> np.ndarray:
    """The ant's controls at ``step``: a fixed pattern, its sign flipped every step (a new command each step)."""
    return _ANT_CTRL if step % 2 == 0 else -_ANT_CTRL


def _step_loop(world: tumble.World, steps: int, dt: float, ctrl) -> None:
    if ctrl is None:
        for _ in range(steps):
            world.step(dt)
    else:
        for step in range(steps):
            world.ctrl = ctrl(step)
            world.step(dt)


def _inside_simulate(world: tumble.World, steps: int, dt: float, ctrl) -> None:
    if ctrl is not None:
        world.ctrl = ctrl(0)
    world.simulate(steps * dt, dt, record_every=steps)


def _tumble_seconds_per_step(make, run, steps: int, dt: float, ctrl, repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        world = make()
        world.step(dt)
        start = time.perf_counter()
        run(world, steps, dt, ctrl)
        best = min(best, (time.perf_counter() - start) / steps)
    return best


def _mujoco_seconds_per_step(model_xml, steps: int, ctrl, repeat: int) -> float | None:
    """``model_xml()``: the MJCF text, or None (no model: no row)."""
    try:
        import mujoco
    except ImportError:
        return None
    xml = model_xml()
    if xml is None:
        return None
    model = mujoco.MjModel.from_xml_string(xml)
    best = float("inf")
    for _ in range(repeat):
        data = mujoco.MjData(model)
        if model.nkey:
            mujoco.mj_resetDataKeyframe(model, data, 0)
        mujoco.mj_step(model, data)
        start = time.perf_counter()
        if ctrl is None:
            for _ in range(steps):
                mujoco.mj_step(model, data)
        else:
            for step in range(steps):
                data.ctrl[:] = ctrl(step)
                mujoco.mj_step(model, data)
        best = min(best, (time.perf_counter() - start) / steps)
    return best


def _exported(make):
    """The MJCF text of the world ``make()`` builds, at the benchmark's timestep."""
    return lambda: make().to_mjcf(timestep=DT)


def _ant_xml() -> str | None:
    path = ant_path()
    if path is None or not os.path.exists(path):
        return None
    with open(path, encoding="utf-8") as file:
        return file.read()


def bench_contact_steps(sizes) -> list[dict]:
    """One row per scene and mode: ``us_per_step``, ``x_simulate``, ``x_mujoco`` (where MuJoCo is installed)."""
    repeat = max(1, min(sizes.repeat, 5))
    calls, tenth = sizes.contact_step_calls, max(1, sizes.contact_step_calls // 10)
    scenes_to_run = [
        ("one free body", one_free_body, calls, DT, None, _exported(one_free_body)),
        ("box on a plane", box_on_a_plane, calls, DT, None, _exported(box_on_a_plane)),
        ("27-box pile", lambda: scenes.box_pile(27), tenth, DT, None, _exported(lambda: scenes.box_pile(27))),
    ]
    if _ant_xml() is not None:
        scenes_to_run.append(("ant, ctrl set every step", _ant, tenth, _ANT_DT, _ant_ctrl, _ant_xml))
    rows = []
    for scene, make, steps, dt, ctrl, xml in scenes_to_run:
        mujoco = _mujoco_seconds_per_step(xml, steps, ctrl, repeat)
        simulate = _tumble_seconds_per_step(make, _inside_simulate, steps, dt, ctrl, repeat)
        loop = _tumble_seconds_per_step(make, _step_loop, steps, dt, ctrl, repeat)
        for mode, seconds in (("step() loop", loop), ("simulate", simulate)):
            row = {"scene": scene, "engine": "tumble", "mode": mode, "hz": round(1.0 / dt), "steps": steps,
                   "us_per_step": 1e6 * seconds, "x_simulate": seconds / simulate}  # fmt: skip
            if mujoco is not None:
                row["x_mujoco"] = seconds / mujoco
            rows.append(row)
        if mujoco is not None:
            rows.append({"scene": scene, "engine": "MuJoCo", "mode": "mj_step loop", "hz": round(1.0 / dt),
                         "steps": steps, "us_per_step": 1e6 * mujoco, "x_mujoco": 1.0})  # fmt: skip
    return rows
