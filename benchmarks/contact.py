"""Contact benchmarks: tumble, MuJoCo and PyBullet on the same scenes, in the same process.

Run through ``python -m benchmarks.run --only pile --only pyramid --only cubes [--only big_pyramid]``.

``pile``         ``tumble.scenes.box_pile(1000)``: 1000 cubes of 0.2 m (density 1000) in a jittered grid of columns,
                 dropped on a ground plane, 3 s.
``pyramid``      ``tumble.scenes.pyramid(20)``: 210 cubes of 0.5 m standing in a 2-D pyramid, 10 s; the drift of the
                 top cube says whether it stands.
``cubes``        box piles of 64 and 512 cubes, 3 s: how the cost grows with the count.
``big_pyramid``  ``pyramid(100)`` (5050 cubes), tumble only, 2 s: ms per step and top drift. Not in the default
                 run (slow); ask for it with ``--only big_pyramid``.

tumble builds every scene; MuJoCo (an MJCF string of free-joint boxes over a plane) and PyBullet (``DIRECT``,
one box multibody per cube, a plane) are built from the tumble world's initial poses, velocities and masses, so
all start identical. Friction 0.5 everywhere (tumble's default; Bullet multiplies the two bodies' frictions, so
each PyBullet body gets √0.5), no restitution. tumble runs at dt = 1/60 with its default substeps (its
recommended setting) and at dt = 1/240; MuJoCo (Newton solver, its defaults otherwise) and PyBullet (default
solver, 50 iterations) at dt = 1/240. PyBullet runs twice: as multibodies (its default) and with
``useMaximalCoordinates`` (plain rigid bodies, faster for free boxes). tumble keeps its default sleeping (bodies
at rest are not simulated); MuJoCo's is off by default.

Only the stepping loop is timed, one Python call per step for every engine (``world.step``, ``mujoco.mj_step``,
``pybullet.stepSimulation``), the first step apart (it includes tumble's JIT compile or its load from Numba's
cache). Each configuration runs once: these runs are long, and the outcome belongs to the run.

Columns: ``steps_per_s``; ``realtime_x`` simulated seconds per wall second; ``x_mujoco``/``x_pybullet`` that
over MuJoCo's / the faster PyBullet configuration's on the same scene; and the outcome at the end: ``max_speed``
[m/s] of any box, ``max_penetration_mm`` the engine's own deepest contact (tumble:
``-contacts().separation.min()``, MuJoCo: ``-contact.dist.min()``, PyBullet: ``-min(contactDistance)``),
``ground_penetration_mm`` the lowest box corner below z = 0 (the same formula for every engine), ``lowest_mm``
the lowest box centre relative to its resting height (half its edge), ``below_ground`` boxes whose centre is
under the plane, ``top_drift_mm`` (pyramids) how far the top cube moved, ``settled`` whether every box is slower
than :data:`SETTLED_SPEED`, ``contacts`` the engine's contact points at the end, ``sleeping`` tumble's sleeping
boxes.
"""

from __future__ import annotations

import functools
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numba
import numpy as np

import tumble
from tumble import scenes

from . import peers

__all__ = [
    "MUJOCO_HZ",
    "PYBULLET_HZ",
    "SETTLED_SPEED",
    "TUMBLE_HZ",
    "bench_big_pyramid",
    "bench_cubes",
    "bench_pile",
    "bench_pyramid",
]

TUMBLE_HZ = (60, 240)
MUJOCO_HZ = 240
PYBULLET_HZ = 240
SETTLED_SPEED = 0.1  # [m/s]: a pile whose fastest box is slower than this has come to rest
FRICTION = 0.5  # tumble's default, for every shape of the scenes


def _timed(function: Callable, *args, **kwargs) -> tuple[float, object]:
    start = time.perf_counter()
    result = function(*args, **kwargs)
    return time.perf_counter() - start, result


# --- scenes ------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Scene:
    """A tumble scene of boxes on a ground plane, and how long to run it."""

    name: str
    make: Callable[[], tumble.World]
    seconds: float
    track_top: bool = False  # report the drift of the body named "top"


@dataclass(frozen=True)
class _Boxes:
    """The dynamic boxes of a tumble world, in its body order: what the peers are built from."""

    index: np.ndarray  # (n,) body rows in the tumble world
    position: np.ndarray  # (n, 3) [m], box centre
    quat: np.ndarray  # (n, 4) [w, x, y, z]
    velocity: np.ndarray  # (n, 3) [m/s]
    angular_velocity: np.ndarray  # (n, 3) [rad/s], world frame
    half: np.ndarray  # (n, 3) [m], half extents
    mass: np.ndarray  # (n,) [kg]
    top: int | None  # position of the body named "top" in these rows


