"""MuJoCo models of the benchmark scenes, as MJCF strings built in Python, plus helpers to read them back.

The same builders serve the benchmarks and the peer tests (``tests/peers``). ``mujoco`` is imported only
by the functions that need it, so this module imports without it.

Frames: for a free joint MuJoCo stores ``qpos = (x, y, z, qw, qx, qy, qz)`` (position of the body frame,
orientation body to world) and ``qvel = (v, ω)`` with ``v`` the world-frame linear velocity and ``ω`` the
angular velocity in the BODY (local) frame. At the identity orientation local and world coincide.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

__all__ = [
    "EngineRun",
    "angular_momentum_world",
    "box_vertices_min_z",
    "boxes_on_plane_mjcf",
    "have_pybullet",
    "mujoco_max_penetration",
    "pybullet_boxes_on_plane",
    "pybullet_max_penetration",
    "pybullet_state",
    "free_bodies_mjcf",
    "free_body_arrays",
    "grid_positions",
    "have_mujoco",
    "load",
    "random_angular_velocities",
    "rotational_energy",
    "set_free_body_angvel",
    "tumbling_body_mjcf",
]

MUJOCO_INTEGRATORS = ("Euler", "RK4", "implicit", "implicitfast")


@dataclass
class EngineRun:
    """A scene built in one engine and configuration: ``step()`` advances one step of ``1 / hz``. Each
    benchmark adds how it reads the scene back."""

    engine: str
    config: str
    hz: int
    threads: int
    build_s: float
    step: Callable[[], None]

    def timing(self, done: int, first: float, elapsed: float) -> dict:
        """The columns every benchmark row shares: ``done`` steps taken, the ``first`` one timed apart [s], and
        ``elapsed`` [s] for the other ``done - 1``."""
        timed = done - 1
        rate = timed / elapsed if timed > 0 else math.nan
        return {
            "engine": self.engine,
            "hz": self.hz,
            "config": self.config,
            "threads": self.threads,
            "sim_s": done / self.hz,
            "steps": done,
            "build_s": self.build_s,
            "first_step_s": first,
            "steps_per_s": rate,
            "ms_per_step": 1e3 / rate if timed > 0 else math.nan,
            "realtime_x": rate / self.hz,
        }


def have_mujoco() -> bool:
    try:
        import mujoco  # noqa: F401
    except ImportError:
        return False
    return True


def _check_integrator(integrator: str) -> str:
    if integrator not in MUJOCO_INTEGRATORS:
        raise ValueError(f"integrator must be one of {MUJOCO_INTEGRATORS}, got {integrator!r}")
    return integrator


def _vec(values) -> str:
    return " ".join(repr(float(v)) for v in values)


def _option(integrator: str, timestep: float, gravity) -> str:
    integrator = _check_integrator(integrator)
    return f"timestep='{float(timestep)!r}' gravity='{_vec(gravity)}' integrator='{integrator}'"


def tumbling_body_mjcf(
    integrator: str = "RK4",
    timestep: float = 1e-3,
    mass: float = 1.0,
    inertia=(1.0, 2.0, 3.0),
    gravity=(0.0, 0.0, 0.0),
) -> str:
    """One free body with principal moments ``inertia`` at its COM, no geometry (so nothing collides)."""
    option = _option(integrator, timestep, gravity)
    return (
        "<mujoco model='tumbling_body'>"
        f"<option {option}/>"
        "<worldbody><body name='body'><freejoint/>"
        f"<inertial pos='0 0 0' mass='{float(mass)!r}' diaginertia='{_vec(inertia)}'/>"
        "</body></worldbody></mujoco>"
    )


def grid_positions(n: int, spacing: float = 0.2, height: float = 10.0) -> np.ndarray:
    """(n, 3) positions on a square grid in the plane ``z = height``, row by row."""
    side = max(1, int(np.ceil(np.sqrt(n))))
    i = np.arange(n)
    return np.column_stack([(i % side) * spacing, (i // side) * spacing, np.full(n, float(height))])


def random_angular_velocities(n: int, seed: int = 0, scale: float = 5.0) -> np.ndarray:
    """(n, 3) [rad/s], normal with standard deviation ``scale``; the same for every engine given ``seed``."""
    return np.random.default_rng(seed).normal(scale=scale, size=(n, 3))


def free_bodies_mjcf(
    positions,
    radius: float = 0.05,
    mass: float = 1.0,
    integrator: str = "Euler",
    timestep: float = 1e-3,
    gravity=(0.0, 0.0, -9.81),
    disable_contact: bool = False,
) -> str:
    """``len(positions)`` free bodies, each one sphere geom with ``contype=0 conaffinity=0`` (no collisions).

    MuJoCo sizes its default arena from the body count and runs out (or asks for gigabytes) past a
    couple of thousand bodies; the collision stage alone wants ``2 n²`` bytes for its pair matrix, so
    the arena is set explicitly. ``disable_contact`` also switches the collision stage off altogether.
    """
    positions = np.asarray(positions, dtype=float).reshape(-1, 3)
    n = positions.shape[0]
    memory_mb = (2 * n * n) // 2**20 + 16
    flag = "<flag contact='disable'/>" if disable_contact else ""
    geom = f"<geom type='sphere' size='{float(radius)!r}' mass='{float(mass)!r}' contype='0' conaffinity='0'/>"
    bodies = "".join(f"<body name='b{i}' pos='{_vec(p)}'><freejoint/>{geom}</body>" for i, p in enumerate(positions))
    return (
        "<mujoco model='free_bodies'>"
        f"<size memory='{memory_mb}M'/>"
        f"<option {_option(integrator, timestep, gravity)}>"
        f"{flag}</option>"
        f"<worldbody>{bodies}</worldbody></mujoco>"
    )


def load(xml: str):
    """``(model, data)`` from an MJCF string."""
    import mujoco

    model = mujoco.MjModel.from_xml_string(xml)
    return model, mujoco.MjData(model)


def _require_free_joints(model) -> None:
    if model.nq != 7 * model.njnt or model.nv != 6 * model.njnt:
        raise ValueError(f"expected free joints only, got nq={model.nq}, nv={model.nv}, njnt={model.njnt}")


def free_body_arrays(model, qpos, qvel):
    """``(quat (n, 4) [w, x, y, z], omega_body (n, 3))`` from ``qpos``/``qvel`` of a free-joints-only model."""
    _require_free_joints(model)
    q = np.asarray(qpos).reshape(-1, 7)
    v = np.asarray(qvel).reshape(-1, 6)
    return q[:, 3:7].copy(), v[:, 3:6].copy()


def set_free_body_angvel(model, data, omega_world) -> None:
    """Set every free body's angular velocity from world-frame values (MuJoCo stores them in the body frame)."""
    quat, _ = free_body_arrays(model, data.qpos, data.qvel)
    omega_world = np.asarray(omega_world, dtype=float).reshape(-1, 3)
    data.qvel.reshape(-1, 6)[:, 3:6] = _rotate(_conjugate(quat), omega_world)


