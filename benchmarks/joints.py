"""World-joint benchmark (issue 4): a chain of hinges, tumble against PyBullet and MuJoCo in the same process.

Run through ``python -m benchmarks.run --only world_chain``.

The scene: ``links`` capsules (radius 1 cm, 10 cm long caps included, 0.1 kg each) end to end along +x, hinged
about y where they touch, the first to the world at (0, 0, 3); released at rest, horizontal; gravity −9.81 m/s²
along z, no ground, no contacts at all (every link's collisions are off in every engine, so a folding chain passes
through itself). The free end whips round at hundreds of rad/s: a hard case for joints solved in maximal
coordinates. 10 s.

tumble builds the chain (:func:`world_chain`: ``tumble.scenes.pendulum_chain``, whose links collide with nothing,
world ``HingeJoint``\\ s, maximal coordinates) and runs it at
dt = 1/60 with its default 8 substeps (its recommended setting) and at dt = 1/240. The peers are built from the
tumble bodies (masses, inertias, poses), so all start identical:

- PyBullet, maximal coordinates (``DIRECT``, plain rigid bodies): PyBullet's user constraints between maximal
  bodies offer no hinge (``JOINT_REVOLUTE`` fails; only point-to-point, fixed and gear work, and none to the
  world), so each hinge is the usual pair of ``JOINT_POINT2POINT`` constraints at ± :data:`PAIR_OFFSET` along the
  hinge axis, and the first joint holds a massless static anchor body at the pivot. A user constraint's
  ``maxForce`` (500 N by default) is raised to :data:`MAX_FORCE` so that it cannot bind (the default gives the
  same run, bit for bit).
  At 240 Hz (PyBullet's recommended rate) and at 60 Hz.
- PyBullet, one multibody (reduced coordinates, ``JOINT_REVOLUTE``: the joints are exact), for reference, at
  240 and 60 Hz. Its joints' default velocity motors are switched off and their 100 rad/s speed cap raised.
- MuJoCo: the same chain of hinges in generalised coordinates (exact joints), Euler (its default) and RK4 at
  240 Hz, and RK4 at 1000 Hz: at 240 Hz both blow up when the free end whips (joint speeds near 400 rad/s, 1.7 rad
  a step), and MuJoCo resets the state on its instability warnings, so such a run stops there (``sim_s``); RK4 at
  1000 Hz keeps the energy within 1 % over the 10 s, the reference for the exact motion.

Every engine runs with its default solver settings (PyBullet: 50 iterations), and no damping (PyBullet's bodies
and links are set to zero linear and angular damping, as tumble's and MuJoCo's).

Only the stepping loop is timed, one Python call per step (``world.step``, ``pybullet.stepSimulation``,
``mujoco.mj_step``), each step timed on its own, the first apart (``first_step_s``: it includes tumble's JIT
compile or its load from Numba's cache); between steps, outside the timer, the state is read and measured. The
configurations take turns, ``min(repeat, 5)`` rounds, each run on a fresh build, and each keeps its fastest run;
the engines are deterministic, so the outcome is the same every run.

The outcome is measured the same way for every engine, from each link's centre of mass ``c``, its orientation
``R`` in tumble's capsule frame (z along the link; at release, y is the hinge axis), its velocity ``v`` and its
world-frame angular velocity ``ω``:

- ``max_gap_mm``: the largest joint gap over the run, ``|c_k − (L/2) R_k z − (c_{k−1} + (L/2) R_{k−1} z)|`` (the
  pivot for the first link): how far the joint points of consecutive links are apart. ``end_gap_mm``: the
  largest at the end.
- ``max_axis_rad``: the largest angle between consecutive links' hinge axes ``R_k y`` (world y for the first).
  ``L`` is the distance between a link's two joints (10 cm), the joints ``L/2`` either side of its centre.
- ``energy_change``: ``(E_end − E_0) / ΔU``, with ``E = Σ ½ m |v|² + ½ ωᵀ R I Rᵀ ω − m g·c``, and ``ΔU`` the
  potential energy the chain releases from horizontal to hanging straight down, ``g Σ m_k (k + ½) L``
  (19.62 J for 20 links): 0 is exact conservation, −1 would be a chain that has lost all the energy it could
  gain. ``energy_max_dev``: the largest ``|E − E_0| / ΔU`` over the run.

Columns besides: ``steps_per_s``, ``ms_per_step``, ``realtime_x`` (simulated seconds per wall second),
``x_pybullet`` that over PyBullet's maximal-coordinate chain at 240 Hz, ``x_mujoco`` over MuJoCo's RK4 at
1000 Hz (the configuration that runs the scene through), ``notes`` where a run stopped or its energy went off by
more than ``ΔU`` (a gain no real chain can make).
"""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numba
import numpy as np

