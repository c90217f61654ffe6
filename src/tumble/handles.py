"""Body: a ``(world, row)`` view over the world's arrays, with no data of its own.

Getters return copies; setters validate and write the row. ``position`` is the body frame's origin (as
the user placed it); internally the state holds the centre of mass.
"""

from __future__ import annotations

import numpy as np

from ._validate import as_quaternion, as_rate, as_vector3, finite_result, listed
from .dynamics.joint_solver import DAMPING, LOWER, MAX_MOTOR, MOTOR_SPEED, TARGET, UPPER, JointKind
from .portable import dot, matmul, matvec
from .rotation import quat_rotate, quat_to_matrix

__all__ = ["Body", "Joint"]


class Body:
    """A rigid body of a :class:`~tumble.World` (dynamic or static)."""

    __slots__ = ("_world", "_index")

    def __init__(self, world, index: int):
        self._world = world
        self._index = index

    # --- identity -----------------------------------------------------------------------------------

    @property
    def index(self) -> int:
        """The body's row in the world's arrays."""
        return self._index

    @property
    def name(self) -> str | None:
        return self._world._builder.rows[self._index].name

    @property
    def is_static(self) -> bool:
        return self._world._builder.rows[self._index].mass_properties is None

    def _row(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(com, quat, linvel, angmom)``: writable views of this body's row (``World._body_row``)."""
        return self._world._body_row(self._index)

    def _mass(self) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
        """``(mass, com_local, inertia, inv_inertia)`` in the body frame (``World._mass_row``)."""
        return self._world._mass_row(self._index)

    def _refuse_static(self, what: str) -> None:
        if self.is_static:
            raise ValueError(f"{what}: body {self.name or self._index!r} is static and cannot move")

    def _require_dynamic(self, what: str) -> None:
        """Refuse to move a static body; wake a sleeping one (with its island), since it is about to move. A call
        that can still refuse its values checks them before this (a refused call must not wake anything)."""
        self._refuse_static(what)
        s = self._world._state
        if self._index < s.body_count and s.body_sleeping[self._index]:  # a body not yet stepped is awake
            island = s.body_island == s.body_island[self._index]
            s.body_sleeping[island] = False
            s.body_sleep_time[island] = 0.0

    @property
    def sleeping(self) -> bool:
        """Whether the body sleeps (is at rest and not simulated until touched or pushed)."""
        s = self._world._state
        return bool(self._index < s.body_count and s.body_sleeping[self._index])

    # --- pose and velocity --------------------------------------------------------------------------

    @property
    def position(self) -> np.ndarray:
        """The body frame's origin [m], world frame."""
        com, quat, _, _ = self._row()
        return com - quat_rotate(quat, self._mass()[1])

    @position.setter
    def position(self, value) -> None:
        value = as_vector3("position", value)
        self._refuse_static("position")
        com, quat, _, _ = self._row()
        with np.errstate(over="ignore", invalid="ignore"):
            com_position = value + quat_rotate(quat, self._mass()[1])
        finite_result(com_position, "position", value, "puts the centre of mass at")
        self._require_dynamic("position")
        com[:] = com_position

    @property
    def orientation(self) -> np.ndarray:
        """Unit quaternion ``[w, x, y, z]``, body to world."""
        return self._row()[1].copy()

    @orientation.setter
    def orientation(self, value) -> None:
        """Rotate the body about its frame origin (which stays where it is)."""
        quat = as_quaternion("orientation", value)
        self._require_dynamic("orientation")
        origin = self.position
        com, row_quat, _, _ = self._row()
        row_quat[:] = quat
        com[:] = origin + quat_rotate(quat, self._mass()[1])

    @property
    def rotation(self) -> np.ndarray:
        """The 3x3 rotation matrix, body to world."""
        return quat_to_matrix(self._row()[1])

    @property
    def center_of_mass(self) -> np.ndarray:
        """[m], world frame."""
        return self._row()[0].copy()

    @property
    def velocity(self) -> np.ndarray:
        """Velocity of the centre of mass [m/s], world frame."""
        return self._row()[2].copy()

    @velocity.setter
    def velocity(self, value) -> None:
        value = as_vector3("velocity", value)
        self._require_dynamic("velocity")
        self._row()[2][:] = value

    @property
    def angular_velocity(self) -> np.ndarray:
        """ω = R I⁻¹ Rᵀ L [rad/s], world frame (the state holds the angular momentum ``L``)."""
        r = self.rotation
        inv_inertia = self._mass()[3]
        return matvec(r, matvec(inv_inertia, matvec(r.T, self._row()[3])))

    @angular_velocity.setter
    def angular_velocity(self, value) -> None:
        value = as_rate("angular_velocity", value)
        self._refuse_static("angular_velocity")
        with np.errstate(over="ignore", invalid="ignore"):
            momentum = matvec(self.inertia_world, value)
        finite_result(momentum, "angular_velocity", value, "gives the angular momentum")
        self._require_dynamic("angular_velocity")
        self._row()[3][:] = momentum

    @property
    def angular_velocity_body(self) -> np.ndarray:
        """ω [rad/s] in the body frame, ``Rᵀ ω``."""
        return matvec(self.rotation.T, self.angular_velocity)

    def point_velocity(self, point) -> np.ndarray:
        """Velocity of the body-fixed point now at world ``point``: ``v + ω × (p − x_com)`` [m/s]."""
        point = as_vector3("point", point)
        com, _, linvel, _ = self._row()
        return linvel + np.cross(self.angular_velocity, point - com)

    # --- mass ---------------------------------------------------------------------------------------

    @property
    def mass(self) -> float:
        """[kg]; 0 for a static body."""
        return float(self._mass()[0])

    @property
    def inertia_body(self) -> np.ndarray:
        """Inertia tensor about the COM in the body frame [kg m²]."""
        return np.array(self._mass()[2])

    @property
    def inertia_world(self) -> np.ndarray:
        """``R I Rᵀ`` [kg m²], about the COM."""
        r = self.rotation
        return matmul(matmul(r, self._mass()[2]), r.T)

    @property
    def linear_momentum(self) -> np.ndarray:
        return self.mass * self.velocity

    @property
    def angular_momentum(self) -> np.ndarray:
        """``L = R I Rᵀ ω`` about the COM [kg m²/s], world frame."""
        return self._row()[3].copy()

    @property
    def kinetic_energy(self) -> float:
        """½ m |v|² + ½ ω·L [J]."""
        v = self.velocity
        return float(0.5 * self.mass * dot(v, v) + 0.5 * dot(self.angular_velocity, self.angular_momentum))

    # --- loads --------------------------------------------------------------------------------------

    def _lever(self, point) -> np.ndarray:
        if point is None:
            return np.zeros(3)
        with np.errstate(over="ignore", invalid="ignore"):  # an overflowing lever shows in the moment it gives
            return as_vector3("point", point) - self._row()[0]

    def apply_force(self, force, point=None) -> None:
        """Apply ``force`` [N] at world ``point`` (default the COM) during the next step only.

        Raises:
            ValueError: the force's moment, or its sum with the loads already applied for the step, overflows (the
                loads are then left as they were).
        """
        force = as_vector3("force", force)
        lever = self._lever(point)
        with np.errstate(over="ignore", invalid="ignore"):
            moment = np.cross(lever, force)
        finite_result(moment, "force", force, f"at point {listed(point)} has the moment")
        self._add_loads("apply_force", force, moment)

    def _add_loads(self, what: str, force: np.ndarray, torque: np.ndarray) -> None:
        """Add to the loads of the next step, both or neither: a sum that overflows is refused before anything is
        written or woken."""
        self._refuse_static(what)
        inputs, i = self._world.inputs, self._index
        totals = []
        for added, pending, unit in ((force, inputs.body_force[i], "N"), (torque, inputs.body_torque[i], "N m")):
            with np.errstate(over="ignore", invalid="ignore"):
                totals.append(pending + added)
            if not np.isfinite(totals[-1]).all():
                raise ValueError(
                    f"{what}: adding {listed(added)} to the {listed(pending)} {unit} already applied to body "
                    f"{self.name or i!r} for the next step overflows (non-finite)"
                )
        self._require_dynamic(what)
        inputs.body_force[i], inputs.body_torque[i] = totals

    @property
    def constant_force(self) -> np.ndarray:
        """(3,) [N] a force that acts at the centre of mass in every step (world frame; settable; zero by
        default): thrust, wind, a spring to a fixed point's rest force. ``apply_force`` acts in one step."""
        return self._world._builder.rows[self._index].constant_force.copy()

    @constant_force.setter
    def constant_force(self, value) -> None:
        self._set_constant("constant_force", as_vector3("constant_force", value))

    @property
    def constant_torque(self) -> np.ndarray:
        """(3,) [N m] a torque that acts in every step (world frame; settable; zero by default)."""
        return self._world._builder.rows[self._index].constant_torque.copy()

    @constant_torque.setter
    def constant_torque(self, value) -> None:
        self._set_constant("constant_torque", as_vector3("constant_torque", value))

    def _set_constant(self, name: str, value: np.ndarray) -> None:
        self._require_dynamic(name)
        setattr(self._world._builder.rows[self._index], name, value)
        model = self._world._model
        if model is not None:
            getattr(model, f"body_{name}")[self._index] = value

    def apply_torque(self, torque) -> None:
        """Apply ``torque`` [N m] (world frame) during the next step only.

        Raises:
            ValueError: its sum with the torques already applied for the step overflows (they are left as they were).
        """
        self._add_loads("apply_torque", np.zeros(3), as_vector3("torque", torque))

    def apply_impulse(self, impulse, point=None) -> None:
        """Change the momenta at once: ``Δp = J``, ``ΔL = r × J`` (so ``Δv = J / m``, ``Δω = I_w⁻¹ (r × J)``).

        Raises:
            ValueError: the velocity, angular momentum or angular velocity it would give overflows (the body is then
                left as it was).
        """
        impulse = as_vector3("impulse", impulse)
        lever = self._lever(point)
        self._refuse_static("apply_impulse")
        inv_mass = 1.0 / self.mass  # as the model's body_inv_mass holds it
        _, _, linvel, angmom = self._row()
        r = self.rotation
        with np.errstate(over="ignore", invalid="ignore"):
            velocity, momentum = linvel + impulse * inv_mass, angmom + np.cross(lever, impulse)
            omega = matvec(r, matvec(self._mass()[3], matvec(r.T, momentum)))
        velocity = finite_result(velocity, "impulse", impulse, f"on a body of {self.mass:g} kg gives the velocity")
        finite_result(momentum, "impulse", impulse, f"at point {listed(point)} gives the angular momentum")
        finite_result(omega, "impulse", impulse, "gives the angular velocity")
        self._require_dynamic("apply_impulse")
        linvel[:], angmom[:] = velocity, momentum

    def __eq__(self, other) -> bool:
        return isinstance(other, Body) and other._world is self._world and other._index == self._index

    def __hash__(self) -> int:
        return hash((id(self._world), self._index))

    def __repr__(self) -> str:
        kind = "static" if self.is_static else f"mass={self.mass:.6g}"
        label = f"{self.name!r}, " if self.name else ""
        return f"Body({label}#{self._index}, {kind}, position={np.round(self.position, 6).tolist()})"


class Joint:
    """A joint of a :class:`~tumble.World`: a ``(world, row)`` view, as :class:`Body` is.

    Coordinates (``angle``, ``translation``, ``length``) are those of ``b`` relative to ``a``, or of ``a``
    relative to the world when ``b`` is None. ``reaction_force`` and ``reaction_torque`` are what the joint
    exerted on body ``a`` over the last step (its average: impulse / dt), in the world frame, the torque about the
    anchor; body ``b`` (or the world) received the opposite. Both are zero before the first step.
    """

    __slots__ = ("_world", "_index")

    def __init__(self, world, index: int):
        self._world = world
        self._index = index

    @property
    def index(self) -> int:
        return self._index

    def _spec(self):
        return self._world._builder.joints[self._index]

    @property
    def kind(self) -> str:
        """``"ball"``, ``"hinge"``, ``"slider"``, ``"fixed"``, ``"distance"``, ``"planar"`` or ``"universal"``."""
        return JointKind(self._spec().kind).name.lower()

    @property
    def body_a(self) -> Body:
        spec = self._spec()
        return self._world.bodies[spec.body_b if spec.to_world else spec.body_a]

    @property
    def body_b(self) -> Body | None:
        """The second body, or None when the joint holds ``a`` to the world."""
        spec = self._spec()
        return None if spec.to_world else self._world.bodies[spec.body_b]

    def _anchor(self, body: int, local: np.ndarray) -> np.ndarray:
        if body < 0:
            return local.copy()
        com, quat, _, _ = self._world._body_row(body)
        return com + quat_rotate(quat, local)

    @property
    def anchor_a(self) -> np.ndarray:
        """(3,) the anchor carried by ``a``, world frame [m]."""
        spec = self._spec()
        if spec.to_world:
            return self._anchor(spec.body_b, spec.local_anchor_b)
        return self._anchor(spec.body_a, spec.local_anchor_a)

    @property
    def anchor_b(self) -> np.ndarray:
        """(3,) the anchor carried by ``b`` (fixed in the world when ``b`` is None), world frame [m]."""
        spec = self._spec()
        if spec.to_world:
            return self._anchor(spec.body_a, spec.local_anchor_a)
        return self._anchor(spec.body_b, spec.local_anchor_b)

    def _coordinates(self) -> np.ndarray:
        from .dynamics.joint_solver import joint_coordinates

        world = self._world
        model, state = world.model, world.state
        out = np.zeros((1, 5))
        joint_coordinates(model.joints, state.body_pos, state.body_quat, state.body_linvel,
                          world.angular_velocities(), self._index, self._index + 1, out)  # fmt: skip
        return out[0]

    def _require(self, *kinds: str) -> None:
        if self.kind not in kinds:
            raise AttributeError(f"a {self.kind} joint has no such coordinate (only {' and '.join(kinds)} joints)")

    @property
    def angle(self) -> float:
        """Hinge: the angle of ``b`` relative to ``a`` about the axis [rad], zero at creation, in (−π, π]."""
        self._require("hinge")
        return float(self._coordinates()[0])

    @property
    def angular_speed(self) -> float:
        """Hinge: d(angle)/dt [rad/s]."""
        self._require("hinge")
        return float(self._coordinates()[1])

    @property
    def twist(self) -> float:
        """Ball joint: the twist of ``b`` relative to ``a`` about the joint's axis [rad], in (−π, π]."""
        self._require("ball")
        return float(self._coordinates()[0])

    @property
    def swing(self) -> float:
        """Ball joint: the angle between the two bodies' joint axes [rad] (bounded by ``cone_angle``)."""
        self._require("ball")
        return float(self._coordinates()[4])

    @property
    def translation(self) -> float:
        """Slider: how far ``b``'s anchor has moved along the axis from ``a``'s [m], zero at creation."""
        self._require("slider")
        return float(self._coordinates()[0])

    @property
    def speed(self) -> float:
        """Slider: d(translation)/dt [m/s]; distance joint: d(length)/dt."""
        self._require("slider", "distance")
        return float(self._coordinates()[1])

    @property
    def length(self) -> float:
        """Distance joint: the distance between the anchors now [m]."""
        self._require("distance")
        return float(self._coordinates()[0])

    @property
    def position_error(self) -> float:
        """How far the joint is from holding [m]: the gap between the anchors (ball, hinge, fixed, universal), its
        part across the axis (slider) or along the normal (planar), or how far the length lies outside
        ``[min_length, max_length]`` (distance)."""
        value, _, gap, _, _ = self._coordinates()
        if self.kind == "planar":
            return float(abs(value))
        if self.kind == "slider":
            return float(np.sqrt(max(gap**2 - value**2, 0.0)))
        if self.kind == "distance":
            lower, upper = self._spec().drive[[LOWER, UPPER]]
            return float(max(lower - value, value - upper, 0.0))
        return float(gap)

    @property
    def angular_error(self) -> float:
        """Misalignment [rad]: hinge axes (planar normals) apart, a universal joint's axes off perpendicular, or the
        relative rotation of a fixed or slider joint; 0 else."""
        return float(self._coordinates()[3])

    @property
    def reaction_force(self) -> np.ndarray:
        """(3,) [N] the force the joint exerted on ``a`` over the last step (world frame)."""
        scratch = self._world._scratch
        if scratch.joint_step == 0.0 or self._index >= scratch.joint_force_total.shape[0]:
            return np.zeros(3)
        return self._on_a(scratch.joint_force_total[self._index]) / scratch.joint_step

    @property
    def reaction_torque(self) -> np.ndarray:
        """(3,) [N m] the torque the joint exerted on ``a`` about the anchor over the last step (world frame)."""
        scratch = self._world._scratch
        if scratch.joint_step == 0.0 or self._index >= scratch.joint_moment_total.shape[0]:
            return np.zeros(3)
        return self._on_a(scratch.joint_moment_total[self._index]) / scratch.joint_step

    def _on_a(self, received_by_b: np.ndarray) -> np.ndarray:
        """The solver sums what its body b received: the user's ``a`` when joined to the world, else ``b``."""
        return received_by_b.copy() if self._spec().to_world else -received_by_b

    def _set_drive(self, column: int, name: str, value, kinds: tuple[str, ...], nonnegative: bool = False) -> None:
        from ._validate import as_float

        self._require(*kinds)
        value = as_float(name, value, nonnegative=nonnegative)
        self._spec().drive[column] = value
        model = self._world._model
        if model is not None:
            model.joints.drive[self._index, column] = value
        self._wake()

    def _wake(self) -> None:
        for body in (self.body_a, self.body_b):
            if body is not None and not body.is_static:
                body._require_dynamic("wake")

    @property
    def motor_speed(self) -> float:
        """Hinge [rad/s] or slider [m/s]: the motor's target speed (settable)."""
        return float(self._spec().drive[MOTOR_SPEED])

    @motor_speed.setter
    def motor_speed(self, value) -> None:
        self._set_drive(MOTOR_SPEED, "motor_speed", value, ("hinge", "slider"))

    @property
    def max_motor_torque(self) -> float:
        """Hinge: the motor's largest torque [N m] (settable; 0 turns the motor off)."""
        self._require("hinge")
        return float(self._spec().drive[MAX_MOTOR])

    @max_motor_torque.setter
    def max_motor_torque(self, value) -> None:
        self._set_drive(MAX_MOTOR, "max_motor_torque", value, ("hinge",), nonnegative=True)

    @property
    def max_motor_force(self) -> float:
        """Slider: the motor's largest force [N] (settable; 0 turns the motor off)."""
        self._require("slider")
        return float(self._spec().drive[MAX_MOTOR])

    @max_motor_force.setter
    def max_motor_force(self, value) -> None:
        self._set_drive(MAX_MOTOR, "max_motor_force", value, ("slider",), nonnegative=True)

    @property
    def spring_target(self) -> float:
        """Hinge [rad] or slider [m]: where the spring pulls (settable)."""
        return float(self._spec().drive[TARGET])

    @spring_target.setter
    def spring_target(self, value) -> None:
        self._set_drive(TARGET, "spring_target", value, ("hinge", "slider"))

    @property
    def damping(self) -> float:
        """Hinge [N m s/rad] or slider [N s/m]: the damping against its rate (settable)."""
        self._require("hinge", "slider")
        return float(self._spec().drive[DAMPING])

    @damping.setter
    def damping(self, value) -> None:
        self._set_drive(DAMPING, "damping", value, ("hinge", "slider"), nonnegative=True)

    def __eq__(self, other) -> bool:
        return isinstance(other, Joint) and other._world is self._world and other._index == self._index

    def __hash__(self) -> int:
        return hash((id(self._world), self._index))

    def __repr__(self) -> str:
        b = self.body_b
        label_a = self.body_a.name or self.body_a.index
        label_b = "world" if b is None else (b.name or b.index)
        return f"Joint(#{self._index}, {self.kind}, a={label_a!r}, b={label_b!r})"


def as_body(value):
    """A body handle (``world.add_body``'s answer)."""
    if not isinstance(value, Body):
        raise TypeError(f"body must be a tumble.Body (from world.add_body), got {value!r}")
    return value


def as_new_part(world, part, kind: type, name: str, article: str, described: str):
    """``part`` (an actuator, a sensor), a ``kind``, in no world yet, on a dynamic body of ``world``; ``name`` and
    its ``article`` name it in messages, ``described`` says what it must be."""
    if not isinstance(part, kind):
        raise TypeError(f"{name} must be {described}, got {part!r}")
    if part._world is not None:
        raise ValueError(f"{part!r} is in a world already")
    as_dynamic_body_of(world, part.body, f"{article} {name}")
    return part


def as_dynamic_body_of(world, value, what: str):
    """A body of ``world`` that moves, for ``what`` (an actuator, a sensor, drag) to act on or read."""
    body = as_body(value)
    name = body.name or body.index
    if body._world is not world:
        raise ValueError(f"body {name!r} belongs to another world; {what} needs a body of this one")
    if body.is_static:
        raise ValueError(f"body {name!r} is static: {what} needs a dynamic body")
    return body