def _conjugate(q: np.ndarray) -> np.ndarray:
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def _rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate ``v`` by unit quaternions ``q`` ([w, x, y, z]), broadcasting over leading axes."""
    w, u = q[..., :1], q[..., 1:]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def rotational_energy(inertia_diag, omega_body) -> np.ndarray:
    """½ ωᵀ I ω with principal moments ``inertia_diag`` and body-frame ``omega_body`` (..., 3)."""
    omega_body = np.asarray(omega_body, dtype=float)
    return 0.5 * np.sum(np.asarray(inertia_diag, dtype=float) * omega_body**2, axis=-1)


def angular_momentum_world(quat, inertia_diag, omega_body) -> np.ndarray:
    """``L = R (I ω_body)`` (..., 3), world frame, from body-frame spin and orientation ``quat``."""
    omega_body = np.asarray(omega_body, dtype=float)
    return _rotate(np.asarray(quat, dtype=float), np.asarray(inertia_diag, dtype=float) * omega_body)


# --- contact scenes: boxes on a ground plane (MuJoCo and PyBullet) ----------------------------------------


def have_pybullet() -> bool:
    try:
        import pybullet  # noqa: F401
    except ImportError:
        return False
    return True


def _boxes(positions, quats, half_extents, masses):
    positions = np.asarray(positions, dtype=float).reshape(-1, 3)
    n = positions.shape[0]
    quats = np.asarray(quats, dtype=float).reshape(n, 4)
    half_extents = np.broadcast_to(np.asarray(half_extents, dtype=float), (n, 3))
    masses = np.broadcast_to(np.asarray(masses, dtype=float), (n,))
    return positions, quats, half_extents, masses


def boxes_on_plane_mjcf(
    positions,
    quats,
    half_extents,
    masses,
    timestep: float = 1 / 240,
    friction: float = 0.5,
    gravity=(0.0, 0.0, -9.81),
    solver: str = "Newton",
    memory_mb: int | None = None,
) -> str:
    """Free-joint boxes (solid, uniform: MuJoCo derives the inertia from ``mass``) over an infinite plane at z = 0.

    ``quats`` are ``[w, x, y, z]`` (MuJoCo's order, as tumble's). Every geom has sliding friction ``friction``
    (MuJoCo combines two geoms' frictions by their maximum, so a contact gets ``friction``); everything else
    is MuJoCo's default (pyramidal cones, soft contacts with solref 0.02, Euler integrator). The arena is
    sized from the box count (about 256 KiB a box: contacts, constraint rows and the Newton solver's factor)
    unless ``memory_mb`` is given.
    """
    positions, quats, half_extents, masses = _boxes(positions, quats, half_extents, masses)
    n = positions.shape[0]
    memory_mb = memory_mb if memory_mb is not None else 64 + n // 4
    material = f"friction='{float(friction)!r} 0.005 0.0001'"
    bodies = "".join(
        f"<body name='box{i}' pos='{_vec(p)}' quat='{_vec(q)}'><freejoint/>"
        f"<geom type='box' size='{_vec(h)}' mass='{float(m)!r}' {material}/></body>"
        for i, (p, q, h, m) in enumerate(zip(positions, quats, half_extents, masses, strict=True))
    )
    return (
        "<mujoco model='boxes_on_plane'>"
        f"<size memory='{int(memory_mb)}M'/>"
        f"<option timestep='{float(timestep)!r}' gravity='{_vec(gravity)}' solver='{solver}'/>"
        f"<worldbody><geom name='ground' type='plane' size='0 0 1' {material}/>{bodies}</worldbody>"
        "</mujoco>"
    )


def mujoco_max_penetration(data) -> float:
    """The deepest overlap among MuJoCo's active contacts [m] (``-min(dist)``, 0 when nothing overlaps)."""
    if data.ncon == 0:
        return 0.0
    return max(0.0, -float(np.min(data.contact.dist[: data.ncon])))


def pybullet_boxes_on_plane(
    positions,
    quats,
    half_extents,
    masses,
    timestep: float = 1 / 240,
    friction: float = 0.5,
    gravity=(0.0, 0.0, -9.81),
    maximal_coordinates: bool = False,
):
    """A PyBullet ``DIRECT`` client with a static plane at z = 0 and one box multibody per row.

    Returns ``(client, body_ids)``; disconnect with ``pybullet.disconnect(client)``. ``quats`` are
    ``[w, x, y, z]`` (converted to PyBullet's ``[x, y, z, w]``). Bullet multiplies the two bodies' lateral
    frictions, so each body gets ``sqrt(friction)`` and a contact gets ``friction``. Solver settings are
    PyBullet's defaults (50 iterations); ``maximal_coordinates`` makes plain rigid bodies instead of
    (reduced-coordinate) multibodies.
    """
    import pybullet as p

    positions, quats, half_extents, masses = _boxes(positions, quats, half_extents, masses)
    client = p.connect(p.DIRECT)
    try:
        p.setGravity(*(float(g) for g in gravity), physicsClientId=client)
        p.setTimeStep(float(timestep), physicsClientId=client)
        per_body = float(np.sqrt(friction))
        plane = p.createMultiBody(0.0, p.createCollisionShape(p.GEOM_PLANE, physicsClientId=client),
                                  physicsClientId=client)  # fmt: skip
        p.changeDynamics(plane, -1, lateralFriction=per_body, physicsClientId=client)
        shapes: dict[tuple[float, ...], int] = {}
        ids = []
        for position, q, half, mass in zip(positions, quats, half_extents, masses, strict=True):
            key = tuple(half.tolist())
            if key not in shapes:
                shapes[key] = p.createCollisionShape(p.GEOM_BOX, halfExtents=list(key), physicsClientId=client)
            body = p.createMultiBody(
                float(mass),
                shapes[key],
                basePosition=position.tolist(),
                baseOrientation=[q[1], q[2], q[3], q[0]],
                useMaximalCoordinates=maximal_coordinates,
                physicsClientId=client,
            )
            p.changeDynamics(body, -1, lateralFriction=per_body, physicsClientId=client)
            ids.append(body)
    except Exception:
        p.disconnect(client)
        raise
    return client, ids


def pybullet_state(client, body_ids) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(position (n, 3), quat (n, 4) [w, x, y, z], velocity (n, 3))`` of the bodies (COM = box centre)."""
    import pybullet as p

    positions, quats, velocities = [], [], []
    for body in body_ids:
        position, q = p.getBasePositionAndOrientation(body, physicsClientId=client)
        velocity, _ = p.getBaseVelocity(body, physicsClientId=client)
        positions.append(position)
        quats.append((q[3], q[0], q[1], q[2]))
        velocities.append(velocity)
    return np.array(positions), np.array(quats), np.array(velocities)


def pybullet_max_penetration(client) -> float:
    """The deepest overlap among PyBullet's contact points [m] (``-min(contactDistance)``, 0 when none overlap)."""
    import pybullet as p

    points = p.getContactPoints(physicsClientId=client)
    if not points:
        return 0.0
    return max(0.0, -min(point[8] for point in points))


def box_vertices_min_z(positions, quats, half_extents) -> np.ndarray:
    """(n,) the lowest z of each box's eight corners [m]: how far below a ground at z = 0 a box reaches."""
    positions, quats, half_extents, _ = _boxes(positions, quats, half_extents, 1.0)
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)
    corners = signs[None, :, :] * half_extents[:, None, :]  # (n, 8, 3), body frame
    world = _rotate(quats[:, None, :], corners) + positions[:, None, :]
    return world[..., 2].min(axis=1)