import tumble
from tumble import scenes

from . import peers

__all__ = [
    "LINKS",
    "MAX_FORCE",
    "MUJOCO_REFERENCE",
    "MUJOCO_RUNS",
    "PAIR_OFFSET",
    "PYBULLET_HZ",
    "TUMBLE_HZ",
    "Chain",
    "bench_world_chain",
    "chain_from_world",
    "chain_mjcf",
    "energy",
    "joint_errors",
    "world_chain",
]

LINKS = 20
RADIUS = 0.01  # [m]
LENGTH = 0.1  # [m], a capsule's length caps included, and the distance between its two joints
LINK_MASS = 0.1  # [kg]
PIVOT = (0.0, 0.0, 3.0)  # [m]
AXIS = (0.0, 1.0, 0.0)
TUMBLE_HZ = (60, 240)
PYBULLET_HZ = (240, 60)
MUJOCO_RUNS = (("Euler", 240), ("RK4", 240), ("RK4", 1000))
MUJOCO_REFERENCE = ("RK4", 1000)  # x_mujoco is against this one: it runs the whole scene, within 1 % in energy
PAIR_OFFSET = 0.05  # [m]: PyBullet's hinge is two point-to-point constraints this far either side along the axis
MAX_FORCE = 1e9  # [N]: PyBullet user constraints' force limit (500 N by default)
MAX_JOINT_SPEED = 1e4  # [rad/s]: PyBullet multibody joints' speed cap (100 rad/s by default)


def _timed(function: Callable, *args, **kwargs) -> tuple[float, object]:
    start = time.perf_counter()
    result = function(*args, **kwargs)
    return time.perf_counter() - start, result


# --- the scene ---------------------------------------------------------------------------------------


def world_chain(links: int = LINKS, **world_settings) -> tumble.World:
    """``tumble.scenes.pendulum_chain(links)``: capsules end to end along +x from ``PIVOT``, hinged about y, the
    first to the world, at rest; link ``k`` (``"link{k}"``) runs from ``k LENGTH`` to ``(k + 1) LENGTH`` from the
    pivot, caps included; the links collide with nothing (the scene's default)."""
    return scenes.pendulum_chain(links, length=LENGTH, mass=LINK_MASS, radius=RADIUS, **world_settings)


@dataclass(frozen=True)
class Chain:
    """The chain as the peers are built from it, read from the tumble bodies in link order."""

    mass: np.ndarray  # (n,) [kg]
    inertia: np.ndarray  # (n, 3, 3) [kg m²] about the centre of mass, in the capsule frame
    com: np.ndarray  # (n, 3) [m]
    rotation: np.ndarray  # (3, 3) every link's orientation at release, capsule frame to world
    pitch: float  # [m] between a link's two joints, centred on its centre of mass along its z axis
    radius: float  # [m], of the capsules
    segment: float  # [m], the capsules' length without the caps
    pivot: np.ndarray  # (3,) [m]
    axis: np.ndarray  # (3,) the hinges' axis at release, world frame
    gravity: np.ndarray  # (3,) [m/s²]

    @property
    def links(self) -> int:
        return int(self.mass.size)

    @property
    def potential_drop(self) -> float:
        """``ΔU`` [J]: from the straight chain at release to hanging straight down from the pivot."""
        depth = np.linalg.norm(self.com - self.pivot, axis=1)  # straight at release
        released = -self.mass @ ((self.com - self.pivot) @ self.gravity)
        return float(self.mass @ depth * np.linalg.norm(self.gravity) + released)