def _boxes(world: tumble.World) -> _Boxes:
    model = world.model
    dynamic = np.flatnonzero(model.body_is_dynamic)
    half = np.empty((dynamic.size, 3))
    for k, row in enumerate(dynamic):
        rows = np.flatnonzero(model.shape_body == row)
        shape = model.shapes[rows[0]] if rows.size == 1 else None
        centred = rows.size == 1 and not np.any(model.shape_pos_local[rows[0]])
        centred = centred and np.array_equal(np.abs(model.shape_quat_local[rows[0]]), [1.0, 0.0, 0.0, 0.0])
        if not (isinstance(shape, tumble.Box) and centred):
            raise ValueError(f"body {row}: the contact benchmarks take one centred box per dynamic body")
        half[k] = shape.half_extents
    bodies = world.bodies
    names = [bodies[i].name for i in dynamic]
    return _Boxes(
        index=dynamic,
        position=np.array([bodies[i].position for i in dynamic]),
        quat=np.array([bodies[i].orientation for i in dynamic]),
        velocity=np.array([bodies[i].velocity for i in dynamic]),
        angular_velocity=world.angular_velocities()[dynamic],
        half=half,
        mass=model.body_mass[dynamic].copy(),
        top=names.index("top") if "top" in names else None,
    )


# --- one engine in one configuration ------------------------------------------------------------------


@dataclass
class _Sim(peers.EngineRun):
    """A built scene: ``state()`` reads the boxes, ``penetration()`` the engine's deepest contact."""

    state: Callable[[], tuple[np.ndarray, np.ndarray, np.ndarray]]  # position, quat [w, x, y, z], velocity
    penetration: Callable[[], float]  # [m], the engine's deepest contact now
    extra: Callable[[], dict] = field(default=dict)
    close: Callable[[], None] = field(default=lambda: None)


def _tumble_sim(scene: _Scene, hz: int) -> _Sim:
    def build():
        world = scene.make()
        world.state  # noqa: B018  (build the model now)
        return world

    build_s, world = _timed(build)
    dynamic = np.flatnonzero(world.model.body_is_dynamic)
    bodies = [world.bodies[i] for i in dynamic]

    def state():
        return (
            np.array([b.position for b in bodies]),
            np.array([b.orientation for b in bodies]),
            np.array([b.velocity for b in bodies]),
        )

    def penetration():
        separation = world.contacts().separation
        return max(0.0, -float(separation.min())) if separation.size else 0.0

    def extra():
        return {"contacts": len(world.contacts()), "sleeping": int(world.state.body_sleeping[dynamic].sum())}

    config = f"substeps={world.solver.substeps}"
    return _Sim("tumble", config, hz, numba.get_num_threads(), build_s, functools.partial(world.step, 1.0 / hz),
                state, penetration, extra)  # fmt: skip


def _mujoco_sim(boxes: _Boxes, hz: int) -> _Sim:
    import mujoco

    xml = peers.boxes_on_plane_mjcf(boxes.position, boxes.quat, boxes.half, boxes.mass, timestep=1.0 / hz,
                                    friction=FRICTION)  # fmt: skip
    build_s, (model, data) = _timed(peers.load, xml)
    data.qvel.reshape(-1, 6)[:, :3] = boxes.velocity
    peers.set_free_body_angvel(model, data, boxes.angular_velocity)

    def state():
        q = data.qpos.reshape(-1, 7)
        return q[:, :3].copy(), q[:, 3:7].copy(), data.qvel.reshape(-1, 6)[:, :3].copy()

    def extra():
        warnings = {name: int(data.warning[int(w)].number) for name, w in mujoco.mjtWarning.__members__.items()
                    if name != "mjNWARNING"}  # fmt: skip
        found = ", ".join(f"{k.removeprefix('mjWARN_')}x{v}" for k, v in warnings.items() if v)
        return {"contacts": int(data.ncon), **({"notes": "MuJoCo warnings: " + found} if found else {})}

    solver = mujoco.mjtSolver(model.opt.solver).name.removeprefix("mjSOL_").capitalize()
    return _Sim("MuJoCo", solver, hz, 1, build_s, functools.partial(mujoco.mj_step, model, data), state,
                functools.partial(peers.mujoco_max_penetration, data), extra)  # fmt: skip


def _pybullet_sim(boxes: _Boxes, hz: int, maximal_coordinates: bool = False) -> _Sim:
    import pybullet as p

    build_s, (client, ids) = _timed(peers.pybullet_boxes_on_plane, boxes.position, boxes.quat, boxes.half,
                                    boxes.mass, timestep=1.0 / hz, friction=FRICTION,
                                    maximal_coordinates=maximal_coordinates)  # fmt: skip
    for body, v, w in zip(ids, boxes.velocity, boxes.angular_velocity, strict=True):
        p.resetBaseVelocity(body, linearVelocity=v.tolist(), angularVelocity=w.tolist(), physicsClientId=client)
    iterations = p.getPhysicsEngineParameters(physicsClientId=client)["numSolverIterations"]

    def extra():
        return {"contacts": len(p.getContactPoints(physicsClientId=client))}

    return _Sim(
        "PyBullet",
        f"{iterations} iterations" + (", maximal coords" if maximal_coordinates else ""),
        hz,
        1,
        build_s,
        functools.partial(p.stepSimulation, physicsClientId=client),
        functools.partial(peers.pybullet_state, client, ids),
        functools.partial(peers.pybullet_max_penetration, client),
        extra,
        functools.partial(p.disconnect, client),
    )


