"""Many copies of one world, stepped together: :class:`Batch`.

Layout: each of the world's per-body state arrays gains a leading copy axis, ``(copies, bodies, ...)``, stored
copy-major, so that ``body_pos.reshape(copies * bodies, 3)`` is a view of the same memory and row ``c`` is copy
``c``'s ``world.state.body_pos``. The model is the world's, with per-copy overrides (gravity, masses, friction,
restitution, joint drive targets) packed as ``(copies, ...)`` tables beside it.

A step runs the world's own pipeline (``runner.simulate_steps``), not a second engine: a block of copies is one
world whose rows are the copies' rows one copy after the other (``batch_rows.py``), stepped by one call per stage
for all its copies.

- Free bodies (nothing touches, no joints): one block of every copy; the free-motion kernel splits its rows over
  threads itself (rows never interact, so every split gives the same bits).
- Contacts or joints: one block per core, stepped on the free-motion kernel's threads (the kernels release the
  GIL); the broad phase pairs no shapes of different copies, so a block costs what its copies' bodies cost.

Either way a copy's trajectory is bit for bit the one of a world built with that copy's values.
"""

from __future__ import annotations

import copy
import dataclasses
import os
from dataclasses import dataclass

import numpy as np

from . import portable
from ._validate import _show, as_array, as_count, as_step, listed
from .batch_rows import DRIVE_TARGET, copy_impulses, rows_model, splice_contacts, tiled_impulses
from .dynamics.actuation import ActuatorArrays
from .dynamics.integrate import thread_pool, threads
from .errors import SimulationError
from .inputs import Inputs
from .params import substeps_to_run
from .runner import simulate_steps
from .scratch import Scratch
from .state import State

__all__ = ["Batch", "BatchState"]

_FIELDS = ("body_pos", "body_quat", "body_linvel", "body_angmom", "body_sleep_time", "body_sleeping")


@dataclass(frozen=True, eq=False)
class BatchState:
    """A batch's state arrays, ``(copies, bodies, ...)``: write into them (``state.body_pos[3, 0, 2] = 1.0``), but
    do not rebind them. Row ``c`` of each is copy ``c``'s :class:`~tumble.state.State` array of the same name.

    Attributes:
        body_pos: (copies, bodies, 3) [m] centre of mass, world frame.
        body_quat: (copies, bodies, 4) unit quaternion ``[w, x, y, z]``, body to world.
        body_linvel: (copies, bodies, 3) [m/s]; body_angmom: (copies, bodies, 3) [kg m²/s], about the COM.
        body_sleep_time: (copies, bodies) [s]; body_sleeping: (copies, bodies) bool.
    """

    body_pos: np.ndarray
    body_quat: np.ndarray
    body_linvel: np.ndarray
    body_angmom: np.ndarray
    body_sleep_time: np.ndarray
    body_sleeping: np.ndarray

    @classmethod
    def tiled(cls, state: State, copies: int) -> BatchState:
        return cls(**{f: np.repeat(getattr(state, f)[None], copies, axis=0) for f in _FIELDS})

    def copy(self) -> BatchState:
        return BatchState(**{f: getattr(self, f).copy() for f in _FIELDS})

    def rows(self, first: int, last: int, island: np.ndarray) -> State:
        """Copies ``first..last-1`` as one state of their rows (views), with the islands ``island``."""
        return State(**{f: getattr(self, f)[first:last].reshape(-1, *getattr(self, f).shape[2:]) for f in _FIELDS},
                     body_island=island)  # fmt: skip