def chain_from_world(world: tumble.World, links: int) -> Chain:
    """The masses, inertias and poses of ``link0`` … ``link{links − 1}`` (straight and at rest at release)."""
    bodies = [world.body(f"link{k}") for k in range(links)]
    rotation = bodies[0].rotation
    model = world.model
    shapes = [model.shapes[np.flatnonzero(model.shape_body == b.index)[0]] for b in bodies]
    for body, shape in zip(bodies, shapes, strict=True):
        if not np.allclose(body.rotation, rotation, atol=1e-12) or np.any(body.velocity) or body.sleeping:
            raise ValueError("the chain must be released straight and at rest")
        if not (isinstance(shape, tumble.Capsule) and math.isclose(shape.radius, shapes[0].radius, rel_tol=1e-12)
                and math.isclose(shape.length, shapes[0].length, rel_tol=1e-12)):  # fmt: skip
            raise ValueError("the links must be equal capsules")
    com = np.array([b.center_of_mass for b in bodies])
    joint = world.joints[0]
    return Chain(
        mass=np.array([b.mass for b in bodies]),
        inertia=np.array([b.inertia_body for b in bodies]),
        com=com,
        rotation=rotation,
        pitch=2.0 * float(np.linalg.norm(com[0] - joint.anchor_b)),
        radius=shapes[0].radius,
        segment=shapes[0].length,
        pivot=np.array(joint.anchor_b),
        axis=np.array(AXIS, dtype=float),
        gravity=np.array(world.gravity, dtype=float),
    )


# --- measuring (the same for every engine) -------------------------------------------------------------


@dataclass(frozen=True)
class _Frame:
    """The links now: centre of mass, capsule frame (z along the link), velocities."""

    com: np.ndarray  # (n, 3)
    rotation: np.ndarray  # (n, 3, 3), capsule frame to world
    velocity: np.ndarray  # (n, 3), of the centre of mass
    omega: np.ndarray  # (n, 3), world frame


def _matrices(quat_wxyz: np.ndarray) -> np.ndarray:
    """(n, 3, 3) rotation matrices of unit quaternions ``[w, x, y, z]`` (n, 4)."""
    w, x, y, z = quat_wxyz.T
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=-1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=-1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=-1),
        ],
        axis=-2,
    )


def joint_errors(chain: Chain, frame: _Frame) -> tuple[np.ndarray, np.ndarray]:
    """``(gap (n,) [m], axis angle (n,) [rad])`` of each joint, from the links' poses."""
    half = 0.5 * chain.pitch * frame.rotation[:, :, 2]
    near, far = frame.com - half, frame.com + half
    gap = np.linalg.norm(near - np.vstack([chain.pivot, far[:-1]]), axis=1)
    axis = frame.rotation @ (chain.rotation.T @ chain.axis)  # each link's hinge axis, world frame
    previous = np.vstack([chain.axis, axis[:-1]])  # the world's hinge axis for the first joint
    angle = np.arctan2(np.linalg.norm(np.cross(previous, axis), axis=1), np.sum(previous * axis, axis=1))
    return gap, angle


def energy(chain: Chain, frame: _Frame) -> float:
    """``Σ ½ m |v|² + ½ ωᵀ R I Rᵀ ω − m g·(c − pivot)`` [J]."""
    spin = np.einsum("nji,nj->ni", frame.rotation, frame.omega)  # Rᵀ ω: body frame
    kinetic = 0.5 * chain.mass @ np.sum(frame.velocity**2, axis=1)
    kinetic += 0.5 * np.einsum("ni,nij,nj->", spin, chain.inertia, spin)
    return float(kinetic - chain.mass @ ((frame.com - chain.pivot) @ chain.gravity))


@dataclass
class _Outcome:
    chain: Chain
    e0: float
    max_gap: float = 0.0
    max_axis: float = 0.0
    max_dev: float = 0.0
    end_gap: float = math.nan
    energy_change: float = math.nan
    finite: bool = True
    frames: int = 0  # measured after the release
    diverged: int | None = None  # the first frame whose energy is off by more than the potential drop

    def add(self, frame: _Frame) -> None:
        if not all(np.all(np.isfinite(a)) for a in (frame.com, frame.rotation, frame.velocity, frame.omega)):
            self.finite = False
            return
        self.frames += 1
        gap, angle = joint_errors(self.chain, frame)
        self.max_gap, self.max_axis = max(self.max_gap, float(gap.max())), max(self.max_axis, float(angle.max()))
        self.end_gap = float(gap.max())
        self.energy_change = (energy(self.chain, frame) - self.e0) / self.chain.potential_drop
        self.max_dev = max(self.max_dev, abs(self.energy_change))
        if self.diverged is None and abs(self.energy_change) > 1.0:
            self.diverged = self.frames


