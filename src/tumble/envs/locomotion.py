"""Gymnasium's MuJoCo locomotion tasks (v5) on tumble: ``tumble/Hopper``, ``tumble/Walker2d``, ``tumble/HalfCheetah``,
``tumble/Ant`` and ``tumble/Humanoid``.

Each task loads the MJCF asset that Gymnasium ships (``gymnasium/envs/mujoco/assets``) into an articulation in
MuJoCo's own coordinates (``tumble.articulation.from_mjcf``: ``q`` is ``qpos``, ``qd`` is ``qvel``), and steps it at
the file's timestep and integrator (MuJoCo's Euler is ``symplectic_implicit_damping``), ``frame_skip`` steps a
control step. The action is MuJoCo's ``ctrl``: each motor pushes its joint with ``gear · clip(ctrl, ctrlrange)``.
Spaces, observation layout, reward terms, ``info`` keys, healthy ranges, reset noise and the v5 constructor arguments
are Gymnasium's (the v5 classes' documentation).

MuJoCo's body quantities that the ant and the humanoid observe are made from tumble's links (the link that carries
each MJCF body's mass and geoms), at the state the step reached, about the robot's centre of mass in world axes as
MuJoCo's "com-based" quantities are: ``cinert`` (inertia, first moment and mass), ``cvel`` (spatial velocity) and
``cfrc_ext`` (the contact wrench, from a solve of the contacts at that state). ``docs/envs.md`` says where and by how
much they differ from MuJoCo's.
"""

from __future__ import annotations

import importlib.resources
import math
import numbers
from pathlib import Path

import numpy as np
from gymnasium import spaces

from ..articulation import Articulation
from ..articulation.kernels import READOUT_INERTIA, READOUT_ORIGIN, READOUT_POINT, READOUT_VELOCITY, READOUT_WRENCH
from ..models.build import to_articulation
from ..models.mjcf import read_mjcf
from ..rotation import quat_rotate
from .canvas import Canvas
from .core import Task, uniform

__all__ = [
    "AntTask",
    "HalfCheetahTask",
    "HopperTask",
    "HumanoidTask",
    "LocomotionTask",
    "Walker2dTask",
    "body_terms",
    "centre_of_mass",
    "root_position",
]

ASSETS = Path(str(importlib.resources.files("gymnasium"))) / "envs" / "mujoco" / "assets"
_INTEGRATORS = {"Euler": "symplectic_implicit_damping", "RK4": "rk4"}