# --- measuring ---------------------------------------------------------------------------------------


def _measure(sim: _Sim, scene: _Scene, boxes: _Boxes) -> dict:
    steps = max(2, round(scene.seconds * sim.hz))
    pos0, _, _ = sim.state()
    notes = ""
    step = sim.step
    first, _ = _timed(step)
    start = time.perf_counter()
    done = 1
    try:
        for _ in range(steps - 1):
            step()
            done += 1
    except tumble.SimulationError as error:
        notes = f"failed at step {done + 1}: {error}"
    elapsed = time.perf_counter() - start
    try:
        pos, quat, vel = sim.state()
        penetration = sim.penetration()
        extra = sim.extra()
    finally:
        sim.close()
    notes = "; ".join(n for n in (notes, extra.pop("notes", "")) if n)
    if not (np.all(np.isfinite(pos)) and np.all(np.isfinite(vel))):
        notes = "; ".join(n for n in (notes, "non-finite state") if n)
    speed = np.linalg.norm(vel, axis=1)
    corners = peers.box_vertices_min_z(pos, quat, boxes.half)
    rest = boxes.half.min(axis=1)  # a cube rests with its centre half an edge up, whatever face is down
    row = {
        "scene": scene.name,
        "bodies": int(boxes.index.size),
        **sim.timing(done, first, elapsed),
        "max_speed": float(speed.max()),
        "settled": bool(speed.max() < SETTLED_SPEED),
        "max_penetration_mm": 1e3 * penetration,
        "ground_penetration_mm": 1e3 * max(0.0, -float(corners.min())),
        "lowest_mm": 1e3 * float(np.min(pos[:, 2] - rest)),
        "below_ground": int(np.sum(pos[:, 2] < 0.0)),
    }
    if scene.track_top and boxes.top is not None:
        row["top_drift_mm"] = 1e3 * float(np.linalg.norm(pos[boxes.top] - pos0[boxes.top]))
    row.update(extra)
    row["notes"] = notes
    return row


def _scene_rows(scene: _Scene, peers_too: bool = True, tumble_hz=TUMBLE_HZ) -> list[dict]:
    """Every engine and setting on ``scene``, with the ratios of real-time factors to the peers'."""
    boxes = _boxes(scene.make())
    rows = [_measure(_tumble_sim(scene, hz), scene, boxes) for hz in tumble_hz]
    if peers_too and peers.have_mujoco():
        rows.append(_measure(_mujoco_sim(boxes, MUJOCO_HZ), scene, boxes))
    if peers_too and peers.have_pybullet():
        rows += [_measure(_pybullet_sim(boxes, PYBULLET_HZ, maximal), scene, boxes) for maximal in (False, True)]
    for engine, column in (("MuJoCo", "x_mujoco"), ("PyBullet", "x_pybullet")):
        reference = max((r["realtime_x"] for r in rows if r["engine"] == engine), default=None)
        if reference:
            for r in rows:
                r[column] = r["realtime_x"] / reference
    # Keep the free-text column last.
    return [{**{k: v for k, v in r.items() if k != "notes"}, "notes": r["notes"]} for r in rows]


# --- the benchmarks ----------------------------------------------------------------------------------


def _pile(count: int, seconds: float, name: str) -> _Scene:
    return _Scene(name, functools.partial(scenes.box_pile, count), seconds)


def bench_pile(sizes) -> list[dict]:
    """``box_pile(sizes.pile_boxes)`` for ``sizes.pile_seconds``: every engine and setting."""
    return _scene_rows(_pile(sizes.pile_boxes, sizes.pile_seconds, "pile"))


def bench_cubes(sizes) -> list[dict]:
    """Box piles of each of ``sizes.cubes_boxes`` cubes for ``sizes.cubes_seconds``: how the cost scales."""
    return [row for count in sizes.cubes_boxes for row in _scene_rows(_pile(count, sizes.cubes_seconds, "cubes"))]


def bench_pyramid(sizes) -> list[dict]:
    """``pyramid(sizes.pyramid_base)`` for ``sizes.pyramid_seconds``: every engine and setting, top drift."""
    scene = _Scene("pyramid", functools.partial(scenes.pyramid, sizes.pyramid_base), sizes.pyramid_seconds, True)
    return _scene_rows(scene)


def bench_big_pyramid(sizes) -> list[dict]:
    """``pyramid(sizes.big_pyramid_base)`` (5050 cubes at base 100), tumble at 60 Hz only: ms/step, top drift."""
    base = sizes.big_pyramid_base
    scene = _Scene("big_pyramid", functools.partial(scenes.pyramid, base), sizes.big_pyramid_seconds, True)
    return _scene_rows(scene, peers_too=False, tumble_hz=(60,))