def _outcome_columns(outcome: _Outcome) -> dict:
    return {
        "max_gap_mm": 1e3 * outcome.max_gap,
        "end_gap_mm": 1e3 * outcome.end_gap,
        "max_axis_rad": outcome.max_axis,
        "energy_change": outcome.energy_change,
        "energy_max_dev": outcome.max_dev,
    }


# --- one engine in one configuration ------------------------------------------------------------------


@dataclass
class _Sim(peers.EngineRun):
    """A built chain: ``frame()`` reads the links."""

    frame: Callable[[], _Frame]
    close: Callable[[], None] = field(default=lambda: None)
    failed: Callable[[], str] = field(default=str)  # why the engine gave up, "" while it runs


def _tumble_sim(links: int, hz: int) -> _Sim:
    def build():
        world = world_chain(links)
        world.state  # noqa: B018  (build the model now)
        return world

    build_s, world = _timed(build)
    index = np.array([world.body(f"link{k}").index for k in range(links)])

    def frame() -> _Frame:
        s = world.state
        return _Frame(s.body_pos[index].copy(), _matrices(s.body_quat[index]), s.body_linvel[index].copy(),
                      world.angular_velocities()[index])  # fmt: skip

    config = f"world hinges, substeps={world.solver.substeps}"
    return _Sim("tumble", config, hz, numba.get_num_threads(), build_s, functools.partial(world.step, 1.0 / hz), frame)


def _xyzw(rotation: np.ndarray) -> list[float]:
    q = tumble.rotation.matrix_to_quat(rotation)
    return [float(q[1]), float(q[2]), float(q[3]), float(q[0])]


def _diagonal(chain: Chain) -> np.ndarray:
    """(n, 3) the principal moments: the capsule frame is principal (PyBullet takes a diagonal only)."""
    diag = np.diagonal(chain.inertia, axis1=1, axis2=2)
    if not np.allclose(chain.inertia, diag[:, :, None] * np.eye(3), atol=1e-15):
        raise ValueError("the links' inertia must be diagonal in their capsule frame")
    return diag


def _check_pybullet_masses(p, client, parts, chain: Chain) -> None:
    """PyBullet's ``changeDynamics`` has surprises (see ``_pybullet_multibody``): read every link's mass and
    inertia back. ``parts``: ``(body, link index)`` of each chain link, in order."""
    for (body, link), mass, moments in zip(parts, chain.mass, _diagonal(chain), strict=True):
        got_mass, _, got_moments = p.getDynamicsInfo(body, link, physicsClientId=client)[:3]
        if not (np.isclose(got_mass, mass, rtol=1e-12) and np.allclose(got_moments, moments, rtol=1e-9, atol=0)):
            raise RuntimeError(f"PyBullet body {body} link {link}: mass {got_mass}, inertia {got_moments}")


def _pybullet_frames(p, client, bodies) -> _Frame:
    com, quat, velocity, omega = [], [], [], []
    for body in bodies:
        position, q = p.getBasePositionAndOrientation(body, physicsClientId=client)
        v, w = p.getBaseVelocity(body, physicsClientId=client)
        com.append(position)
        quat.append((q[3], q[0], q[1], q[2]))
        velocity.append(v)
        omega.append(w)
    return _Frame(np.array(com), _matrices(np.array(quat)), np.array(velocity), np.array(omega))


def _pybullet_client(p, chain: Chain, hz: int) -> int:
    client = p.connect(p.DIRECT)
    p.setGravity(*chain.gravity.tolist(), physicsClientId=client)
    p.setTimeStep(1.0 / hz, physicsClientId=client)
    return client


