"""MuJoCo models of the benchmark scenes, as MJCF strings built in Python, plus helpers to read them back.

The same builders serve the benchmarks and the peer tests (``tests/peers``). ``mujoco`` is imported only
by the functions that need it, so this module imports without it.

Frames: for a free joint MuJoCo stores ``qpos = (x, y, z, qw, qx, qy, qz)`` (position of the body frame,
orientation body to world) and ``qvel = (v, ω)`` with ``v`` the world-frame linear velocity and ``ω`` the
angular velocity in the BODY (local) frame. At the identity orientation local and world coincide.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "angular_momentum_world",
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