def _weight(name: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(value):
        raise ValueError(f"{name} must be a finite number, got {value!r}")
    return float(value)


def _range(name: str, value) -> tuple[float, float]:
    try:
        low, high = (float(v) for v in value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a (low, high) pair of numbers, got {value!r}") from None
    if math.isnan(low) or math.isnan(high) or low > high:
        raise ValueError(f"{name} must be a (low, high) pair with low <= high, got {value!r}")
    return low, high


def _flag(name: str, value) -> bool:
    if not isinstance(value, bool):
        raise TypeError(f"{name} must be True or False, got {value!r}")
    return value


def body_terms(links: np.ndarray, body_links: np.ndarray):
    """MuJoCo's com-based body quantities of each copy from ``batch_kernel``'s readout ``links`` (copies, links, ...):
    ``(cinert (copies, bodies, 10), cvel (copies, bodies, 6), cfrc_ext (copies, bodies, 6))`` of the links
    ``body_links`` (one per MJCF body, the world left out), as ``articulation.kernels._read_links`` makes them."""
    rows = links[:, body_links]
    return (rows[..., READOUT_INERTIA : READOUT_INERTIA + 10], rows[..., READOUT_VELOCITY : READOUT_VELOCITY + 6],
            rows[..., READOUT_WRENCH : READOUT_WRENCH + 6])  # fmt: skip


def centre_of_mass(links: np.ndarray) -> np.ndarray:
    """(copies, 3) the robot's centre of mass [m] (its base link's tree's) from the readout ``links``."""
    return links[:, 0, READOUT_POINT : READOUT_POINT + 3]


def root_position(links: np.ndarray) -> np.ndarray:
    """(copies, 3) the base link's frame origin [m] (MuJoCo's ``xpos`` of the root body) from the readout."""
    return links[:, 0, READOUT_ORIGIN : READOUT_ORIGIN + 3]


class LocomotionTask(Task):
    """What the five tasks share: the asset, the motors, the reset noise, the forward reward and the picture.

    Subclasses set ``asset`` (the file name; ``frame_skip``'s default is their constructor's),
    ``skipped_positions`` (the leading ``qpos`` entries an observation leaves out: 1 for the planar robots, 2 for
    those on a free joint) and ``uniform_velocity_noise`` (whether the start's velocity noise is uniform, else
    normal), and call :meth:`_load` from ``__init__``.
    """

    asset: str
    skipped_positions: int
    uniform_velocity_noise: bool
    max_episode_steps = 1000
    reward_reads_start = True  # the forward reward is the displacement over the step

    def _arguments(self, **values) -> None:
        """Gymnasium's constructor arguments, validated, as attributes of the same names: ``*_range`` a (low, high)
        pair (or None), ``terminate_when_unhealthy`` a bool, any other a finite number."""
        for name, value in values.items():
            if name.endswith("_range"):
                value = None if value is None else _range(name, value)
            else:
                value = _flag(name, value) if name == "terminate_when_unhealthy" else _weight(name, value)
            setattr(self, name, value)

    def _load(self, xml_file, frame_skip, reset_noise_scale, exclude_current_positions) -> None:
        path = ASSETS / self.asset if xml_file is None else Path(xml_file)
        if not path.is_absolute() and xml_file is not None and not path.exists():
            path = ASSETS / path  # a bare name: one of Gymnasium's assets, as MujocoEnv resolves it
        if isinstance(frame_skip, bool) or not isinstance(frame_skip, numbers.Integral) or frame_skip < 1:
            raise ValueError(f"frame_skip must be a positive integer, got {frame_skip!r}")
        self.xml_file = str(path)
        self.description = read_mjcf(path)
        if self.description.integrator not in _INTEGRATORS:
            raise ValueError(f"{path}: integrator {self.description.integrator!r} is not simulated here; "
                             f"use one of {tuple(_INTEGRATORS)}")  # fmt: skip
        self.integrator = _INTEGRATORS[self.description.integrator]
        self.substeps = int(frame_skip)
        self.dt = self.description.timestep * self.substeps
        self.render_fps = int(np.round(1.0 / self.dt))
        self.reset_noise_scale = _weight("reset_noise_scale", reset_noise_scale)
        self.exclude_current_positions = _flag("exclude_current_positions_from_observation", exclude_current_positions)
        template = self.articulation()
        self._template = template
        self.init_q, self.init_qd = template.q, template.qd
        nq, nv = self.init_q.shape[0], self.init_qd.shape[0]
        self.start_draws = (("uniform", nq), ("uniform" if self.uniform_velocity_noise else "normal", nv))
        # each MJCF body is the last link of its chain of joints (models.build.to_articulation)
        self.body_links = np.cumsum([max(1, len(body.joints)) for body in self.description.bodies]) - 1
        self._motors(template)

    def _motors(self, art: Articulation) -> None:
        """The action space and each motor's degree of freedom and gear; other actuators are refused."""
        dofs, gears, low, high = [], [], [], []
        for actuator in art.actuators:
            label = actuator.name or f"#{actuator.index}"
            link = None if actuator.link is None else art.links[actuator.link]
            if (link is None or link.v_slice.stop - link.v_slice.start != 1 or actuator.gain != 1.0
                    or np.any(actuator.bias != 0.0) or actuator.force_range is not None):  # fmt: skip
                raise ValueError(f"{self.xml_file}: actuator {label} must be a motor on a hinge or slide joint "
                                 "(gain 1, no bias, no forcerange) for a locomotion task")  # fmt: skip
            dofs.append(link.v_slice.start)
            gears.append(actuator.gear)
            ctrl_range = actuator.ctrl_range or (0.0, 0.0)  # MuJoCo's ctrlrange of an unlimited actuator
            low.append(ctrl_range[0])
            high.append(ctrl_range[1])
        if len(set(dofs)) != len(dofs):
            raise ValueError(f"{self.xml_file}: two actuators drive one joint")
        self.motor_dofs, self.gears = np.array(dofs, dtype=np.int64), np.array(gears)
        limited = np.array([a.ctrl_range is not None for a in art.actuators], dtype=bool)
        self.ctrl_low = np.where(limited, low, -np.inf)
        self.ctrl_high = np.where(limited, high, np.inf)
        self.action_space = spaces.Box(np.array(low, dtype=np.float32), np.array(high, dtype=np.float32),
                                       dtype=np.float32)  # fmt: skip

    def articulation(self) -> Articulation:
        return to_articulation(self.description)

    def _observation_space(self, size: int) -> None:
        self.observation_space = spaces.Box(-np.inf, np.inf, shape=(size,), dtype=np.float64)

    def start(self, draws):
        noise, nq = self.reset_noise_scale, self.init_q.shape[0]
        # a free joint's quaternion keeps its noise unnormalised, as MuJoCo's qpos does until the first step (the
        # kinematics read it normalised; the step's update normalises it)
        q = self.init_q + uniform(draws[:, :nq], -noise, noise)
        if self.uniform_velocity_noise:
            return q, self.init_qd + uniform(draws[:, nq:], -noise, noise)
        return q, self.init_qd + noise * draws[:, nq:]

    def prepare(self, actions, q, qd, tau):
        # the costs square the actions as given (float32 from the action space), as Gymnasium's do
        actions = np.asarray(actions)
        count, size = q.shape[0], self.motor_dofs.shape[0]
        if actions.shape != (count, size):
            raise ValueError(f"action must have shape {(size,) if count == 1 else (count, size)}, "
                             f"got {actions.shape[1:] if count == 1 else actions.shape}")  # fmt: skip
        if not np.all(np.isfinite(actions)):
            raise ValueError(f"action must be finite, got {actions[~np.all(np.isfinite(actions), axis=1)][0]!r}")
        ctrl = actions.astype(np.float64)
        # only the motors' rows of tau are ever set (a start zeroes them all)
        tau[:, self.motor_dofs] = self.gears * np.minimum(np.maximum(ctrl, self.ctrl_low), self.ctrl_high)
        return actions if np.issubdtype(actions.dtype, np.floating) else ctrl

    def _positions(self, q):
        return q[:, self.skipped_positions :] if self.exclude_current_positions else q

    def draw(self, q):
        """A side view (x right, z up) of the geoms at ``q``, following the root."""
        positions, quats = self._template.link_poses(q)
        canvas = Canvas(480, 480, scale=480 / 4.0, centre=(positions[0, 0], 1.0))
        for mark in np.arange(math.floor(positions[0, 0] - 2.0), positions[0, 0] + 2.0, 0.5):  # ground ticks
            canvas.segment((mark, 0.0), (mark, -0.05), 0.02, (120, 120, 120))
        canvas.segment((positions[0, 0] - 2.5, 0.0), (positions[0, 0] + 2.5, 0.0), 0.02, (120, 120, 120))
        for geom in self._template.geoms:
            if geom.link is None or geom.kind == "plane":
                continue
            centre = positions[geom.link] + quat_rotate(quats[geom.link], geom.position)
            axis = quat_rotate(quats[geom.link], quat_rotate(geom.orientation, (0.0, 0.0, geom.size[1])))
            a, b = centre - axis, centre + axis
            if geom.kind == "sphere":
                a = b = centre
            canvas.segment((a[0], a[2]), (b[0], b[2]), 2.0 * geom.size[0], (179, 102, 51))
        return canvas.image

    # --- the terms every task has ---------------------------------------------------------------------------------

    terminate_when_unhealthy = False

    def healthy(self, q, qd):
        """Gymnasium's ``is_healthy`` of each copy (always, for a task that cannot fall)."""
        return np.ones(q.shape[0], dtype=bool)

    def terminated(self, q, qd):
        return self._ended(self.healthy(q, qd))

    def _ended(self, healthy):
        return ~healthy if self.terminate_when_unhealthy else np.zeros(healthy.shape[0], dtype=bool)

    def control_cost(self, actions):
        return self.ctrl_cost_weight * np.sum(np.square(actions), axis=1)


class _PlanarTask(LocomotionTask):
    """Hopper and Walker2d: a planar robot on (rootx, rootz, rooty) that must stay up."""

    skipped_positions = 1
    uniform_velocity_noise = True

    def __init__(self, xml_file, frame_skip, forward_reward_weight, ctrl_cost_weight, healthy_reward,
                 terminate_when_unhealthy, healthy_z_range, healthy_angle_range, reset_noise_scale,
                 exclude_current_positions_from_observation, healthy_state_range=None) -> None:  # fmt: skip
        self._arguments(forward_reward_weight=forward_reward_weight, ctrl_cost_weight=ctrl_cost_weight,
                        healthy_reward=healthy_reward, terminate_when_unhealthy=terminate_when_unhealthy,
                        healthy_z_range=healthy_z_range, healthy_angle_range=healthy_angle_range,
                        healthy_state_range=healthy_state_range)  # fmt: skip
        self._load(xml_file, frame_skip, reset_noise_scale, exclude_current_positions_from_observation)
        self._observation_space(self.init_q.shape[0] + self.init_qd.shape[0] - self.exclude_current_positions)

    def healthy(self, q, qd):
        """Gymnasium's ``is_healthy`` of each copy (strict inequalities)."""
        (z_low, z_high), (a_low, a_high) = self.healthy_z_range, self.healthy_angle_range
        healthy = (z_low < q[:, 1]) & (q[:, 1] < z_high) & (a_low < q[:, 2]) & (q[:, 2] < a_high)
        if self.healthy_state_range is not None:  # over the state (qpos, qvel) but its first two entries
            low, high = self.healthy_state_range
            healthy &= ((low < q[:, 2:]) & (q[:, 2:] < high)).all(axis=1) & ((low < qd) & (qd < high)).all(axis=1)
        return healthy

    def observe(self, q, qd, links=None, tau=None):
        return np.concatenate([self._positions(q), np.clip(qd, -10.0, 10.0)], axis=1)

    def outcome(self, start, actions, q, qd, links):
        x_velocity = (q[:, 0] - start[0][:, 0]) / self.dt
        forward = self.forward_reward_weight * x_velocity
        healthy = self.healthy(q, qd)
        survive = healthy * self.healthy_reward
        ctrl = self.control_cost(actions)
        info = {"x_position": q[:, 0].copy(), "z_distance_from_origin": q[:, 1] - self.init_q[1],
                "x_velocity": x_velocity, "reward_forward": forward, "reward_ctrl": -ctrl,
                "reward_survive": survive}  # fmt: skip
        return forward + survive - ctrl, self._ended(healthy), info

    def reset_info(self, q, qd, links=None):
        return {"x_position": q[:, 0].copy(), "z_distance_from_origin": q[:, 1] - self.init_q[1]}


class HopperTask(_PlanarTask):
    """``tumble/Hopper``: Gymnasium's ``Hopper-v5`` (``hopper.xml``, four RK4 steps of 2 ms a control step)."""

    asset = "hopper.xml"

    def __init__(self, xml_file=None, frame_skip=4, forward_reward_weight=1.0, ctrl_cost_weight=1e-3,
                 healthy_reward=1.0, terminate_when_unhealthy=True, healthy_state_range=(-100.0, 100.0),
                 healthy_z_range=(0.7, float("inf")), healthy_angle_range=(-0.2, 0.2), reset_noise_scale=5e-3,
                 exclude_current_positions_from_observation=True) -> None:  # fmt: skip
        super().__init__(xml_file, frame_skip, forward_reward_weight, ctrl_cost_weight, healthy_reward,
                         terminate_when_unhealthy, healthy_z_range, healthy_angle_range, reset_noise_scale,
                         exclude_current_positions_from_observation, healthy_state_range)  # fmt: skip


class Walker2dTask(_PlanarTask):
    """``tumble/Walker2d``: Gymnasium's ``Walker2d-v5`` (``walker2d_v5.xml``, four RK4 steps of 2 ms)."""

    asset = "walker2d_v5.xml"

    def __init__(self, xml_file=None, frame_skip=4, forward_reward_weight=1.0, ctrl_cost_weight=1e-3,
                 healthy_reward=1.0, terminate_when_unhealthy=True, healthy_z_range=(0.8, 2.0),
                 healthy_angle_range=(-1.0, 1.0), reset_noise_scale=5e-3,
                 exclude_current_positions_from_observation=True) -> None:  # fmt: skip
        super().__init__(xml_file, frame_skip, forward_reward_weight, ctrl_cost_weight, healthy_reward,
                         terminate_when_unhealthy, healthy_z_range, healthy_angle_range, reset_noise_scale,
                         exclude_current_positions_from_observation)  # fmt: skip


class HalfCheetahTask(LocomotionTask):
    """``tumble/HalfCheetah``: Gymnasium's ``HalfCheetah-v5`` (``half_cheetah.xml``, five Euler steps of 10 ms);
    it never terminates."""

    asset = "half_cheetah.xml"
    skipped_positions = 1
    uniform_velocity_noise = False

    def __init__(self, xml_file=None, frame_skip=5, forward_reward_weight=1.0, ctrl_cost_weight=0.1,
                 reset_noise_scale=0.1, exclude_current_positions_from_observation=True) -> None:  # fmt: skip
        self._arguments(forward_reward_weight=forward_reward_weight, ctrl_cost_weight=ctrl_cost_weight)
        self._load(xml_file, frame_skip, reset_noise_scale, exclude_current_positions_from_observation)
        self._observation_space(self.init_q.shape[0] + self.init_qd.shape[0] - self.exclude_current_positions)

    def observe(self, q, qd, links=None, tau=None):
        return np.concatenate([self._positions(q), qd], axis=1)

    def outcome(self, start, actions, q, qd, links):
        x_velocity = (q[:, 0] - start[0][:, 0]) / self.dt
        forward = self.forward_reward_weight * x_velocity
        ctrl = self.control_cost(actions)
        info = {"x_position": q[:, 0].copy(), "x_velocity": x_velocity, "reward_forward": forward,
                "reward_ctrl": -ctrl}  # fmt: skip
        return forward - ctrl, np.zeros(q.shape[0], dtype=bool), info

    def reset_info(self, q, qd, links=None):
        return {"x_position": q[:, 0].copy()}


class _SpatialTask(LocomotionTask):
    """Ant and Humanoid: a robot on a free joint, with contact forces in its reward and observation."""

    skipped_positions = 2
    reads_links = True

    def _place_info(self, q) -> dict:
        return {"x_position": q[:, 0].copy(), "y_position": q[:, 1].copy(),
                "distance_from_origin": np.sqrt(q[:, 0] ** 2 + q[:, 1] ** 2)}  # fmt: skip


class AntTask(_SpatialTask):
    """``tumble/Ant``: Gymnasium's ``Ant-v5`` (``ant.xml``, five RK4 steps of 10 ms a control step)."""

    asset = "ant.xml"
    uniform_velocity_noise = False

    def __init__(self, xml_file=None, frame_skip=5, forward_reward_weight=1.0, ctrl_cost_weight=0.5,
                 contact_cost_weight=5e-4, healthy_reward=1.0, main_body=1, terminate_when_unhealthy=True,
                 healthy_z_range=(0.2, 1.0), contact_force_range=(-1.0, 1.0), reset_noise_scale=0.1,
                 exclude_current_positions_from_observation=True,
                 include_cfrc_ext_in_observation=True) -> None:  # fmt: skip
        self._arguments(forward_reward_weight=forward_reward_weight, ctrl_cost_weight=ctrl_cost_weight,
                        contact_cost_weight=contact_cost_weight, healthy_reward=healthy_reward,
                        terminate_when_unhealthy=terminate_when_unhealthy, healthy_z_range=healthy_z_range,
                        contact_force_range=contact_force_range)  # fmt: skip
        self.include_cfrc_ext = _flag("include_cfrc_ext_in_observation", include_cfrc_ext_in_observation)
        self._load(xml_file, frame_skip, reset_noise_scale, exclude_current_positions_from_observation)
        root = self.description.bodies[0].name
        if main_body not in (1, root) or isinstance(main_body, bool):
            raise ValueError(f"main_body must be the root body (1 or {root!r}): the forward reward follows the free "
                             f"joint's position; got {main_body!r}")  # fmt: skip
        size = self.init_q.shape[0] + self.init_qd.shape[0] - 2 * self.exclude_current_positions
        self._observation_space(size + 6 * len(self.body_links) * self.include_cfrc_ext)

    def healthy(self, q, qd):
        """Gymnasium's ``is_healthy``: a finite state and the root's height within the range (inclusive)."""
        low, high = self.healthy_z_range
        finite = np.all(np.isfinite(q), axis=1) & np.all(np.isfinite(qd), axis=1)
        return finite & (low <= q[:, 2]) & (q[:, 2] <= high)

    def contact_forces(self, links):
        """``cfrc_ext`` of every body (the world's is zero, left out) clipped to ``contact_force_range``."""
        return np.clip(body_terms(links, self.body_links)[2], *self.contact_force_range)

    def observe(self, q, qd, links=None, tau=None):
        parts = [self._positions(q), qd]
        if self.include_cfrc_ext:
            parts.append(self.contact_forces(links).reshape(q.shape[0], -1))
        return np.concatenate(parts, axis=1)

    def outcome(self, start, actions, q, qd, links):
        # the root's xpos, as MuJoCo's mjData holds it after the step (from its last evaluation, as every body term)
        xy_velocity = (root_position(links)[:, :2] - root_position(start[2])[:, :2]) / self.dt
        forward = self.forward_reward_weight * xy_velocity[:, 0]
        healthy = self.healthy(q, qd)
        survive = healthy * self.healthy_reward
        ctrl = self.control_cost(actions)
        contact = self.contact_cost_weight * np.sum(np.square(self.contact_forces(links)), axis=(1, 2))
        info = {**self._place_info(q), "x_velocity": xy_velocity[:, 0], "y_velocity": xy_velocity[:, 1],
                "reward_forward": forward, "reward_ctrl": -ctrl, "reward_contact": -contact,
                "reward_survive": survive}  # fmt: skip
        return forward + survive - ctrl - contact, self._ended(healthy), info

    def reset_info(self, q, qd, links=None):
        return self._place_info(q)


class HumanoidTask(_SpatialTask):
    """``tumble/Humanoid``: Gymnasium's ``Humanoid-v5`` (``humanoid.xml``, five RK4 steps of 3 ms a control step)."""

    asset = "humanoid.xml"
    uniform_velocity_noise = True

    def __init__(self, xml_file=None, frame_skip=5, forward_reward_weight=1.25, ctrl_cost_weight=0.1,
                 contact_cost_weight=5e-7, contact_cost_range=(-np.inf, 10.0), healthy_reward=5.0,
                 terminate_when_unhealthy=True, healthy_z_range=(1.0, 2.0), reset_noise_scale=1e-2,
                 exclude_current_positions_from_observation=True, include_cinert_in_observation=True,
                 include_cvel_in_observation=True, include_qfrc_actuator_in_observation=True,
                 include_cfrc_ext_in_observation=True) -> None:  # fmt: skip
        self._arguments(forward_reward_weight=forward_reward_weight, ctrl_cost_weight=ctrl_cost_weight,
                        contact_cost_weight=contact_cost_weight, healthy_reward=healthy_reward,
                        terminate_when_unhealthy=terminate_when_unhealthy, healthy_z_range=healthy_z_range,
                        contact_cost_range=contact_cost_range)  # fmt: skip
        self.include = {name: _flag(f"include_{name}_in_observation", value) for name, value in
                        (("cinert", include_cinert_in_observation), ("cvel", include_cvel_in_observation),
                         ("qfrc_actuator", include_qfrc_actuator_in_observation),
                         ("cfrc_ext", include_cfrc_ext_in_observation))}  # fmt: skip
        self._load(xml_file, frame_skip, reset_noise_scale, exclude_current_positions_from_observation)
        bodies, nv = len(self.body_links), self.init_qd.shape[0]
        widths = {"cinert": 10 * bodies, "cvel": 6 * bodies, "qfrc_actuator": nv - 6, "cfrc_ext": 6 * bodies}
        size = self.init_q.shape[0] + nv - 2 * self.exclude_current_positions
        self._observation_space(size + sum(widths[name] for name, on in self.include.items() if on))
        self._tendons = [(np.array(t.links), np.array(t.coefficients)) for t in self._template.tendons]

    def control_cost(self, actions):
        # Humanoid-v5 squares MuJoCo's ctrl (the action stored as float64), the other tasks the action as given
        return self.ctrl_cost_weight * np.sum(np.square(actions.astype(np.float64)), axis=1)

    def healthy(self, q, qd):
        """Gymnasium's ``is_healthy``: the root's height strictly within the range."""
        low, high = self.healthy_z_range
        return (low < q[:, 2]) & (q[:, 2] < high)

    def observe(self, q, qd, links=None, tau=None):
        # the motors' joint forces are MuJoCo's qfrc_actuator: tau holds them over the step (zero at a start)
        cinert, cvel, cfrc_ext = body_terms(links, self.body_links)
        count = q.shape[0]
        parts = {"cinert": cinert.reshape(count, -1), "cvel": cvel.reshape(count, -1),
                 "qfrc_actuator": tau[:, 6:], "cfrc_ext": cfrc_ext.reshape(count, -1)}  # fmt: skip
        return np.concatenate([self._positions(q), qd, *(parts[n] for n, on in self.include.items() if on)], axis=1)

    def outcome(self, start, actions, q, qd, links):
        cfrc_ext = body_terms(links, self.body_links)[2]
        xy_velocity = (centre_of_mass(links)[:, :2] - centre_of_mass(start[2])[:, :2]) / self.dt
        forward = self.forward_reward_weight * xy_velocity[:, 0]
        healthy = self.healthy(q, qd)
        survive = healthy * self.healthy_reward
        ctrl = self.control_cost(actions)
        contact = np.clip(self.contact_cost_weight * np.sum(np.square(cfrc_ext), axis=(1, 2)), *self.contact_cost_range)
        info = {**self._place_info(q), **self._tendon_info(q, qd), "x_velocity": xy_velocity[:, 0],
                "y_velocity": xy_velocity[:, 1], "reward_survive": survive, "reward_forward": forward,
                "reward_ctrl": -ctrl, "reward_contact": -contact}  # fmt: skip
        return forward + survive - ctrl - contact, self._ended(healthy), info

    def _tendon_info(self, q, qd) -> dict:
        """The fixed tendons' lengths and velocities (copies, tendons): ``Σ coefᵢ qᵢ`` over their joints."""
        length = np.zeros((q.shape[0], len(self._tendons)))
        velocity = np.zeros_like(length)
        for k, (links, coefficients) in enumerate(self._tendons):
            for link, coefficient in zip(links, coefficients, strict=True):
                start = self._template.links[link]
                length[:, k] += coefficient * q[:, start.q_slice.start]
                velocity[:, k] += coefficient * qd[:, start.v_slice.start]
        return {"tendon_length": length, "tendon_velocity": velocity}

    def reset_info(self, q, qd, links=None):
        return {**self._place_info(q), **self._tendon_info(q, qd)}