def _pybullet_maximal(chain: Chain, hz: int) -> tuple[int, list[int]]:
    """Rigid bodies joined by pairs of point-to-point constraints ± ``PAIR_OFFSET`` along the hinge axis."""
    import pybullet as p

    client = _pybullet_client(p, chain, hz)
    try:
        capsule = p.createCollisionShape(p.GEOM_CAPSULE, radius=chain.radius, height=chain.segment,
                                         physicsClientId=client)  # fmt: skip
        orientation = _xyzw(chain.rotation)
        bodies = []
        for mass, moments, com in zip(chain.mass, _diagonal(chain), chain.com, strict=True):
            body = p.createMultiBody(float(mass), capsule, basePosition=com.tolist(), baseOrientation=orientation,
                                     useMaximalCoordinates=True, physicsClientId=client)  # fmt: skip
            # PyBullet zeroes the mass when only the inertia is given: pass both.
            p.changeDynamics(body, -1, mass=float(mass), localInertiaDiagonal=moments.tolist(), linearDamping=0.0,
                             angularDamping=0.0, physicsClientId=client)  # fmt: skip
            p.setCollisionFilterGroupMask(body, -1, 0, 0, physicsClientId=client)
            bodies.append(body)
        _check_pybullet_masses(p, client, [(body, -1) for body in bodies], chain)
        anchor = p.createMultiBody(0.0, -1, basePosition=chain.pivot.tolist(), useMaximalCoordinates=True,
                                   physicsClientId=client)  # fmt: skip
        axis = chain.axis
        half = 0.5 * chain.pitch * chain.rotation[:, 2]
        for k, body in enumerate(bodies):
            joint = chain.com[k] - half
            other, other_origin = (anchor, chain.pivot) if k == 0 else (bodies[k - 1], chain.com[k - 1])
            for side in (-1.0, 1.0):
                point = joint + side * PAIR_OFFSET * axis
                constraint = p.createConstraint(
                    body, -1, other, -1, p.JOINT_POINT2POINT, [0.0, 0.0, 0.0],
                    (chain.rotation.T @ (point - chain.com[k])).tolist(),
                    (point - other_origin if k == 0 else chain.rotation.T @ (point - other_origin)).tolist(),
                    physicsClientId=client,
                )  # fmt: skip
                p.changeConstraint(constraint, maxForce=MAX_FORCE, physicsClientId=client)
    except Exception:
        p.disconnect(client)
        raise
    return client, bodies


def _pybullet_multibody(chain: Chain, hz: int) -> tuple[int, int]:
    """One multibody: a fixed massless base at the pivot, each link on a revolute joint at its near end."""
    import pybullet as p

    client = _pybullet_client(p, chain, hz)
    try:
        n = chain.links
        capsule = p.createCollisionShape(p.GEOM_CAPSULE, radius=chain.radius, height=chain.segment,
                                         physicsClientId=client)  # fmt: skip
        identity = [0.0, 0.0, 0.0, 1.0]
        # Link frames are the capsule frames (z along the link) at the joints; the first is turned from the base's.
        body = p.createMultiBody(
            0.0, -1, basePosition=chain.pivot.tolist(),
            linkMasses=chain.mass.tolist(),
            linkCollisionShapeIndices=[capsule] * n,
            linkVisualShapeIndices=[-1] * n,
            linkPositions=[[0.0, 0.0, 0.0]] + [[0.0, 0.0, chain.pitch]] * (n - 1),
            linkOrientations=[_xyzw(chain.rotation)] + [identity] * (n - 1),
            linkInertialFramePositions=[[0.0, 0.0, 0.5 * chain.pitch]] * n,
            linkInertialFrameOrientations=[identity] * n,
            linkParentIndices=list(range(n)),
            linkJointTypes=[p.JOINT_REVOLUTE] * n,
            linkJointAxis=[(chain.rotation.T @ chain.axis).tolist()] * n,
            physicsClientId=client,
        )  # fmt: skip
        # One setting a call: PyBullet 3.2 gives a link's inertia to the base when the same changeDynamics call also
        # sets a damping or the joint's speed cap. The masses are set already (setting one again scales the shape's
        # inertia to it); the damping belongs to the whole multibody.
        p.changeDynamics(body, -1, linearDamping=0.0, angularDamping=0.0, physicsClientId=client)
        for k, moments in enumerate(_diagonal(chain)):
            p.changeDynamics(body, k, localInertiaDiagonal=moments.tolist(), physicsClientId=client)
            p.changeDynamics(body, k, maxJointVelocity=MAX_JOINT_SPEED, physicsClientId=client)
            p.setCollisionFilterGroupMask(body, k, 0, 0, physicsClientId=client)
        _check_pybullet_masses(p, client, [(body, k) for k in range(n)], chain)
        p.setJointMotorControlArray(body, list(range(n)), p.VELOCITY_CONTROL, forces=[0.0] * n,
                                    physicsClientId=client)  # fmt: skip
    except Exception:
        p.disconnect(client)
        raise
    return client, body


