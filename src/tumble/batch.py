"""Many copies of one world, stepped together: :class:`Batch`.

Layout: each of the world's per-body state arrays gains a leading copy axis, ``(copies, bodies, ...)``, stored
copy-major, so that ``body_pos.reshape(copies * bodies, 3)`` is a view of the same memory and row ``c`` is copy
``c``'s ``world.state.body_pos``. The model is the world's, with per-copy overrides (gravity, masses, friction,
restitution, joint drive targets) packed as ``(copies, ...)`` tables beside it.

A step runs the world's own pipeline (``pipeline.simulate_steps``), not a second engine:

- without contacts or joints the copies are one world of ``copies × bodies`` independent rows, advanced by one call
  of the free-motion kernel (split over threads by ``dynamics/integrate.py``; rows never interact, so every split
  gives the same bits). Each copy's gravity is folded into its rows' constant force, ``F + m g``: the sum the
  kernel forms for one world, so the bits are those of a world with that gravity;
- with contacts or joints each copy steps through the contact pipeline on views of its rows, blocks of copies on
  the free-motion kernel's threads (the kernels release the GIL; copies share nothing they write).

Either way a copy's trajectory is bit for bit the one of a world built with that copy's values.
"""

from __future__ import annotations

import copy
import dataclasses
from dataclasses import dataclass

import numpy as np

from ._validate import _show, as_array, as_count, as_step, listed
from .dynamics.actuation import ActuatorArrays
from .dynamics.integrate import _thread_pool, threads
from .errors import SimulationError
from .inputs import Inputs
from .model import Model
from .pipeline import simulate_steps
from .scratch import Scratch
from .state import State

__all__ = ["Batch", "BatchState"]

_FIELDS = ("body_pos", "body_quat", "body_linvel", "body_angmom", "body_sleep_time", "body_sleeping", "body_island")
_DRIVE_TARGET = 6  # the column of JointArrays.drive that holds a spring drive's target


@dataclass(frozen=True, eq=False)
class BatchState:
    """A batch's state arrays, ``(copies, bodies, ...)``: write into them (``state.body_pos[3, 0, 2] = 1.0``), but
    do not rebind them. Row ``c`` of each is copy ``c``'s :class:`~tumble.state.State` array of the same name.

    Attributes:
        body_pos: (copies, bodies, 3) [m] centre of mass, world frame.
        body_quat: (copies, bodies, 4) unit quaternion ``[w, x, y, z]``, body to world.
        body_linvel: (copies, bodies, 3) [m/s]; body_angmom: (copies, bodies, 3) [kg m²/s], about the COM.
        body_sleep_time: (copies, bodies) [s]; body_sleeping: (copies, bodies) bool; body_island: (copies, bodies).
    """

    body_pos: np.ndarray
    body_quat: np.ndarray
    body_linvel: np.ndarray
    body_angmom: np.ndarray
    body_sleep_time: np.ndarray
    body_sleeping: np.ndarray
    body_island: np.ndarray

    @classmethod
    def tiled(cls, state: State, copies: int) -> BatchState:
        return cls(**{f: np.repeat(getattr(state, f)[None], copies, axis=0) for f in _FIELDS})

    def copy(self) -> BatchState:
        return BatchState(**{f: getattr(self, f).copy() for f in _FIELDS})

    def copy_state(self, c: int) -> State:
        """Copy ``c`` as a :class:`State` whose body arrays are views of row ``c`` (no contacts or joint impulses)."""
        return State(**{f: getattr(self, f)[c] for f in _FIELDS})

    def flat_state(self) -> State:
        """Every copy as one state of ``copies × bodies`` rows (views)."""
        return State(**{f: getattr(self, f).reshape(-1, *getattr(self, f).shape[2:]) for f in _FIELDS})


def _refuse_unsupported(world) -> None:
    """A batch copies bodies, shapes, joints and the solver's settings; what runs Python between steps does not
    copy yet: say which part of the world stands in the way."""
    parts = {
        "controllers": len(world._controllers),
        "actuators": len(world._actuation.actuators),
        "drag": len(world._actuation.drag),
        "sensors": len(world._sensors),
        "joint actuators": 0 if world._joint_drives is None else len(world._joint_drives.drives),
    }
    held = [f"{name} ({count})" for name, count in parts.items() if count]
    if world.wind is not None:
        held.append("wind")
    if held:
        raise ValueError(
            f"world has {', '.join(held)}: a Batch steps bodies, shapes and joints under gravity and applied loads; "
            "build the world without them"
        )


