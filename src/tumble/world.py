"""World: the Pythonic facade over the model, state and inputs arrays.

``add_*`` calls write rows to a :class:`~tumble.builder.ModelBuilder`; the model is packed once, before the
first step or query that needs it, so building costs linear time. A handle reads and writes its own row (the
builder's, or the state's once the row is there) without packing anything. ``world.state`` exposes the arrays
for batch work; reading it appends the rows of bodies added since (re-read it after adding bodies: adding
reallocates them), without packing the model.
"""

from __future__ import annotations

import math

import numpy as np

from . import diagnostics, world_stepping
from ._validate import (
    as_array,
    as_filter,
    as_float,
    as_material,
    as_quaternion,
    as_rate,
    as_vector3,
    finite_result,
)
from .actuators import Actuation, Actuator
from .builder import ModelBuilder
from .controllers import Controller, Controllers, StepClock
from .handles import Body, Joint
from .inputs import Inputs
from .mass import MassProperties, require_invertible
from .model import Model
from .params import DEFAULT_SOLVER, Params, SolverSettings, solver_with
from .queries import Contacts, RayHit, first_ray_hit, overlapping_bodies
from .rotation import quat_rotate
from .scratch import Scratch
from .sensors import Sensor, Sensors
from .state import State
from .trajectory import Trajectory
from .wind import Wind, as_wind
from .world_building import (
    NO_ROTATION,
    ORIGIN,
    body_mass_properties,
    check_dynamic_shapes,
    check_integrator,
    checked_name,
    explicit_mass_properties,
    shape_items,
    vector_or_origin,
    world_apply,
)

__all__ = ["World"]