def _pybullet_multibody_frames(p, client, body, n) -> _Frame:
    states = p.getLinkStates(body, list(range(n)), computeLinkVelocity=1, computeForwardKinematics=1,
                             physicsClientId=client)  # fmt: skip
    quat = np.array([(s[1][3], s[1][0], s[1][1], s[1][2]) for s in states])
    return _Frame(np.array([s[0] for s in states]), _matrices(quat), np.array([s[6] for s in states]),
                  np.array([s[7] for s in states]))  # fmt: skip


def _pybullet_sim(chain: Chain, hz: int, multibody: bool) -> _Sim:
    import pybullet as p

    if multibody:
        build_s, (client, body) = _timed(_pybullet_multibody, chain, hz)
        frame = functools.partial(_pybullet_multibody_frames, p, client, body, chain.links)
        config = "multibody, revolute joints"
    else:
        build_s, (client, bodies) = _timed(_pybullet_maximal, chain, hz)
        frame = functools.partial(_pybullet_frames, p, client, bodies)
        config = "maximal coords, 2 point2point per hinge"
    iterations = p.getPhysicsEngineParameters(physicsClientId=client)["numSolverIterations"]
    return _Sim("PyBullet", f"{config}, {iterations} iterations", hz, 1, build_s,
                functools.partial(p.stepSimulation, physicsClientId=client), frame,
                functools.partial(p.disconnect, client))  # fmt: skip


def chain_mjcf(chain: Chain, integrator: str = "RK4", timestep: float = 1 / 240) -> str:
    """The chain as nested MuJoCo bodies on hinges (generalised coordinates), capsule geoms that collide with
    nothing, each link's inertia given explicitly (its capsule frame turned by ``chain.rotation``)."""
    along = chain.rotation[:, 2] * chain.pitch
    axis = chain.axis
    ends = f"{peers._vec(along * chain.radius / chain.pitch)} {peers._vec(along * (1 - chain.radius / chain.pitch))}"
    option = f"timestep='{float(timestep)!r}' gravity='{peers._vec(chain.gravity)}' integrator='{integrator}'"
    opened = []
    for k, (mass, inertia) in enumerate(zip(chain.mass, chain.inertia, strict=True)):
        full = chain.rotation @ inertia @ chain.rotation.T  # body frames are world-aligned at release
        moments = (full[0, 0], full[1, 1], full[2, 2], full[0, 1], full[0, 2], full[1, 2])
        position = chain.pivot if k == 0 else along
        opened.append(
            f"<body name='link{k}' pos='{peers._vec(position)}'>"
            f"<joint type='hinge' axis='{peers._vec(axis)}'/>"
            f"<inertial pos='{peers._vec(0.5 * along)}' mass='{float(mass)!r}' fullinertia='{peers._vec(moments)}'/>"
            f"<geom type='capsule' fromto='{ends}' size='{float(chain.radius)!r}' "
            "contype='0' conaffinity='0'/>"
        )
    return (
        "<mujoco model='world_chain'><compiler inertiafromgeom='false'/>"
        f"<option {option}/><worldbody>{''.join(opened)}{'</body>' * len(opened)}</worldbody></mujoco>"
    )


def _mujoco_sim(chain: Chain, integrator: str, hz: int) -> _Sim:
    import mujoco

    build_s, (model, data) = _timed(peers.load, chain_mjcf(chain, integrator, 1.0 / hz))
    n = chain.links
    ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, f"link{k}") for k in range(n)]
    to_capsule = chain.rotation  # MuJoCo's body frames are the world's at release
    velocity = np.zeros(6)

    def failed() -> str:
        found = [
            w
            for w in ("BADQACC", "BADQVEL", "BADQPOS")
            if data.warning[getattr(mujoco.mjtWarning, "mjWARN_" + w)].number
        ]
        return f"MuJoCo unstable ({', '.join(found)}): it resets the state, run stopped" if found else ""

    def frame() -> _Frame:
        mujoco.mj_forward(model, data)  # positions after the last step (mj_step leaves them a step behind)
        vel = np.empty((n, 3))
        omega = np.empty((n, 3))
        for k, body in enumerate(ids):
            mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_BODY, body, velocity, 0)
            omega[k], vel[k] = velocity[:3], velocity[3:]
        rotation = data.xmat[ids].reshape(n, 3, 3) @ to_capsule
        return _Frame(data.xipos[ids].copy(), rotation, vel, omega)

    return _Sim("MuJoCo", f"hinges, {integrator}", hz, 1, build_s, functools.partial(mujoco.mj_step, model, data),
                frame, failed=failed)  # fmt: skip