class Batch:
    """``n`` copies of ``world``'s model, stepped together; see docs/batch.md.

    The batch copies the world's bodies, shapes, joints, solver settings and present state (later changes to the
    world do not reach it). Copies differ by their state, their applied loads and their :meth:`override` values.

    Args:
        world: a :class:`~tumble.World` without controllers, actuators, drag, sensors or wind.
        n: the number of copies (>= 1).
    """

    def __init__(self, world, n: int):
        from .world import World

        if not isinstance(world, World):
            raise TypeError(f"world must be a tumble.World, got {type(world).__name__}")
        n = as_count("n", n)
        _refuse_unsupported(world)
        state = world.state.copy()
        world.model  # noqa: B018 (builds the world's model: state and builder agree)
        self._builder = copy.deepcopy(world._builder)
        self._params = copy.deepcopy(world._params)
        self._base = self._builder.finalize(world.gravity)
        self._n = n
        base = self._base
        self._state = BatchState.tiled(state, n)
        self._initial = self._state.copy()
        self._template = state  # the contacts and joint impulses a reset copy starts from
        shape = (n, base.body_count, 3)
        self._inputs = Inputs(np.zeros(shape), np.zeros(shape))
        self._gravity = np.tile(world.gravity, (n, 1))
        self._mass = np.tile(base.body_mass, (n, 1))
        self._friction = np.tile(base.shape_friction, (n, 1))
        self._restitution = np.tile(base.shape_restitution, (n, 1))
        self._drive_target = np.tile(base.joints.drive[:, _DRIVE_TARGET], (n, 1))
        self._no_actuators = ActuatorArrays.empty(base.body_count if base.has_constraints else n * base.body_count)
        self._clock = State.empty(0)
        self._clock.time, self._clock.step_count = state.time, state.step_count
        self._models: list[Model] | None = None  # per copy (contacts, joints) or one flat model (free bodies)
        if base.has_constraints:
            self._copies = [self._fresh_copy(c) for c in range(n)]
            self._copy_inputs = [Inputs(self._inputs.body_force[c], self._inputs.body_torque[c]) for c in range(n)]
            self._scratches = [Scratch.for_world(base.body_count, base.shape_count, base.joint_count) for _ in range(n)]
        else:
            self._flat = self._state.flat_state()
            self._flat_inputs = Inputs(self._inputs.body_force.reshape(-1, 3), self._inputs.body_torque.reshape(-1, 3))
            self._flat_scratch = Scratch.for_world(n * base.body_count, 0)

    def _fresh_copy(self, c: int) -> State:
        """Copy ``c``'s state over its rows, with the world's contacts and joint impulses to warm-start from."""
        state = self._state.copy_state(c)
        for f in ("contact_shape_a", "contact_shape_b", "contact_point_count", "contact_feature",
                  "contact_normal_impulse", "contact_tangent_impulse", "joint_linear_impulse", "joint_angular_impulse",
                  "joint_drive_impulse"):  # fmt: skip
            setattr(state, f, getattr(self._template, f).copy())
        return state

    # --- reading ------------------------------------------------------------------------------------

    @property
    def n(self) -> int:
        """The number of copies."""
        return self._n

    def __len__(self) -> int:
        return self._n

    @property
    def body_count(self) -> int:
        return self._base.body_count

    @property
    def state(self) -> BatchState:
        """The copies' state arrays ``(copies, bodies, ...)``, views to read and write."""
        return self._state

    @property
    def initial_state(self) -> BatchState:
        """The state :meth:`reset` returns copies to (the world's, until written): views to read and write."""
        return self._initial

    @property
    def inputs(self) -> Inputs:
        """The loads of the next step, ``(copies, bodies, 3)`` [N], [N m] at the centres of mass, world frame."""
        return self._inputs

    @property
    def time(self) -> float:
        """Simulated time [s], the same for every copy."""
        return self._clock.time

    @property
    def step_count(self) -> int:
        return self._clock.step_count

    @property
    def gravity(self) -> np.ndarray:
        """(copies, 3) [m/s²] each copy's gravity (a copy)."""
        return self._gravity.copy()

    @property
    def mass(self) -> np.ndarray:
        """(copies, bodies) [kg] each copy's body masses (0 for static bodies; a copy)."""
        return self._mass.copy()

    @property
    def friction(self) -> np.ndarray:
        """(copies, shapes) each copy's shape friction coefficients (a copy)."""
        return self._friction.copy()

    @property
    def restitution(self) -> np.ndarray:
        """(copies, shapes) each copy's shape restitution coefficients (a copy)."""
        return self._restitution.copy()

    @property
    def drive_target(self) -> np.ndarray:
        """(copies, joints) each copy's joint spring targets [rad or m] (a copy)."""
        return self._drive_target.copy()

    def __repr__(self) -> str:
        return f"Batch(n={self._n}, bodies={self.body_count}, t={self.time:.6g})"

    # --- choosing copies ----------------------------------------------------------------------------

    def _which(self, name: str, which) -> np.ndarray:
        """Copy indices from ``None`` (all), a boolean mask of length n, or integers in ``[0, n)``."""
        if which is None:
            return np.arange(self._n)
        array = np.asarray(which)
        if array.dtype == np.bool_:
            if array.shape != (self._n,):
                raise ValueError(f"{name} as a mask must have shape ({self._n},), got shape {array.shape}")
            return np.flatnonzero(array)
        if array.ndim > 1 or array.size and not np.issubdtype(array.dtype, np.integer):
            raise TypeError(f"{name} must be None, a boolean mask or copy indices, got {_show(which)}")
        indices = array.astype(np.int64).reshape(-1)
        out = indices[(indices < 0) | (indices >= self._n)]
        if out.size:
            raise IndexError(f"{name} holds copy {int(out[0])}, out of range for a batch of {self._n} copies")
        return indices

    def _body(self, body) -> int:
        """A body row from its index, its name or its handle (a :class:`~tumble.Body` of the batch's world)."""
        from .handles import Body

        index = body.index if isinstance(body, Body) else body
        if isinstance(index, str):
            found = self._builder.index_of(index)
            if found is None:
                raise KeyError(f"no body named {index!r}; names: {sorted(self._builder.names)}")
            return found
        if isinstance(index, (bool, np.bool_)) or not isinstance(index, (int, np.integer)):
            raise TypeError(f"body must be a body's index, name or handle, got {_show(body)}")
        if not 0 <= index < self.body_count:
            raise IndexError(f"body={int(index)} is out of range for {self.body_count} bodies")
        return int(index)

    # --- per-copy values ----------------------------------------------------------------------------

    def override(self, which=None, *, gravity=None, mass=None, friction=None, restitution=None, drive_target=None):
        """Give the copies ``which`` (all, a mask or indices) their own gravity (3,) [m/s²], body masses (bodies,)
        [kg] (inertias scale with them, as :meth:`MassProperties.scaled_to`; static bodies keep 0), shape friction
        and restitution (shapes,), or joint spring targets (joints,); one row for them all, or one per copy.

        Raises:
            ValueError, TypeError, IndexError: a value of the wrong shape or out of range, naming it; nothing changes.
        """
        rows = self._which("which", which)
        base = self._base
        new = {}
        for name, value, width in (("gravity", gravity, 3), ("mass", mass, base.body_count),
                                   ("friction", friction, base.shape_count),
                                   ("restitution", restitution, base.shape_count),
                                   ("drive_target", drive_target, base.joint_count)):  # fmt: skip
            if value is not None:
                new[name] = self._per_copy(name, value, width, rows.size)
        if "mass" in new:
            self._check_masses(new["mass"])
        if "friction" in new and (new["friction"] < 0).any():
            raise ValueError(f"friction must be >= 0, got {_show(new['friction'])}")
        if "restitution" in new and ((new["restitution"] < 0) | (new["restitution"] > 1)).any():
            raise ValueError(f"restitution must be in [0, 1], got {_show(new['restitution'])}")
        for name, value in new.items():
            getattr(self, f"_{name}")[rows] = value
        if new:
            self._models = None

    def _per_copy(self, name: str, value, width: int, rows: int) -> np.ndarray:
        array = as_array(name, value, (width,))
        if array.ndim == 1:
            return np.broadcast_to(array, (rows, width))
        if array.shape != (rows, width):
            raise ValueError(f"{name} must have shape ({width},) or ({rows}, {width}) for {rows} copies, "
                             f"got shape {array.shape}")  # fmt: skip
        return array

    def _check_masses(self, mass: np.ndarray) -> None:
        base = self._base
        dynamic = base.body_is_dynamic
        static_set = mass[:, ~dynamic] != 0.0
        if static_set.any():
            body = int(np.flatnonzero(~dynamic)[np.argwhere(static_set)[0, 1]])
            raise ValueError(f"mass of body {body} must stay 0: it is static, got {_show(mass[:, body])}")
        if (mass[:, dynamic] <= 0).any():
            raise ValueError(f"mass must be > 0 for dynamic bodies, got {_show(mass)}")
        with np.errstate(over="ignore"):
            largest = np.abs(base.body_inertia_local).max(axis=(1, 2)) * (mass / np.where(dynamic, base.body_mass, 1))
        if not np.isfinite(largest).all():
            raise ValueError(f"mass={listed(mass)} scales an inertia out of float range")

    def _body_tables(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(mass, inv_mass, inertia, inv_inertia)`` per copy and body: the world's inertia scaled by the copy's mass
        over the world's (``MassProperties.scaled_to``'s rule), inverted as ``ModelBuilder.finalize`` inverts."""
        base, mass = self._base, self._mass
        dynamic = base.body_is_dynamic
        scale = np.divide(mass, base.body_mass, out=np.ones_like(mass), where=dynamic)
        inertia = base.body_inertia_local * scale[:, :, None, None]
        inv_inertia = np.zeros_like(inertia)
        inv_inertia[:, dynamic] = np.linalg.inv(inertia[:, dynamic])
        inv_mass = np.divide(1.0, mass, out=np.zeros_like(mass), where=dynamic)
        return mass, inv_mass, inertia, inv_inertia

    def _copy_models(self) -> list[Model]:
        """Each copy's model: the world's with the copy's values (copies without overrides share it)."""
        base = self._base
        mass, inv_mass, inertia, inv_inertia = self._body_tables()
        models = []
        for c in range(self._n):
            drive = base.joints.drive.copy()
            drive[:, _DRIVE_TARGET] = self._drive_target[c]
            model = dataclasses.replace(
                base, gravity=self._gravity[c].copy(), body_mass=mass[c], body_inv_mass=inv_mass[c],
                body_inertia_local=inertia[c], body_inv_inertia_local=inv_inertia[c],
                shape_friction=self._friction[c].copy(), shape_restitution=self._restitution[c].copy(),
                joints=base.joints._replace(drive=drive),
            )  # fmt: skip
            model.body_arrays, model.body_free_to_sweep  # noqa: B018 (cached here, not raced for by the threads)
            models.append(model)
        return models

    def _flat_model(self) -> Model:
        """Every copy's bodies as the rows of one model without gravity, each copy's weight in its constant force."""
        base, n = self._base, self._n
        mass, inv_mass, inertia, inv_inertia = self._body_tables()
        weight = base.body_constant_force + self._gravity[:, None, :] * mass[:, :, None]

        def tiled(array):
            return np.tile(array, (n,) + (1,) * (array.ndim - 1))

        return dataclasses.replace(
            base, gravity=np.zeros(3), body_mass=mass.reshape(-1), body_inv_mass=inv_mass.reshape(-1),
            body_inertia_local=inertia.reshape(-1, 3, 3), body_inv_inertia_local=inv_inertia.reshape(-1, 3, 3),
            body_com_local=tiled(base.body_com_local), body_is_dynamic=tiled(base.body_is_dynamic),
            body_linear_damping=tiled(base.body_linear_damping), body_angular_damping=tiled(base.body_angular_damping),
            body_name=base.body_name * n, body_constant_force=weight.reshape(-1, 3),
            body_constant_torque=tiled(base.body_constant_torque),
        )  # fmt: skip

    # --- loads --------------------------------------------------------------------------------------

    def apply_force(self, body, force, point=None) -> None:
        """Apply ``force`` [N] to ``body`` (index, name or handle) in every copy during the next step: (3,) for all
        copies or (n, 3), one per copy; at world ``point`` ((3,) or (n, 3), default each copy's COM).

        Raises:
            ValueError: a static body, a shape other than (3,) or (n, 3), or a sum that overflows; nothing is added.
        """
        i = self._body(body)
        force = self._per_copy("force", force, 3, self._n)
        torque = np.zeros((self._n, 3))
        if point is not None:
            lever = self._per_copy("point", point, 3, self._n) - self._state.body_pos[:, i]
            with np.errstate(over="ignore", invalid="ignore"):
                torque = np.cross(lever, force)
        self._add_loads("apply_force", i, force, torque)

    def apply_torque(self, body, torque) -> None:
        """Apply ``torque`` [N m] (world frame; (3,) or (n, 3)) to ``body`` in every copy during the next step."""
        i = self._body(body)
        self._add_loads("apply_torque", i, np.zeros((self._n, 3)), self._per_copy("torque", torque, 3, self._n))

    def _add_loads(self, what: str, i: int, force: np.ndarray, torque: np.ndarray) -> None:
        if not self._base.body_is_dynamic[i]:
            raise ValueError(f"{what}: body {i} is static; loads act on dynamic bodies only")
        with np.errstate(over="ignore", invalid="ignore"):
            totals = self._inputs.body_force[:, i] + force, self._inputs.body_torque[:, i] + torque
        if not (np.isfinite(totals[0]).all() and np.isfinite(totals[1]).all()):
            raise ValueError(f"{what}: the loads on body {i} for the next step overflow (non-finite); nothing added")
        self._inputs.body_force[:, i], self._inputs.body_torque[:, i] = totals

    # --- stepping -----------------------------------------------------------------------------------

    def step(self, dt: float, steps: int = 1) -> None:
        """Advance every copy ``steps`` steps of ``dt`` seconds (applied loads act in the first one).

        Raises:
            ValueError: ``dt`` or ``steps`` is not a step the copies can take; nothing has moved.
            SimulationError: a copy turned non-finite (``error.copy``, ``error.body``); every copy keeps its state
                after the last step all of them completed, and the applied loads are dropped.
        """
        dt = as_step("dt", dt, self.time)
        steps = as_count("steps", steps)
        if self._base.has_constraints:
            self._params.solver.substeps_for(dt)
        if self._models is None:
            self._models = self._copy_models() if self._base.has_constraints else [self._flat_model()]
        if self._base.has_constraints:
            failure = self._step_copies(dt, steps)
        else:
            self._flat.time, self._flat.step_count = self._clock.time, self._clock.step_count
            done, row = simulate_steps(self._models[0], self._flat, self._flat_inputs, self._params,
                                       self._flat_scratch, dt, steps, acts=self._no_actuators)  # fmt: skip
            self._clock.time, self._clock.step_count = self._flat.time, self._flat.step_count
            failure = None if row < 0 else divmod(row, self.body_count)
        if failure is not None:
            raise self._failed(*failure)

    def _step_copies(self, dt: float, steps: int) -> tuple[int, int] | None:
        """Contacts and joints: each step, every copy through the pipeline; blocks of copies on the threads."""
        count = min(threads(), self._n)
        bounds = np.linspace(0, self._n, count + 1).astype(np.int64)
        blocks = list(zip(bounds[:-1].tolist(), bounds[1:].tolist(), strict=True))
        for _ in range(steps):
            before = [state.copy() for state in self._copies]
            if count > 1:
                errors = np.geterr()  # NumPy's error settings are per thread: the caller's hold in the workers too
                futures = [_thread_pool().submit(self._step_block, lo, hi, dt, errors) for lo, hi in blocks]
                results = [future.result() for future in futures]
            else:
                results = [self._step_block(0, self._n, dt)]
            failed = [r for r in results if r is not None]
            if failed:
                for state, old in zip(self._copies, before, strict=True):
                    state.assign(old)
                self._inputs.body_force.fill(0.0)
                self._inputs.body_torque.fill(0.0)
                return failed[0]
            self._clock.time, self._clock.step_count = self._copies[0].time, self._copies[0].step_count
        return None

    def _step_block(self, first: int, last: int, dt: float, errors: dict | None = None) -> tuple[int, int] | None:
        """One step of copies ``first..last-1`` (under NumPy's error settings ``errors``, if given): ``(copy, body)``
        of the first that failed, or None."""
        if errors is not None:
            with np.errstate(**errors):
                return self._step_block(first, last, dt)
        failure = None
        for c in range(first, last):
            _, body = simulate_steps(self._models[c], self._copies[c], self._copy_inputs[c], self._params,
                                     self._scratches[c], dt, 1, acts=self._no_actuators)  # fmt: skip
            if body >= 0 and failure is None:
                failure = (c, body)
        return failure

    def _failed(self, c: int, body: int) -> SimulationError:
        name = self._base.body_name[body]
        label = repr(name) if name is not None else f"#{body}"
        error = SimulationError(
            f"copy {c}: body {label} became non-finite (NaN or Inf) in step {self.step_count} (t = {self.time:.6g} s); "
            "every copy keeps its state from before that step (the loads applied for it are dropped)",
            body=name if name is not None else body,
            step=self.step_count,
        )
        error.copy = c
        return error

    # --- resetting ----------------------------------------------------------------------------------

    def reset(self, which=None, *, body_pos=None, body_quat=None, body_linvel=None, body_angmom=None) -> None:
        """Return the copies ``which`` (all, a boolean mask of n, or indices) to :attr:`initial_state`, or to the
        given arrays ((bodies, k) for all of them or (copies, bodies, k), one per chosen copy); fields not given
        come from the initial state. Their applied loads are dropped; time is the batch's and does not change.

        Raises:
            ValueError, TypeError, IndexError: a mask, index or array that does not fit, naming it; nothing changes.
        """
        rows = self._which("which", which)
        given = {}
        for name, value, width in (("body_pos", body_pos, 3), ("body_quat", body_quat, 4),
                                   ("body_linvel", body_linvel, 3), ("body_angmom", body_angmom, 3)):  # fmt: skip
            if value is not None:
                given[name] = self._per_copy_rows(name, value, width, rows.size)
        if "body_quat" in given:
            norm = np.linalg.norm(given["body_quat"], axis=-1)
            if not (np.abs(norm - 1.0) <= 1e-6).all():
                raise ValueError(f"body_quat must hold unit quaternions (norm 1 within 1e-6), got {_show(norm)}")
            given["body_quat"] = given["body_quat"] / norm[..., None]
        static = ~self._base.body_is_dynamic
        for name in ("body_linvel", "body_angmom"):
            if name in given and (given[name][:, static] != 0.0).any():
                raise ValueError(f"{name} must be 0 for static bodies {np.flatnonzero(static).tolist()}")
        for f in _FIELDS:
            getattr(self._state, f)[rows] = given[f] if f in given else getattr(self._initial, f)[rows]
        if given:  # a new state: awake, with nothing to warm-start from
            self._state.body_sleep_time[rows] = 0.0
            self._state.body_sleeping[rows] = False
            self._state.body_island[rows] = -1
        self._inputs.body_force[rows] = 0.0
        self._inputs.body_torque[rows] = 0.0
        if self._base.has_constraints:
            for c in rows.tolist():
                fresh = self._fresh_copy(c)
                if given:
                    fresh.forget_contacts()
                    for f in ("joint_linear_impulse", "joint_angular_impulse", "joint_drive_impulse"):
                        getattr(fresh, f).fill(0.0)
                fresh.time, fresh.step_count = self.time, self.step_count
                self._copies[c] = fresh
                self._scratches[c].contact_count = 0

    def _per_copy_rows(self, name: str, value, width: int, rows: int) -> np.ndarray:
        array = as_array(name, value, (self.body_count, width))
        if array.ndim == 2:
            return np.broadcast_to(array, (rows, self.body_count, width))
        if array.shape != (rows, self.body_count, width):
            raise ValueError(f"{name} must have shape ({self.body_count}, {width}) or ({rows}, {self.body_count}, "
                             f"{width}) for {rows} copies, got shape {array.shape}")  # fmt: skip
        return array

    # --- one copy as a world ------------------------------------------------------------------------

    def world(self, i: int):
        """Copy ``i`` as a new :class:`~tumble.World` (a copy, not a view: stepping it leaves the batch as it is),
        with the copy's state, pending loads and override values; it steps as the copy would."""
        from .world import World

        if isinstance(i, (bool, np.bool_)) or not isinstance(i, (int, np.integer)):
            raise TypeError(f"i must be a copy index, got {_show(i)}")
        c = int(self._which("i", [i])[0])
        builder = copy.deepcopy(self._builder)
        base = self._base
        for b, row in enumerate(builder.rows):
            if row.mass_properties is not None and self._mass[c, b] != base.body_mass[b]:
                row.mass_properties = row.mass_properties.scaled_to(float(self._mass[c, b]))
        k = 0
        for row in builder.rows:
            for s, spec in enumerate(row.shapes):
                row.shapes[s] = dataclasses.replace(spec, friction=float(self._friction[c, k]),
                                                    restitution=float(self._restitution[c, k]))  # fmt: skip
                k += 1
        for j, spec in enumerate(builder.joints):
            spec.drive = spec.drive.copy()
            spec.drive[_DRIVE_TARGET] = self._drive_target[c, j]
        state = self._copies[c].copy() if base.has_constraints else self._state.copy_state(c).copy()
        state.time, state.step_count = self.time, self.step_count
        inputs = Inputs(self._inputs.body_force[c].copy(), self._inputs.body_torque[c].copy())
        return World._from_builder(builder, state, inputs, gravity=self._gravity[c].copy(),
                                   params=copy.deepcopy(self._params))  # fmt: skip