class World:
    """A set of rigid bodies under gravity.

    Args:
        gravity: (3,) [m/s²], world frame.
        integrator: ``"auto"`` (default: RK4 in momentum form while nothing couples the bodies), ``"rk4"``,
            ``"midpoint"`` (Lie–Poisson implicit midpoint: energy and L conserved to round-off),
            ``"symplectic"`` (semi-implicit Euler) or ``"euler"`` (explicit, as in the course notes).
            ``docs/integrators.md`` says which to use when.
    """

    def __init__(
        self,
        gravity=(0.0, 0.0, -9.81),
        *,
        integrator: str = "auto",
        substeps: int = DEFAULT_SOLVER.substeps,
        contact_hertz: float = DEFAULT_SOLVER.contact_hertz,
        contact_damping_ratio: float = DEFAULT_SOLVER.contact_damping_ratio,
        contact_push_max: float = DEFAULT_SOLVER.contact_push_max,
        restitution_threshold: float = DEFAULT_SOLVER.restitution_threshold,
        speculative_distance: float = DEFAULT_SOLVER.speculative_distance,
        sleep: bool = DEFAULT_SOLVER.sleep,
        joint_hertz: float = DEFAULT_SOLVER.joint_hertz,
        joint_damping_ratio: float = DEFAULT_SOLVER.joint_damping_ratio,
    ):
        self._gravity = as_vector3("gravity", gravity)
        self._params = Params(integrator=check_integrator(integrator))
        self.set_solver(
            substeps=substeps,
            contact_hertz=contact_hertz,
            contact_damping_ratio=contact_damping_ratio,
            contact_push_max=contact_push_max,
            restitution_threshold=restitution_threshold,
            speculative_distance=speculative_distance,
            sleep=sleep,
            joint_hertz=joint_hertz,
            joint_damping_ratio=joint_damping_ratio,
        )
        self._builder = ModelBuilder()
        self._model: Model | None = None
        self._state = State.empty(0)
        self._inputs = Inputs.zeros(0)
        self._scratch = Scratch.for_world(0, 0)
        # The rows of bodies added since the state last grew: their COM, quat, linvel and angmom, a list each.
        self._pending: tuple[list[np.ndarray], ...] = ([], [], [], [])
        self._bodies: list[Body] = []
        self._joints: list[Joint] = []
        self._controllers = Controllers()
        self._clock = StepClock()
        self._actuation = Actuation()
        self._sensors = Sensors()
        self._wind: Wind | None = None
        self._attachments: list = []  # what attach() registered: vehicles (tumble.vehicles.Quadrotor)
        self._joint_drives = None  # tumble.joint_drives.JointDrives, made with the first joint actuator
        self._last_dt, self._substeps_told = None, set()  # the last step's dt; the (asked, raised) substeps told

    @classmethod
    def _from_builder(cls, builder: ModelBuilder, state: State, inputs: Inputs, *, gravity, params: Params) -> World:
        """A world over a filled builder and the state of its rows (a checkpoint's): handles made, model packed."""
        world = cls(gravity=gravity, integrator=params.integrator)
        world.set_solver(**params.solver._asdict())  # checked as a user's settings would be
        world._builder = builder
        world._bodies = [Body(world, i) for i in range(builder.body_count)]
        world._joints = [Joint(world, i) for i in range(len(builder.joints))]
        world._state, world._inputs = state, inputs
        world._sync()
        return world

    # --- building -----------------------------------------------------------------------------------

    def add_body(
        self,
        shape=None,
        *,
        mass=None,
        density=None,
        inertia=None,
        position=ORIGIN,
        orientation=NO_ROTATION,
        velocity=ORIGIN,
        angular_velocity=ORIGIN,
        friction: float = 0.5,
        restitution: float = 0.0,
        rolling_resistance: float = 0.0,
        linear_damping: float = 0.0,
        angular_damping: float = 0.0,
        collision_group: int = 1,
        collision_mask: int = 0xFFFFFFFF,
        name: str | None = None,
        mass_properties: MassProperties | None = None,
    ) -> Body:
        """Add a dynamic body. ``velocity`` is that of the centre of mass.

        ``shape`` is a :class:`~tumble.Shape`, a list of ``(shape, position[, orientation])`` in the body frame
        (a compound body), or ``None`` with ``mass=`` and ``inertia=``. Two shapes collide when
        ``collision_group & other.collision_mask`` and ``other.collision_group & collision_mask`` are both
        non-zero; ``collision_mask=0`` turns collisions off for this body. ``friction`` (Coulomb μ, mixed as
        ``√(μa μb)``), ``restitution`` (in [0, 1], mixed as the larger) and ``rolling_resistance`` (the coefficient
        ``c`` of a resisting torque ``c N r`` on round shapes of radius ``r``, mixed as the larger) apply to all
        of the body's shapes; see ``docs/contact.md``. ``mass_properties`` (a :class:`~tumble.MassProperties` in
        the body frame) gives mass, centre of mass and inertia at once, in place of ``mass``/``density``/``inertia``.
        """
        position = vector_or_origin("position", position)
        quat = np.array(NO_ROTATION) if orientation is NO_ROTATION else as_quaternion("orientation", orientation)
        velocity = vector_or_origin("velocity", velocity)
        angular_velocity = np.zeros(3) if angular_velocity is ORIGIN else as_rate("angular_velocity", angular_velocity)
        material = as_material(friction, restitution, rolling_resistance)
        linear_damping = as_float("linear_damping", linear_damping, nonnegative=True)
        angular_damping = as_float("angular_damping", angular_damping, nonnegative=True)
        name = checked_name(self._builder, name)
        group, mask = as_filter("collision_group", collision_group), as_filter("collision_mask", collision_mask)
        items = shape_items(shape, material, group, mask)
        check_dynamic_shapes(shape)
        mp = explicit_mass_properties(mass_properties, mass, density, inertia)
        if mp is None:
            mp = body_mass_properties(items, mass, density, inertia)
        require_invertible(mp)
        # Skipping the rotations of zero vectors (the usual COM at the origin, a body at rest) keeps building cheap.
        com, angmom = position, np.zeros(3)
        if mp.com.any():
            with np.errstate(over="ignore", invalid="ignore"):
                com = finite_result(position + quat_rotate(quat, mp.com), "position", position,
                                    "puts the centre of mass at")  # fmt: skip
        if angular_velocity.any():
            angmom = world_apply(mp.inertia, quat, angular_velocity)
            finite_result(angmom, "angular_velocity", angular_velocity, "gives the angular momentum")
        index = self._builder.add_body(
            mp, items, linear_damping=linear_damping, angular_damping=angular_damping, name=name
        )
        return self._append(index, com, quat, velocity, angmom)

    def add_static(
        self,
        shape,
        *,
        position=(0.0, 0.0, 0.0),
        orientation=(1.0, 0.0, 0.0, 0.0),
        friction: float = 0.5,
        restitution: float = 0.0,
        rolling_resistance: float = 0.0,
        collision_group: int = 1,
        collision_mask: int = 0xFFFFFFFF,
        name: str | None = None,
    ) -> Body:
        """Add fixed geometry (a plane, a mesh, any shape, or a compound list); it never moves."""
        if shape is None:
            raise TypeError("add_static needs a shape, got None")
        position = as_vector3("position", position)
        quat = as_quaternion("orientation", orientation)
        material = as_material(friction, restitution, rolling_resistance)
        name = checked_name(self._builder, name)
        group, mask = as_filter("collision_group", collision_group), as_filter("collision_mask", collision_mask)
        items = shape_items(shape, material, group, mask)
        index = self._builder.add_body(None, items, name=name)
        return self._append(index, position, quat, np.zeros(3), np.zeros(3))

    def add_joint(self, joint) -> Joint:
        """Join two bodies (or a body and the world) with a :class:`~tumble.BallJoint`, :class:`~tumble.HingeJoint`,
        :class:`~tumble.SliderJoint`, :class:`~tumble.FixedJoint` or :class:`~tumble.DistanceJoint`.

        The joint's anchors and axes are world-frame values taken at the bodies' current poses; the two bodies
        stop colliding with each other unless ``collide_connected=True``. Returns a :class:`~tumble.handles.Joint`
        handle (angles, reaction forces, motor settings); see ``docs/joints.md``.
        """
        from .joints import joint_spec

        spec = joint_spec(joint, self)
        index = self._builder.add_joint(spec)
        self._model = None
        handle = Joint(self, index)
        self._joints.append(handle)
        handle._wake()
        return handle

    def add_articulation(self, articulation):
        """Copy a :class:`~tumble.articulation.Articulation` at its current ``q``, ``qd`` into this world: its links
        become bodies that collide with the rest, its joints world joints (maximal coordinates, solved with the
        contacts). Returns a :class:`~tumble.world_articulation.WorldArticulation` that reads ``q`` and ``qd``
        back and applies joint forces; see ``docs/joints.md``."""
        from .world_articulation import add_articulation

        return add_articulation(self, articulation)

    def add_controller(self, callback, rate: float | None = None, name: str | None = None) -> Controller:
        """Run ``callback(world, t)`` before each step, or with ``rate`` (Hz) before the first step at or past each
        tick ``k / rate``; what it commands holds until its next call. ``t`` is the step's start time, counted as
        steps of ``dt`` (see ``tumble.control``). Returns a handle with ``.remove()``. A controller that raises
        stops ``step``/``simulate`` with a :class:`SimulationError` naming it and the time."""
        self._scratch.ready = None  # the prepared step (world_stepping.step) runs no controllers
        return self._controllers.add(callback, rate, name)

    def add_actuator(self, actuator: Actuator) -> Actuator:
        """Fix a :class:`~tumble.actuators.Rotor` or :class:`~tumble.actuators.Thruster` to its (dynamic) body;
        returns it, now the handle through which it is commanded and read. Its loads act inside every step."""
        return self._actuation.add(self, actuator)

    @property
    def actuators(self) -> list[Actuator]:
        """The actuators, in the order added."""
        return list(self._actuation.actuators)

    def add_joint_actuator(self, joint: Joint, *, gear=1.0, gain=1.0, bias=(0.0, 0.0, 0.0), ctrl_range=None,
                           ref=0.0, name: str | None = None, coordinate: int = 0, axes=None):  # fmt: skip
        """Drive a hinge, slider, universal or ball joint from ``world.ctrl`` (its new last entry, starting at 0);
        returns its record.

        The actuator pulls along its length ``l = gear · (ref + q)`` (``q`` the joint's angle or translation, zero
        at its creation; ``ref`` the coordinate that is, MJCF's ``ref``) with ``f = gain · c + bias[0] + bias[1] l
        + bias[2] l̇`` (``c`` the control clipped to ``ctrl_range``) and turns (pushes) the joint's second body with
        ``gear · f``, the first with the opposite: a motor is the default, a position servo ``gain=kp, bias=(0,
        -kp, -kv)``, a velocity servo ``gain=kv, bias=(0, 0, -kv)`` (``tumble/joint_drives.py``). The loads are
        worked out before each step and held through it.

        A universal joint's ``coordinate`` 0 or 1 is its turn about ``axis_a`` or ``axis_b``; ``b``'s rotation
        relative to ``a`` (``a``'s relative to the world when ``b`` is None) is the turn about the reference side's
        axis, then the other's. A ball joint's are three angles about ``axes`` ((3, 3), orthonormal rows, world
        frame now), turned in order as MuJoCo turns a body's three hinges: the first axis carried by the reference
        side (``a``, or the world when ``b`` is None), the last by the other; all zero at the joint's creation."""
        from .joint_drives import JointDrives, checked_drive

        settings = checked_drive(self, joint, gear, gain, bias, ctrl_range, ref, coordinate, axes)
        if self._joint_drives is None:
            self._joint_drives = JointDrives()
        return self._joint_drives.add(self, joint, name=name, **settings)

    @property
    def ctrl(self) -> np.ndarray:
        """(number of joint actuators,) their controls (a copy), held until set again."""
        return np.zeros(0) if self._joint_drives is None else self._joint_drives.ctrl.copy()

    @ctrl.setter
    def ctrl(self, value) -> None:
        size = 0 if self._joint_drives is None else len(self._joint_drives.drives)
        values = np.array(as_array("ctrl", value, (size,), batch=False), dtype=float)
        if size:
            self._joint_drives.ctrl = values

    def actuator_forces(self) -> np.ndarray:
        """Each joint actuator's force along its length now, before its gear (MuJoCo's ``actuator_force``)."""
        return np.zeros(0) if self._joint_drives is None else self._joint_drives.forces(self)

    def add_drag(self, body: Body, coefficients) -> None:
        """Parasitic drag on ``body``: the force ``−c ⊙ |v_air| v_air`` at its COM, in its frame, with ``c =
        coefficients`` (cx, cy, cz) [kg/m] and ``v_air`` its velocity relative to the wind. Called again for a body,
        it replaces the coefficients."""
        self._actuation.add_drag(self, body, coefficients)

    def add_sensor(self, sensor: Sensor) -> Sensor:
        """Add a :class:`~tumble.sensors.IMU` or :class:`~tumble.sensors.Pose`; returns it, to ``read()``. It samples
        at the end of every step."""
        self._scratch.ready = None  # nor sensors
        return self._sensors.add(self, sensor)

    @property
    def sensors(self) -> list[Sensor]:
        """The sensors: the IMUs, then the pose sensors, each in the order added."""
        return list(self._sensors)

    @property
    def wind(self) -> Wind | None:
        """The air's velocity that rotors and drag see: ``None`` (still air, the default), a
        :class:`~tumble.wind.Constant`, :class:`~tumble.wind.Sinusoid` or :class:`~tumble.wind.Dryden` model, or
        a 3-vector (a constant wind) [m/s]."""
        return self._wind

    @wind.setter
    def wind(self, value) -> None:
        self._wind = as_wind(value)
        self._scratch.ready = None  # as a controller or sensor added: the next step takes the path that runs it

    def attach(self, attachment) -> None:
        """Register ``attachment``, an object that plugs into this world's step through its public interface (a
        vehicle: ``tumble.vehicles.Quadrotor`` attaches itself). The viewer, recordings, scene files and MJCF export
        find vehicles here. ``docs/step.md`` says what an attachment may add to the step."""
        if attachment in self._attachments:
            raise ValueError(f"{attachment!r} is attached to this world already")
        self._attachments.append(attachment)

    @property
    def attachments(self) -> tuple:
        """What :meth:`attach` registered, in order."""
        return tuple(self._attachments)

    @property
    def controllers(self) -> list[Controller]:
        """The controllers, in the order they run."""
        return list(self._controllers)

    def to_scene(self, *, dt: float | None = None, duration: float | None = None) -> dict:
        """This world now as a scene dict, the structure of a scene file (``tumble.scene_file.dumps`` writes it as
        TOML or JSON; ``tumble.scene_file.from_dict`` builds it again)."""
        from .io.scene_dump import world_to_scene as to_scene

        return to_scene(self, dt=dt, duration=duration)

    def to_mjcf(self, *, timestep: float | None = None) -> str:
        """This world now as MJCF text, to be cross-checked in MuJoCo: joints as MuJoCo's body tree, loops as
        equality constraints, exact mass properties, the present velocities as the keyframe ``now``; what MJCF
        cannot say is refused with a ``ValueError`` naming it (``tumble/io/mjcf_export.py``)."""
        from .io.mjcf_export import world_to_mjcf

        if timestep is not None:
            timestep = as_float("timestep", timestep, positive=True)
        return world_to_mjcf(self, timestep=timestep)

    @property
    def joints(self) -> list[Joint]:
        """Every joint, in the order they were added."""
        return list(self._joints)

    def _append(self, index, com, quat, velocity, angmom) -> Body:
        """The new body's handle; its (3,) and (4,) float64 arrays must be fresh: the world owns them from now."""
        for column, value in zip(self._pending, (com, quat, velocity, angmom), strict=True):
            column.append(value)
        self._model = None
        body = Body(self, index)
        self._bodies.append(body)
        return body

    def _body_row(self, index: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(com, quat, linvel, angmom)`` of one body as writable views, whether or not its row has reached the
        state yet: what a handle reads and writes while the world is being built, without growing the state or
        rebuilding the model (which would make building quadratic)."""
        s = self._state
        if index < s.body_count:
            return s.body_pos[index], s.body_quat[index], s.body_linvel[index], s.body_angmom[index]
        row = index - s.body_count
        return tuple(column[row] for column in self._pending)

    def _mass_row(self, index: int) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
        """``(mass, com, inertia, inv_inertia)`` of one body, body frame: the model's row when it is built, else the
        builder's (so that a handle's read never builds the model)."""
        m = self._model
        if m is None:
            return self._builder.mass_row(index)
        return m.body_mass[index], m.body_com_local[index], m.body_inertia_local[index], m.body_inv_inertia_local[index]

    def _grow(self) -> None:
        """Append the state and input rows of the bodies added since, and zero impulses for the joints added since;
        the model is left as it is."""
        if self._pending[0]:
            self._state = self._state.grown(*(np.array(column) for column in self._pending))
            self._inputs = self._inputs.grown(len(self._pending[0]))
            for column in self._pending:
                column.clear()
        self._state.with_joints(len(self._builder.joints))

    def _sync(self) -> None:
        """Grow the state and build the model once after ``add_*`` calls, before a step or a query needs them."""
        self._grow()
        if self._model is not None:
            return
        self._model = self._builder.finalize(self._gravity)
        self._scratch = Scratch.for_world(self._model.body_count, self._model.shape_count, self._model.joint_count)

    # --- arrays -------------------------------------------------------------------------------------

    @property
    def model(self) -> Model:
        """The static arrays (masses, inertias, shapes)."""
        self._sync()
        return self._model

    @property
    def state(self) -> State:
        """The dynamic arrays (``body_pos`` is the COM); views, for batch reads and writes."""
        self._grow()
        return self._state

    @property
    def inputs(self) -> Inputs:
        """The applied forces and torques of the next step."""
        self._grow()
        return self._inputs

    @property
    def bodies(self) -> list[Body]:
        """Every body, dynamic and static, in the order they were added."""
        return list(self._bodies)

    def body(self, name: str) -> Body:
        """The body called ``name``."""
        index = self._builder.index_of(name) if isinstance(name, str) else None
        if index is None:
            raise KeyError(f"no body named {name!r}; names: {sorted(self._builder.names)}")
        return self._bodies[index]

    @property
    def gravity(self) -> np.ndarray:
        return self._gravity.copy()

    @gravity.setter
    def gravity(self, value) -> None:
        self._gravity = as_vector3("gravity", value)
        self._model = None

    @property
    def solver(self) -> SolverSettings:
        """The contact solver's settings (read-only; change them with :meth:`set_solver`)."""
        return self._params.solver

    @property
    def substeps(self) -> int:
        """The substeps a step runs: those asked, or more where the last step's ``dt`` is too long for contacts of
        ``contact_hertz`` (a ``tumble.SubstepsRaisedWarning`` said so, once; ``docs/contact.md``)."""
        return world_stepping.substeps_run(self)

    def set_solver(self, **settings) -> None:
        """Change contact solver settings by name: ``substeps`` (int >= 1; a step takes more where contacts of
        ``contact_hertz`` need them, 8 per contact period, saying so once: ``World.substeps``), ``contact_hertz`` (> 0),
        ``contact_damping_ratio`` (>= 0), ``contact_push_max`` [m/s] (> 0; joint limits push a joint outside its range
        back at most this fast too, in rad/s for angles), ``restitution_threshold`` [m/s] (>= 0),
        ``speculative_distance`` [m] (>= 0), ``sleep`` (bool), ``sleep_linear`` [m/s], ``sleep_angular`` [rad/s],
        ``time_to_sleep`` [s] (all >= 0), ``joint_hertz`` (> 0; capped at a quarter of the substep rate, and the
        default ``inf`` means that cap: 120 Hz at 60 Hz with 8 substeps) and ``joint_damping_ratio`` (>= 0), the
        stiffness of the joints' position correction."""
        self._params.solver = solver_with(self._params.solver, settings)

    @property
    def integrator(self) -> str:
        return self._params.integrator

    @integrator.setter
    def integrator(self, value: str) -> None:
        self._params.integrator = check_integrator(value)

    @property
    def time(self) -> float:
        return self._state.time

    @property
    def step_count(self) -> int:
        return self._state.step_count

    # --- stepping (world_stepping.py: the controllers, the compiled stages and sensors around the runner) -----

    def step(self, dt: float) -> None:
        """Advance one step of ``dt`` seconds. Applied forces act during this step only.

        Raises:
            ValueError: ``dt`` does not advance the time, or its contacts would need more than 65 536 substeps
                (``solver.substeps_for(dt)``); nothing has moved.
            SimulationError: the step produced a non-finite value; the world keeps its state from before, and the
                loads applied for the step are dropped (so that the next step can succeed).
        """
        world_stepping.step(self, dt)

    def simulate(self, duration: float, dt: float, record_every: int = 1) -> Trajectory:
        """Take ``round(duration / dt)`` steps in one compiled loop, recording every ``record_every`` steps.

        The trajectory starts with the current state. On a :class:`SimulationError` the world keeps its last
        good state and the error's ``trajectory`` holds the frames recorded up to it.
        """
        return world_stepping.simulate(self, duration, dt, record_every)

    # --- diagnostics --------------------------------------------------------------------------------

    def angular_velocities(self) -> np.ndarray:
        """ω = R I⁻¹ Rᵀ L of every body: (body_count, 3) [rad/s], world frame (zeros for static bodies)."""
        m, s = self.model, self._state
        return diagnostics.world_tensor_apply(m.body_inv_inertia_local, s.body_quat, s.body_angmom)

    def kinetic_energy(self) -> float:
        """Σ ½ m |v|² + ½ ω·L [J]."""
        omega = self.angular_velocities()
        s = self._state
        return float(diagnostics.kinetic_energy(self._model.body_mass, s.body_linvel, omega, s.body_angmom).sum())

    def potential_energy(self) -> float:
        """Gravitational potential energy −Σ m g·x_com [J] (zero at the origin)."""
        return float(diagnostics.potential_energy(self.model.body_mass, self._state.body_pos, self._gravity).sum())

    def total_energy(self) -> float:
        return self.kinetic_energy() + self.potential_energy()

    def linear_momentum(self) -> np.ndarray:
        """Σ m v [kg m/s], world frame."""
        return diagnostics.linear_momentum(self.model.body_mass, self._state.body_linvel)

    def angular_momentum(self, point=(0.0, 0.0, 0.0)) -> np.ndarray:
        """Σ (x − p) × m v + L about ``point`` [kg m²/s], world frame (``L`` each body's spin)."""
        point = as_vector3("point", point)
        m, s = self.model, self._state
        return diagnostics.angular_momentum(m.body_mass, s.body_pos, s.body_linvel, s.body_angmom, point)

    # --- queries ------------------------------------------------------------------------------------

    def contacts(self) -> Contacts:
        """The contact points of the last step, with the impulses the solver applied (see :class:`Contacts`)."""
        model = self.model
        s = self._scratch
        count = s.contact_count if model.has_contacts else 0
        return Contacts.from_solver(model.shape_body, s.manifolds, s.rows, count)

    def query_ray(self, origin, direction, max_distance: float = math.inf, *, mask: int = 0xFFFFFFFF) -> RayHit | None:
        """The first shape hit by the ray from ``origin`` along ``direction`` within ``max_distance``, or None.

        ``direction`` need not be unit; only shapes whose ``collision_group`` shares a bit with ``mask`` count.
        A ray that starts inside a solid shape hits it at distance 0.
        """
        return first_ray_hit(self.model, self._state, self._bodies, origin, direction, max_distance, mask)

    def query_overlap(
        self, shape, position=(0.0, 0.0, 0.0), orientation=(1.0, 0.0, 0.0, 0.0), *, mask: int = 0xFFFFFFFF
    ) -> list[Body]:
        """Every body with a shape that overlaps ``shape`` placed at ``position`` and ``orientation``, by index.

        ``shape`` is a :class:`~tumble.Sphere`, :class:`~tumble.Box`, :class:`~tumble.Capsule`,
        :class:`~tumble.Cylinder` or :class:`~tumble.ConvexHull`; its frame is put at the pose (world frame), as
        :meth:`add_static` would put it. The contact kernels of the step decide: two shapes overlap when their
        manifold has a point with separation <= 0, so shapes that just touch count. Static bodies count; only
        shapes whose ``collision_group`` shares a bit with ``mask`` are tested. A plane is a solid half-space, a
        :class:`~tumble.TriMesh` a surface: a shape wholly inside a closed mesh does not overlap it.

        Returns:
            The bodies, sorted by :attr:`Body.index`, each once (empty when nothing overlaps).
        """
        return overlapping_bodies(self.model, self._state, self._bodies, shape, position, orientation, mask)

    # --- checkpoints --------------------------------------------------------------------------------

    def save(self, path) -> None:
        """Write a checkpoint (model description, settings, state; no pickle) that :meth:`load` resumes bit for
        bit; see ``docs/files.md``."""
        from .checkpoint import save_world

        save_world(self, path)

    @classmethod
    def load(cls, path) -> World:
        """The world saved by :meth:`save` to ``path``; stepping it continues the saved run bit for bit."""
        from .checkpoint import load_world

        return load_world(path, cls)

    def __repr__(self) -> str:
        dynamic = sum(1 for b in self._bodies if not b.is_static)
        return (
            f"World(bodies={len(self._bodies)} ({dynamic} dynamic), t={self.time:.6g} s, "
            f"integrator={self.integrator!r}, gravity={self._gravity.tolist()})"
        )