# --- running -----------------------------------------------------------------------------------------


def _steps(sim: _Sim, outcome: _Outcome, steps: int) -> tuple[float, float, int, str]:
    """Take ``steps`` steps, each timed on its own and measured after; ``(first step, the others' time, steps
    done, notes)``."""
    clock, step, failed = time.perf_counter, sim.step, sim.failed
    first, elapsed, done = math.nan, 0.0, 0
    try:
        start = clock()
        step()
        first = clock() - start
        done = 1
        while not failed():
            outcome.add(sim.frame())
            if done == steps or not outcome.finite:
                break
            start = clock()
            step()
            elapsed += clock() - start
            done += 1
    except tumble.SimulationError as error:
        return first, elapsed, done, f"failed at step {done + 1}: {error}"
    notes = [failed() or ("" if outcome.finite else "non-finite state")]
    if outcome.diverged is not None:
        notes.append(f"energy off by more than the potential drop from t = {outcome.diverged / sim.hz:.2f} s")
    return first, elapsed, done, "; ".join(n for n in notes if n)


def _run(make: Callable[[], _Sim], chain: Chain, seconds: float) -> dict:
    """One fresh build stepped ``seconds``, the state measured between steps: one row."""
    sim = make()
    try:
        outcome = _Outcome(chain, energy(chain, sim.frame()))
        first, elapsed, done, notes = _steps(sim, outcome, max(2, round(seconds * sim.hz)))
    finally:
        sim.close()
    return {
        "links": chain.links,
        **sim.timing(done, first, elapsed),
        **_outcome_columns(outcome),
        "notes": notes,
    }


def bench_world_chain(sizes) -> list[dict]:
    """A chain of ``sizes.chain_links`` hinged capsules released horizontal, ``sizes.chain_seconds``: tumble at
    60 and 240 Hz, PyBullet (maximal coordinates and a multibody) at 240 and 60 Hz, MuJoCo at 240 Hz (Euler, RK4)
    and 1000 Hz (RK4); each peer only when installed."""
    links, seconds = sizes.chain_links, sizes.chain_seconds
    rounds = max(1, min(sizes.repeat, 5))
    chain = chain_from_world(world_chain(links), links)
    makers = [functools.partial(_tumble_sim, links, hz) for hz in TUMBLE_HZ]
    if peers.have_pybullet():
        makers += [functools.partial(_pybullet_sim, chain, hz, multibody) for multibody in (False, True)
                   for hz in PYBULLET_HZ]  # fmt: skip
    if peers.have_mujoco():
        makers += [functools.partial(_mujoco_sim, chain, integrator, hz) for integrator, hz in MUJOCO_RUNS]
    # The configurations take turns, round after round, so that load from other processes falls on all alike; each
    # keeps its fastest run, and the first round's first step (the one that compiles).
    rows = [_run(make, chain, seconds) for make in makers]
    for _ in range(rounds - 1):
        for k, make in enumerate(makers):
            row = _run(make, chain, seconds)
            if row["steps_per_s"] > rows[k]["steps_per_s"]:
                rows[k] = {**row, "first_step_s": rows[k]["first_step_s"]}
    references = {
        "x_pybullet": ("PyBullet", PYBULLET_HZ[0], "maximal"),
        "x_mujoco": ("MuJoCo", MUJOCO_REFERENCE[1], MUJOCO_REFERENCE[0]),
    }
    for column, (engine, hz, config) in references.items():
        reference = next((r for r in rows if r["engine"] == engine and r["hz"] == hz and config in r["config"]), None)
        if reference is not None:
            for r in rows:
                r[column] = r["realtime_x"] / reference["realtime_x"]
    # Keep the free-text column last.
    return [{**{k: v for k, v in r.items() if k != "notes"}, "notes": r["notes"]} for r in rows]