class _Block:
    """Copies ``first..last-1`` as one world of their rows: a state of views into the batch's arrays with the
    copies' contacts, joint impulses and islands (numbered in the block), their loads (views), buffers, a model."""

    def __init__(self, batch: Batch, first: int, last: int, template: State) -> None:
        base, k = batch._base, last - first
        bodies = base.body_count
        island = np.tile(template.body_island, k)
        island = np.where(island >= 0, island + np.repeat(np.arange(k) * bodies, bodies), island)
        self.first, self.last = first, last
        self.state = batch._state.rows(first, last, island)
        tiled_impulses(self.state, template, k, base.shape_count)
        self.state.time, self.state.step_count = template.time, template.step_count
        inputs = batch._inputs
        self.inputs = Inputs(
            inputs.body_force[first:last].reshape(-1, 3), inputs.body_torque[first:last].reshape(-1, 3)
        )
        self.scratch = Scratch.for_world(k * bodies, k * base.shape_count, k * base.joint_count)
        self.acts = ActuatorArrays.empty(k * bodies)
        self.model = None


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

    The batch copies the world's bodies, shapes, joints, solver settings and present state, warm starts included
    (later changes to the world do not reach it; loads applied to the world for its next step are not copied). Copies
    differ by their state, their applied loads and their :meth:`override` values.

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
        self._substeps_told: set = set()  # the (asked, raised) substeps a warning told (params.substeps_to_run)
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
        self._drive_target = np.tile(base.joints.drive[:, DRIVE_TARGET], (n, 1))
        self._stale = True  # the blocks' models are rebuilt before the next step
        # One block of every copy for free bodies (their kernel threads itself), else one block per core.
        parts = 1 if not base.has_constraints else min(os.cpu_count() or 1, n)
        bounds = np.linspace(0, n, parts + 1).astype(np.int64).tolist()
        self._blocks = [_Block(self, lo, hi, state) for lo, hi in zip(bounds[:-1], bounds[1:], strict=True)]

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
        return self._blocks[0].state.time

    @property
    def step_count(self) -> int:
        return self._blocks[0].state.step_count

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
            self._stale = True

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

    def _tables(self, first: int, last: int) -> dict[str, np.ndarray]:
        """Copies ``first..last-1``'s values for :func:`~tumble.batch_rows.rows_model`: masses as given, inertias the
        world's scaled by the copy's mass over the world's (``MassProperties.scaled_to``'s rule) and inverted as
        ``ModelBuilder.finalize`` inverts them."""
        base, mass = self._base, self._mass[first:last]
        dynamic = base.body_is_dynamic
        scale = np.divide(mass, base.body_mass, out=np.ones_like(mass), where=dynamic)
        inertia = base.body_inertia_local * scale[:, :, None, None]
        inv_inertia = np.zeros_like(inertia)
        inv_inertia[:, dynamic] = portable.inverse(inertia[:, dynamic])
        inv_mass = np.divide(1.0, mass, out=np.zeros_like(mass), where=dynamic)
        span = slice(first, last)
        return {"gravity": self._gravity[span], "mass": mass, "inv_mass": inv_mass, "inertia": inertia,
                "inv_inertia": inv_inertia, "friction": self._friction[span], "restitution": self._restitution[span],
                "drive_target": self._drive_target[span]}  # fmt: skip

    def _block_of(self, c: int) -> tuple[_Block, int]:
        """The block holding copy ``c`` and the copy's place in it."""
        for block in self._blocks:
            if block.first <= c < block.last:
                return block, c - block.first
        raise AssertionError(c)

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
        free = not self._base.has_constraints
        if not free:
            substeps_to_run(self._params.solver, dt, self._substeps_told, "Batch")
        if self._stale:
            for block in self._blocks:
                block.model = rows_model(self._base, self._tables(block.first, block.last), fold_gravity=free)
            self._stale = False
        if free:  # one call for every step: the kernel keeps the last step all rows completed
            block = self._blocks[0]
            row = simulate_steps(block.model, block.state, block.inputs, self._params, block.scratch, dt, steps,
                                 acts=block.acts).failing_body  # fmt: skip
            failure = None if row < 0 else divmod(row, self.body_count)
        else:
            failure = self._step_blocks(dt, steps)
        if failure is not None:
            raise self._failed(*failure)

    def _step_blocks(self, dt: float, steps: int) -> tuple[int, int] | None:
        """Contacts and joints: step by step, every block on the threads; a failure in one block takes every block
        back to the state before that step."""
        blocks = self._blocks
        workers = min(threads(), len(blocks))
        for _ in range(steps):
            before = [block.state.copy() for block in blocks] if len(blocks) > 1 else None
            if workers > 1:
                errors = np.geterr()  # NumPy's error settings are per thread: the caller's hold in the workers too
                futures = [thread_pool().submit(self._step_block, block, dt, errors) for block in blocks]
                rows = [future.result() for future in futures]
            else:
                rows = [self._step_block(block, dt) for block in blocks]
            failed = [(block, row) for block, row in zip(blocks, rows, strict=True) if row >= 0]
            if failed:
                if before is not None:
                    for block, old in zip(blocks, before, strict=True):
                        block.state.assign(old)
                self._inputs.body_force.fill(0.0)
                self._inputs.body_torque.fill(0.0)
                block, row = failed[0]
                copy_in_block, body = divmod(row, self.body_count)
                return block.first + copy_in_block, body
        return None

    def _step_block(self, block: _Block, dt: float, errors: dict | None = None) -> int:
        """One step of a block (under NumPy's error settings ``errors``, if given): the failing row, or -1."""
        if errors is not None:
            with np.errstate(**errors):
                return self._step_block(block, dt)
        return simulate_steps(block.model, block.state, block.inputs, self._params, block.scratch, dt, 1,
                              acts=block.acts).failing_body  # fmt: skip

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
        self._inputs.body_force[rows] = 0.0
        self._inputs.body_torque[rows] = 0.0
        for block in self._blocks:
            mine = rows[(rows >= block.first) & (rows < block.last)] - block.first
            if mine.size:
                self._restart(block, mine, None if given else self._template)

    def _restart(self, block: _Block, copies: np.ndarray, template: State | None) -> None:
        """The islands, contacts and joint impulses of a block's local ``copies``: the template's, or none."""
        base, state = self._base, block.state
        bodies, k = base.body_count, block.last - block.first
        islands = state.body_island.reshape(k, bodies)  # a view: rows of the copies
        if template is None:
            islands[copies] = -1
        else:
            shifted = template.body_island[None, :] + (copies * bodies)[:, None]
            islands[copies] = np.where(template.body_island >= 0, shifted, -1)
        for name in ("joint_linear_impulse", "joint_angular_impulse", "joint_drive_impulse"):
            impulses = getattr(state, name)
            impulses = impulses.reshape(k, base.joint_count, impulses.shape[1])
            impulses[copies] = 0.0 if template is None else getattr(template, name)
        splice_contacts(state, copies, template, base.shape_count)

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
            spec.drive[DRIVE_TARGET] = self._drive_target[c, j]
        block, j = self._block_of(c)
        bodies = base.body_count
        island = block.state.body_island[j * bodies : (j + 1) * bodies]
        state = State(**{f: getattr(self._state, f)[c].copy() for f in _FIELDS},
                      body_island=np.where(island >= 0, island - j * bodies, -1),
                      **copy_impulses(block.state, j, base.shape_count, base.joint_count))  # fmt: skip
        state.time, state.step_count = self.time, self.step_count
        inputs = Inputs(self._inputs.body_force[c].copy(), self._inputs.body_torque[c].copy())
        return World._from_builder(builder, state, inputs, gravity=self._gravity[c].copy(),
                                   params=copy.deepcopy(self._params))  # fmt: skip
