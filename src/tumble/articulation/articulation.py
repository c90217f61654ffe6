"""``Articulation``: a tree of links in generalised coordinates, the Pythonic facade over the kernels.

The facade validates everything a user hands in (errors name the argument and the value, and a refused call
changes nothing), packs the links into the model buffers when they change (``model.py``), and calls the
compiled kernel (``kernels.py``). The state is ``q`` (nq,), ``qd`` (nv,) and ``time``; see ``joints.py`` for
each joint's coordinates and ``docs/articulation.md`` for the whole layout.
"""

from __future__ import annotations

import functools
import numbers
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from .. import portable
from .._validate import (
    _show,
    as_array,
    as_count,
    as_float,
    as_quaternion,
    as_step,
    as_vector3,
    mass_or_density,
    require_memory,
    step_count,
)
from ..errors import SimulationError
from ..mass import MassProperties
from ..rotation import quat_from_rotvec, quat_multiply, quat_to_matrix
from ..shapes import Shape
from .actuators import Actuator
from .collision import Collisions, Geom, pack_geoms, pack_pairs, pair_weights, translation_weight
from .drives import JointDrives, softness
from .integrators import DAMPED, EULER, NOT_FINITE, RK4, SYMPLECTIC
from .joint_view import ArticulationJoint
from .joints import Ball, Free, Joint, Prismatic, Revolute
from .kernels import CONTACTS, FORWARD, INVERSE, KINEMATICS, MASS_MATRIX, PROJECT, SIMULATE, articulation_kernel
from .limits import SoftConstraint, Tendon, check_limits, invweights, pack_actuators, pack_scalars, readonly
from .loops import LoopClosure
from .model import (
    CONTACT_DIST,
    CONTACT_NORMAL,
    CONTACT_PAIR,
    CONTACT_POINT,
    DOF_PARENT,
    DOF_TIP,
    INERTIA_WORLD,
    INVWEIGHT,
    LOOP_ERROR,
    POS,
    QUAT,
    VEL,
    counts,
    model_views,
    pack_model,
    python_function,
    work_size,
    work_views,
)

__all__ = [
    "Actuator",
    "Articulation",
    "ArticulationContacts",
    "ArticulationTrajectory",
    "Geom",
    "Link",
    "SoftConstraint",
    "Tendon",
]

INTEGRATORS = {"euler": EULER, "symplectic": SYMPLECTIC, "rk4": RK4, "symplectic_implicit_damping": DAMPED}
LOOP_KINDS = ("point",)


@dataclass(frozen=True, eq=False)
class Link:
    """One link as it was added (read-only).

    Attributes:
        index: the link's row; ``parent``: the parent link's index, or ``None`` for the base.
        joint: the joint to the parent. ``position`` (3,) [m] and ``orientation`` (4,): the link frame in the
            parent frame at zero joint displacement (for a ``Free`` joint: its initial pose).
        mass_properties: in the link frame, or ``None`` for a massless link.
        damping: joint damping (torque ``-damping q̇`` on each of its degrees of freedom).
        q_slice, v_slice: the link's rows of ``q`` and ``qd``.
        shape, shape_position, shape_orientation: the geometry, if any, in the link frame.
        armature: inertia added to each of the joint's degrees of freedom (a motor's rotor, as MuJoCo's).
        stiffness, springref: a spring ``-stiffness (q - springref)`` on a revolute or prismatic joint.
        limits: ``(lower, upper)`` of a revolute or prismatic joint's coordinate, or ``None``; margin: the distance
            from a limit at which it starts to act; frictionloss: the dry friction on each degree of freedom;
            limit_softness, friction_softness: their :class:`SoftConstraint` (MuJoCo's ``solref``/``solimp``).
        joint_name: the joint's own name (``Articulation.joint``), or ``None``.
    """

    index: int
    name: str | None
    parent: int | None
    joint: Joint
    position: np.ndarray
    orientation: np.ndarray
    mass_properties: MassProperties | None
    damping: float
    q_slice: slice
    v_slice: slice
    shape: Shape | None = None
    shape_position: np.ndarray = field(default_factory=lambda: readonly((0.0, 0.0, 0.0)))
    shape_orientation: np.ndarray = field(default_factory=lambda: readonly((1.0, 0.0, 0.0, 0.0)))
    armature: float = 0.0
    stiffness: float = 0.0
    springref: float = 0.0
    limits: tuple[float, float] | None = None
    margin: float = 0.0
    frictionloss: float = 0.0
    limit_softness: SoftConstraint = field(default_factory=SoftConstraint)
    friction_softness: SoftConstraint = field(default_factory=SoftConstraint)
    joint_name: str | None = None


class ArticulationContacts(NamedTuple):
    """Contacts of an articulation's geoms (:meth:`Articulation.contacts`): ``geoms`` (k, 2) the two geoms (the
    normal points from the first to the second), ``point`` (k, 3) [m] midway between their surfaces, ``normal``
    (k, 3), ``distance`` (k,) [m] (negative: overlapping)."""

    geoms: np.ndarray
    point: np.ndarray
    normal: np.ndarray
    distance: np.ndarray


@dataclass(frozen=True, eq=False)
class ArticulationTrajectory:
    """Recorded frames of :meth:`Articulation.simulate`.

    Attributes:
        time: (T,) [s]; q: (T, nq); qd: (T, nv); energy: (T,) [J], kinetic plus potential (zero at the world
            origin); dt: the step [s]; integrator: its name.
    """

    time: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    energy: np.ndarray
    dt: float
    integrator: str

    def __getitem__(self, key: str) -> np.ndarray:
        """Dictionary-style access: ``trajectory["q"]``."""
        if key not in ("time", "q", "qd", "energy"):
            raise KeyError(key)
        return getattr(self, key)


@dataclass
class _Compiled:
    """The packed model, the work buffer and reusable arrays for one version of the link list."""

    ints: np.ndarray
    reals: np.ndarray
    work: np.ndarray
    zero_v: np.ndarray
    zero_external: np.ndarray
    out_v: np.ndarray
    no_record: np.ndarray

    def views(self):
        """The named model and work arrays (views, for reading results after a kernel call; made once)."""
        return self._views

    def __getstate__(self):
        state = dict(self.__dict__)
        state.pop("_views", None)  # views of the buffers: a copy or a pickle makes them again from its own buffers
        return state

    @functools.cached_property
    def _views(self):
        model = python_function(model_views)(self.ints, self.reals)
        return model, python_function(work_views)(self.work, *counts(self.ints))


class Articulation(JointDrives, Collisions):
    """A tree of rigid links joined by joints, in generalised coordinates.

    Args:
        gravity: (3,) [m/s²], world frame.
        base_position: (3,) [m] and base_orientation: (4,) ``[w, x, y, z]``: the pose of the fixed base, the
            parent of every link added with ``parent=None``.
        name: optional label.

    >>> from tumble.articulation import Articulation, Revolute
    >>> art = Articulation()
    >>> i = art.add_link(Revolute((0, 1, 0)), mass=1.0, shape_position=(0, 0, -1))
    >>> art.nq, art.nv, round(float(art.mass_matrix()[0, 0]), 12)
    (1, 1, 1.0)
    """

    def __init__(self, gravity=(0.0, 0.0, -9.81), base_position=(0.0, 0.0, 0.0),
                 base_orientation=(1.0, 0.0, 0.0, 0.0), name=None) -> None:  # fmt: skip
        self._gravity = as_vector3("gravity", gravity)
        self._base_position = as_vector3("base_position", base_position)
        self._base_orientation = as_quaternion("base_orientation", base_orientation)
        if name is not None and not isinstance(name, str):
            raise TypeError(f"name must be a string or None, got {_show(name)}")
        self.name = name
        self._links: list[Link] = []
        self._loops: list[LoopClosure] = []
        self._q = np.zeros(0)
        self._qd = np.zeros(0)
        self._quat_starts: list[tuple[int, int]] = []  # (first row in q, link) of every quaternion
        self._time = 0.0
        self._step_count = 0
        self._compiled: _Compiled | None = None
        self._actuators: list[Actuator] = []
        self._ctrl = np.zeros(0)
        self._tendons: list[Tendon] = []
        self._law = None  # the actuators' control law as arrays (drives.py)
        self._geoms: list[Geom] = []
        self._excluded: set[frozenset] = set()
        self._impratio = 1.0

    # --- building ------------------------------------------------------------------------------------

    def add_link(self, joint, *, parent=None, position=(0.0, 0.0, 0.0), orientation=(1.0, 0.0, 0.0, 0.0),
                 shape=None, mass=None, density=None, mass_properties=None, shape_position=(0.0, 0.0, 0.0),
                 shape_orientation=(1.0, 0.0, 0.0, 0.0), damping=0.0, name=None, armature=0.0, stiffness=0.0,
                 springref=0.0, limits=None, margin=0.0, frictionloss=0.0, limit_softness=None,
                 friction_softness=None, joint_name=None) -> int:  # fmt: skip
        """Add a link joined to ``parent`` by ``joint``; returns its index.

        Args:
            joint: ``Revolute(axis)``, ``Prismatic(axis)``, ``Ball()``, ``Free()`` or ``Fixed()``.
            parent: ``None`` (the base) or the index of an earlier link.
            position: (3,) [m], orientation: (4,): the link (joint) frame in the parent frame at zero joint
                displacement. For a ``Free`` joint, the initial pose (its coordinates are the pose itself).
            shape: a :class:`~tumble.shapes.Shape` with ``mass=`` or ``density=``, placed in the link frame at
                ``shape_position``/``shape_orientation``. Without a shape, ``mass=`` alone is a point mass at
                ``shape_position``.
            mass_properties: a :class:`~tumble.mass.MassProperties` already in the link frame (instead of
                ``shape``/``mass``/``density``). With none of these the link is massless: allowed, but the
                mass matrix must stay positive definite (every joint must move some mass or inertia), which
                the dynamics check.
            damping: >= 0, joint damping: a force ``-damping q̇`` on each of the joint's degrees of freedom.
            name: optional unique label.
            armature: >= 0, inertia [kg m² or kg] added to each of the joint's degrees of freedom: the reflected
                inertia of a motor's rotor, on the mass matrix's diagonal (MuJoCo's ``armature``).
            stiffness: >= 0, springref: a spring ``-stiffness (q - springref)`` on a ``Revolute`` or ``Prismatic``
                joint; its energy counts in ``potential_energy``.
            limits: ``(lower, upper)`` [rad or m] of a ``Revolute`` or ``Prismatic`` joint's coordinate, or ``None``;
                each acts once the coordinate is within ``margin`` >= 0 of it, as a soft constraint with
                ``limit_softness`` (a :class:`SoftConstraint`, default MuJoCo's ``solref``/``solimp``).
            frictionloss: >= 0, dry friction [N m or N] on each of the joint's degrees of freedom: a constraint force
                of at most that much against the motion, soft as ``friction_softness`` says (MuJoCo's joint
                ``frictionloss``; ``constraints.py``).
            joint_name: optional, unique among the joints: :meth:`joint` finds the joint by it.
        """
        if not isinstance(joint, Joint):
            raise TypeError(f"joint must be a Revolute, Prismatic, Ball, Free or Fixed, got {_show(joint)}")
        index = len(self._links)
        parent = self._check_parent(parent, index)
        position = readonly(as_vector3("position", position))
        orientation = readonly(as_quaternion("orientation", orientation))
        shape_position = readonly(as_vector3("shape_position", shape_position))
        shape_orientation = readonly(as_quaternion("shape_orientation", shape_orientation))
        properties = _mass_properties(shape, mass, density, mass_properties, shape_position, shape_orientation)
        damping = as_float("damping", damping, nonnegative=True)
        armature = as_float("armature", armature, nonnegative=True)
        stiffness = as_float("stiffness", stiffness, nonnegative=True)
        springref = as_float("springref", springref)
        if stiffness != 0.0 and not isinstance(joint, (Revolute, Prismatic)):
            raise ValueError(f"stiffness={stiffness!r} needs a Revolute or Prismatic joint, got {joint!r}")
        limits = check_limits("limits", limits)
        if limits is not None and not isinstance(joint, (Revolute, Prismatic)):
            raise ValueError(f"limits={limits!r} need a Revolute or Prismatic joint, got {joint!r}")
        margin = as_float("margin", margin, nonnegative=True)
        frictionloss = as_float("frictionloss", frictionloss, nonnegative=True)
        limit_softness = softness("limit_softness", limit_softness)
        friction_softness = softness("friction_softness", friction_softness)
        if (limits is not None or frictionloss > 0.0) and self._loops:
            raise ValueError("limits and frictionloss are not simulated with loop closures (yet); this articulation "
                             "has loop closures")  # fmt: skip
        if name is not None and not isinstance(name, str):
            raise TypeError(f"name must be a string or None, got {_show(name)}")
        if name is not None and any(link.name == name for link in self._links):
            raise ValueError(f"name must be unique, got {name!r} (link {self.link_index(name)} has it)")
        if joint_name is not None and not isinstance(joint_name, str):
            raise TypeError(f"joint_name must be a string or None, got {_show(joint_name)}")
        if joint_name is not None and any(link.joint_name == joint_name for link in self._links):
            raise ValueError(f"joint_name must be unique, got {joint_name!r}")
        nq, nv = self.nq, self.nv
        link = Link(index, name, parent, joint, position, orientation, properties, damping,
                    slice(nq, nq + joint.nq), slice(nv, nv + joint.nv), shape, shape_position,
                    shape_orientation, armature, stiffness, springref, limits, margin, frictionloss, limit_softness,
                    friction_softness, joint_name)  # fmt: skip
        if isinstance(joint, Ball):
            self._quat_starts.append((nq, index))
        elif isinstance(joint, Free):
            self._quat_starts.append((nq + 3, index))
        self._links.append(link)
        self._q = np.concatenate([self._q, _initial_coordinates(link)])
        self._qd = np.concatenate([self._qd, np.zeros(joint.nv)])
        self._compiled = None
        return index

    def add_loop_closure(self, link_a, point_a, link_b=None, point_b=(0.0, 0.0, 0.0), kind="point") -> int:
        """Close a loop: keep ``point_a`` of ``link_a`` on ``point_b`` of ``link_b``; returns the closure's index.

        Args:
            link_a: a link index; point_a: (3,) [m] in its frame.
            link_b: another link index, or ``None`` for the world (``point_b`` is then a world point).
            point_b: (3,) [m] in ``link_b``'s frame.
            kind: ``"point"`` (the two points coincide: three constraint rows; rows that a planar mechanism
                makes redundant are detected and dropped).
        """
        link_a = self._check_link("link_a", link_a)
        link_b = None if link_b is None else self._check_link("link_b", link_b)
        if link_a == link_b:
            raise ValueError(f"link_b must differ from link_a, got both {link_a}")
        if not isinstance(kind, str) or kind not in LOOP_KINDS:
            raise ValueError(f"kind must be one of {LOOP_KINDS}, got {_show(kind)}")
        if self._has_soft_constraints():
            raise ValueError("loop closures are not simulated with limits, frictionloss, tendons or geoms (yet); this "
                             "articulation has some")  # fmt: skip
        loop = LoopClosure(len(self._loops), link_a, readonly(as_vector3("point_a", point_a)), link_b,
                           readonly(as_vector3("point_b", point_b)), kind)  # fmt: skip
        self._loops.append(loop)
        self._compiled = None
        return loop.index

    def _has_soft_constraints(self) -> bool:
        limited = any(link.limits is not None or link.frictionloss > 0.0 for link in self._links)
        return limited or bool(self._tendons) or bool(self._geoms)

    # --- description -----------------------------------------------------------------------------------

    @property
    def links(self) -> tuple[Link, ...]:
        return tuple(self._links)

    @property
    def loop_closures(self) -> tuple[LoopClosure, ...]:
        return tuple(self._loops)

    @property
    def link_count(self) -> int:
        return len(self._links)

    def link_index(self, name: str) -> int:
        """The index of the link called ``name``."""
        for link in self._links:
            if link.name == name:
                return link.index
        raise ValueError(f"name must be the name of a link, got {name!r}")

    def joint(self, name: str) -> ArticulationJoint:
        """The joint called ``name`` (its link's ``joint_name``; a model file's joint names): ``.angle``,
        ``.angular_speed`` of a hinge, ``.translation``, ``.speed`` of a slide, settable."""
        for link in self._links:
            if link.joint_name == name and name is not None:
                return ArticulationJoint(self, link.index, name)
        names = sorted(link.joint_name for link in self._links if link.joint_name is not None)
        raise KeyError(f"no joint named {name!r}; names: {names}")

    @property
    def gravity(self) -> np.ndarray:
        return self._gravity.copy()

    @property
    def base_position(self) -> np.ndarray:
        return self._base_position.copy()

    @property
    def base_orientation(self) -> np.ndarray:
        return self._base_orientation.copy()

    @property
    def nq(self) -> int:
        """The number of position coordinates (quaternions count 4)."""
        return self._q.shape[0]

    @property
    def nv(self) -> int:
        """The number of velocity coordinates (degrees of freedom)."""
        return self._qd.shape[0]

    # --- state -----------------------------------------------------------------------------------------

    @property
    def q(self) -> np.ndarray:
        """(nq,) the joint coordinates (a copy); setting validates and renormalises quaternions."""
        return self._q.copy()

    @q.setter
    def q(self, value) -> None:
        self._q = self._check_q("q", value)

    @property
    def qd(self) -> np.ndarray:
        """(nv,) the joint velocities (a copy)."""
        return self._qd.copy()

    @qd.setter
    def qd(self, value) -> None:
        self._qd = self._check_vector("qd", value, self.nv)

    @property
    def time(self) -> float:
        return self._time

    @time.setter
    def time(self, value) -> None:
        self._time = as_float("time", value)

    def set_joint(self, link, q=None, qd=None) -> None:
        """Set one link's joint coordinates and/or velocities (a scalar is fine for a one-coordinate joint)."""
        info = self._links[self._check_link("link", link)]
        new_q, new_qd = self._q.copy(), self._qd.copy()
        if q is not None:
            new_q[info.q_slice] = _joint_values("q", q, info.joint.nq)
            new_q = self._check_q("q", new_q)
        if qd is not None:
            new_qd[info.v_slice] = _joint_values("qd", qd, info.joint.nv)
        self._q, self._qd = new_q, new_qd

    # --- kinematics ------------------------------------------------------------------------------------

    def link_poses(self, q=None) -> tuple[np.ndarray, np.ndarray]:
        """World poses of the link frames: ``(positions (n, 3) [m], quaternions (n, 4))``."""
        _, w = self._evaluate(KINEMATICS, q=q, qd=self._compile().zero_v)
        return w.link_work[:, POS : POS + 3].copy(), w.link_work[:, QUAT : QUAT + 4].copy()

    def link_velocities(self, q=None, qd=None) -> tuple[np.ndarray, np.ndarray]:
        """World velocities: ``(linear velocity of each link origin (n, 3) [m/s], angular (n, 3) [rad/s])``."""
        _, w = self._evaluate(KINEMATICS, q=q, qd=qd)
        angular, linear = w.link_work[:, VEL : VEL + 3], w.link_work[:, VEL + 3 : VEL + 6]
        # the velocity of the origin of each link from that of the point at the world origin
        return linear + np.cross(angular, w.link_work[:, POS : POS + 3]), angular.copy()

    def jacobian(self, link, point=None, q=None) -> np.ndarray:
        """The world-frame Jacobian (6, nv): rows ``[linear velocity of point; angular velocity]`` of ``link``.

        Args:
            link: a link index; point: (3,) [m] in the link frame, default its origin; q: default the state.
        """
        index = self._check_link("link", link)
        local = np.zeros(3) if point is None else as_vector3("point", point)
        m, w = self._evaluate(KINEMATICS, q=q, qd=self._compile().zero_v)
        row = w.link_work[index]
        x = row[POS : POS + 3] + portable.matvec(quat_to_matrix(row[QUAT : QUAT + 4]), local)
        jac = np.zeros((6, self.nv))
        k = int(m.link_ints[index, DOF_TIP])
        while k >= 0:
            angular, linear = w.dof_motion[k, :3], w.dof_motion[k, 3:]
            jac[:3, k] = linear + np.cross(angular, x)
            jac[3:, k] = angular
            k = int(m.dof_ints[k, DOF_PARENT])
        return jac

    def contacts(self, q=None) -> ArticulationContacts:
        """The contacts of the geoms at ``q`` (default the current coordinates): MuJoCo's, within each pair's margin."""
        c = self._compile()
        q = self._q.copy() if q is None else self._check_q("q", q)
        found, _, _ = articulation_kernel(c.ints, c.reals, q, c.zero_v, c.zero_v, c.zero_external, False, c.work,
                                          c.out_v, c.no_record, 0.0, 0, 0, 1, CONTACTS)  # fmt: skip
        model, w = c.views()
        rows = w.contact_work[:found]
        pairs = model.pair_ints[rows[:, CONTACT_PAIR].astype(np.int64)]
        return ArticulationContacts(pairs[:, :2].copy(), rows[:, CONTACT_POINT : CONTACT_POINT + 3].copy(),
                                    rows[:, CONTACT_NORMAL : CONTACT_NORMAL + 3].copy(),
                                    rows[:, CONTACT_DIST].copy())  # fmt: skip

    @property
    def impratio(self) -> float:
        """MuJoCo's ``impratio`` (> 0, default 1): the contacts' friction rows are weighted by ``1 / impratio``."""
        return self._impratio

    @impratio.setter
    def impratio(self, value) -> None:
        self._impratio = as_float("impratio", value, positive=True)
        self._compiled = None

    def com(self, q=None) -> np.ndarray:
        """(3,) [m]: the centre of mass of all links, world frame."""
        _, w = self._evaluate(KINEMATICS, q=q, qd=self._compile().zero_v)
        spatial_inertia = w.link_work[:, INERTIA_WORLD : INERTIA_WORLD + 4]  # mass, then mass times position
        mass = float(spatial_inertia[:, 0].sum())
        if not mass > 0.0:
            raise ValueError("com: the articulation has no mass")
        return spatial_inertia[:, 1:].sum(axis=0) / mass

    def loop_closure_error(self, q=None) -> np.ndarray:
        """(L, 3) [m]: ``x_a - x_b`` of every loop closure, world frame (zero when closed)."""
        _, w = self._evaluate(KINEMATICS, q=q, qd=self._compile().zero_v)
        return w.loop_work[LOOP_ERROR].reshape(-1, 3).copy()

    def integrate(self, q, v, dt=1.0) -> np.ndarray:
        """``q ⊕ dt v``: coordinates (nq,) moved by the velocity ``v`` (nv,) for ``dt`` seconds (quaternions by
        the exponential map, ``ω`` in the link frame). A pure function of its arguments."""
        q = self._check_q("q", q)
        v = self._check_vector("v", v, self.nv)
        dt = as_float("dt", dt)
        out = q.copy()
        for link in self._links:
            qs, vs = link.q_slice, link.v_slice
            if isinstance(link.joint, (Ball, Free)):
                rot = 3 if isinstance(link.joint, Free) else 0
                out[qs.start : qs.start + rot] += dt * v[vs.start : vs.start + rot]
                turn = quat_from_rotvec(dt * v[vs.start + rot : vs.stop])
                out[qs.start + rot : qs.stop] = quat_multiply(q[qs.start + rot : qs.stop], turn)
            else:
                out[qs] += dt * v[vs]
        return self._check_q("q", out)

    # --- dynamics --------------------------------------------------------------------------------------

    def inverse_dynamics(self, q, qd, qdd, external=None) -> np.ndarray:
        """(nv,) the joint forces ``τ = H q̈ + C(q, q̇) + D q̇`` that produce ``qdd`` (RNEA; damping included).

        Args:
            q: (nq,); qd, qdd: (nv,).
            external: optional (n, 6) world-frame rows ``(force [N] at the link's centre of mass, torque [N m])``.

        Loop closures are not part of inverse dynamics (their forces ``Jᵀ λ`` are not determined by ``q̈``).
        """
        qdd = self._check_vector("qdd", qdd, self.nv)
        self._evaluate(INVERSE, q=q, qd=qd, vec_in=qdd, external=external, require_all=True)
        return self._compile().out_v.copy()

    def bias_forces(self, q=None, qd=None, external=None) -> np.ndarray:
        """(nv,) ``C(q, q̇) + D q̇``: Coriolis, centrifugal, gravity and damping forces (``τ`` at ``q̈ = 0``)."""
        self._evaluate(INVERSE, q=q, qd=qd, vec_in=self._compile().zero_v, external=external)
        return self._compile().out_v.copy()

    def mass_matrix(self, q=None) -> np.ndarray:
        """(nv, nv) the joint-space inertia matrix ``H(q)`` by the composite-rigid-body algorithm."""
        _, w = self._evaluate(MASS_MATRIX, q=q, qd=self._compile().zero_v)
        return w.mass_matrix.copy()

    def forward_dynamics(self, q=None, qd=None, tau=None, external=None) -> np.ndarray:
        """(nv,) ``q̈`` for the joint forces ``tau`` (default zero), loop closures enforced.

        Raises:
            SimulationError: the mass matrix is singular (a joint moves no mass).
        """
        tau = self._compile().zero_v if tau is None else self._check_vector("tau", tau, self.nv)
        self._evaluate(FORWARD, q=q, qd=qd, vec_in=tau, external=external)
        return self._compile().out_v.copy()

    def kinetic_energy(self, q=None, qd=None) -> float:
        """[J] ``½ q̇ᵀ H q̇``."""
        _, w = self._evaluate(KINEMATICS, q=q, qd=qd)
        return float(w.energy[0])

    def potential_energy(self, q=None) -> float:
        """[J] ``-Σ m g · c`` (zero with every centre of mass at the world origin)."""
        _, w = self._evaluate(KINEMATICS, q=q, qd=self._compile().zero_v)
        return float(w.energy[1])

    def energy(self, q=None, qd=None) -> float:
        """[J] kinetic plus potential energy."""
        _, w = self._evaluate(KINEMATICS, q=q, qd=qd)
        return float(w.energy[0] + w.energy[1])

    def project_loop_closures(self) -> None:
        """Move the state onto the loop closures: ``q`` by Gauss–Newton steps, then ``qd`` by the
        mass-weighted projection (as after every step). Use it to assemble a closed chain from a guess."""
        compiled = self._compile()
        q, qd = self._q.copy(), self._qd.copy()
        self._run(compiled, PROJECT, q, qd, compiled.zero_v, compiled.zero_external)
        if not (np.all(np.isfinite(q)) and np.all(np.isfinite(qd))):
            raise SimulationError("project_loop_closures produced a non-finite state; the state is unchanged")
        self._q, self._qd = q, qd

    # --- time stepping ---------------------------------------------------------------------------------

    def step(self, dt, tau=None, integrator="symplectic", external=None) -> None:
        """Advance the state by ``dt`` seconds under joint forces ``tau`` (nv,) (default zero).

        ``integrator``: ``"symplectic"`` (semi-implicit Euler), ``"rk4"``, ``"euler"``, or
        ``"symplectic_implicit_damping"`` (MuJoCo's Euler: the joints' damping implicit, ``integrators.py``).
        ``external``: optional (n, 6) world-frame rows (force [N] at each link's centre of mass, torque [N m]) held
        over the step. On a :class:`~tumble.SimulationError` the state stays as it was.
        """
        dt = as_step("dt", dt, self._time)
        method = _check_integrator(integrator)
        c = self._compiled if self._compiled is not None else self._compile()
        tau = c.zero_v if tau is None else self._check_vector("tau", tau, self.nv)
        forces = c.zero_external if external is None else self._check_external(external)
        _, status, where = articulation_kernel(c.ints, c.reals, self._q, self._qd, tau, forces, external is not None,
                                               c.work, c.out_v, c.no_record, dt, method, 1, 1, SIMULATE)  # fmt: skip
        if status:
            raise self._step_error(status, where, self._step_count)
        self._time += dt
        self._step_count += 1

    def simulate(
        self, duration, dt, tau=None, integrator="rk4", record_every=1, external=None
    ) -> ArticulationTrajectory:
        """Take ``round(duration / dt)`` steps in one compiled loop, recording every ``record_every`` steps.

        The trajectory starts with the current state. ``tau`` (nv,) and ``external`` (n, 6) are held constant
        (use :meth:`step` in a loop for a controller). On a :class:`~tumble.SimulationError` the articulation
        keeps its last good state and the error's ``trajectory`` holds the frames recorded up to it.
        """
        duration = as_float("duration", duration, positive=True)
        dt = as_step("dt", dt, self._time)
        method = _check_integrator(integrator)
        every = as_count("record_every", record_every)
        steps = step_count(duration, dt)
        frames = steps // every + 1
        require_memory(8 * frames * (self.nq + self.nv + 1), f"recording {frames} frames",
                       "record fewer frames (a larger record_every, a shorter duration)")  # fmt: skip
        c = self._compile()
        tau = c.zero_v if tau is None else self._check_vector("tau", tau, self.nv)
        forces = c.zero_external if external is None else self._check_external(external)
        nq, nv = self.nq, self.nv
        record = np.empty((frames, nq + nv + 1))
        done, status, where = articulation_kernel(c.ints, c.reals, self._q, self._qd, tau, forces,
                                                  external is not None, c.work, c.out_v, record, dt, method, steps,
                                                  every, SIMULATE)  # fmt: skip
        kept = record[: done // every + 1]
        t0 = self._time
        trajectory = ArticulationTrajectory(t0 + dt * every * np.arange(len(kept)), kept[:, :nq].copy(),
                                            kept[:, nq : nq + nv].copy(), kept[:, nq + nv].copy(), dt,
                                            integrator)  # fmt: skip
        self._time = t0 + done * dt
        self._step_count += done
        if status:
            error = self._step_error(status, where, self._step_count)
            error.trajectory = trajectory
            raise error
        return trajectory

    # --- internals -------------------------------------------------------------------------------------

    def _compile(self) -> _Compiled:
        if self._compiled is None:
            nq, nv = self.nq, self.nv
            actuated = {a.link for a in self._actuators if a.link is not None}
            scalars, link_scalar, tendon_scalar = pack_scalars(self._links, self._tendons, actuated, nq, nv)
            rows = pack_actuators(self._actuators, lambda a: link_scalar[a.link] if a.tendon is None
                                 else tendon_scalar[a.tendon], self._ctrl)  # fmt: skip
            ints, reals = pack_model(self._links, self._loops, self._gravity, self._base_position,
                                     self._base_orientation, scalars, rows, pack_geoms(self._geoms),
                                     pack_pairs(self._links, self._geoms, self._excluded))  # fmt: skip
            n = len(self._links)
            self._compiled = _Compiled(
                ints, reals, np.zeros(work_size(*counts(ints))), np.zeros(nv), np.zeros((n, 6)), np.zeros(nv),
                np.zeros((0, nq + nv + 1)),
            )  # fmt: skip
            model = self._compiled.views()[0]
            if len(scalars) or len(model.pair_ints):
                initial = np.concatenate([_initial_coordinates(link) for link in self._links])
                mass_matrix = self._initial_mass_matrix(initial)
                inverse = portable.solve(mass_matrix, np.eye(len(mass_matrix)))  # once, for every weight
                model.scalar_reals[:, INVWEIGHT] = invweights(self._links, model.scalar_v, inverse)
                weights = {link: translation_weight(self.jacobian(link, self._com_point(link), initial), inverse)
                           for link in {g.link for g in self._geoms if g.link is not None}}  # fmt: skip
                pair_weights(model.pair_ints, model.pair_reals, self._geoms, weights, self._impratio)
        return self._compiled

    def _initial_mass_matrix(self, initial) -> np.ndarray:
        """``H`` at the links' zero displacement ``initial`` (a free joint at its initial pose): MuJoCo's ``qpos0``,
        where it weighs its constraints (``invweight0``)."""
        _, w = self._evaluate(MASS_MATRIX, q=initial, qd=self._compiled.zero_v)
        return w.mass_matrix.copy()

    def _com_point(self, link: int) -> np.ndarray:
        """A link's centre of mass in its frame (its origin when massless)."""
        properties = self._links[link].mass_properties
        return np.zeros(3) if properties is None else properties.com

    def _evaluate(self, mode, *, q=None, qd=None, vec_in=None, external=None, require_all=False):
        """Validate the state arguments, run one query of the kernel and return the model and work views."""
        if require_all and (q is None or qd is None):
            raise TypeError("q and qd are required")
        c = self._compile()
        q = self._q.copy() if q is None else self._check_q("q", q)
        qd = self._qd if qd is None else self._check_vector("qd", qd, self.nv)
        vec_in = c.zero_v if vec_in is None else vec_in
        external = c.zero_external if external is None else self._check_external(external)
        self._run(c, mode, q, qd, vec_in, external)
        return c.views()

    def _run(self, c, mode, q, qd, vec_in, external) -> None:
        if not self._links:
            raise ValueError("the articulation has no links; add one with add_link")
        _, status, where = articulation_kernel(c.ints, c.reals, q, qd, vec_in, external, True, c.work, c.out_v,
                                               c.no_record, 0.0, 0, 0, 1, mode)  # fmt: skip
        if status:
            raise self._singular_error(where)

    def _singular_error(self, dof: int) -> SimulationError:
        link = self._links[next(link.index for link in self._links if link.v_slice.start <= dof < link.v_slice.stop)]
        label = repr(link.name) if link.name is not None else f"#{link.index}"
        return SimulationError(
            f"the mass matrix is singular at degree of freedom {dof} (joint of link {label}): it moves no mass or "
            "inertia; give that link or one of its descendants mass_properties, a shape or a mass",
            body=link.name if link.name is not None else link.index,
            step=self._step_count,
        )

    def _step_error(self, status: int, where: int, step: int) -> SimulationError:
        if status != NOT_FINITE:
            error = self._singular_error(where)
            error.step = step
            return error
        link = self._links[where]
        label = repr(link.name) if link.name is not None else f"#{link.index}"
        return SimulationError(
            f"step {step}: link {label} got a non-finite coordinate or velocity; the articulation keeps its "
            "state from before that step",
            body=link.name if link.name is not None else link.index,
            step=step,
        )

    def _check_parent(self, parent, index: int) -> int | None:
        if parent is None:
            return None
        if isinstance(parent, (bool, np.bool_)) or not isinstance(parent, numbers.Integral):
            raise TypeError(f"parent must be None or the index (int) of an earlier link, got {_show(parent)}")
        if not 0 <= int(parent) < index:
            raise ValueError(f"parent must be None or the index of an earlier link (0 to {index - 1}), got {parent}")
        return int(parent)

    def _check_link(self, name: str, link) -> int:
        if isinstance(link, (bool, np.bool_)) or not isinstance(link, numbers.Integral):
            raise TypeError(f"{name} must be a link index (int), got {_show(link)}")
        if not 0 <= int(link) < len(self._links):
            raise ValueError(f"{name} must be a link index in 0 to {len(self._links) - 1}, got {link}")
        return int(link)

    def _check_vector(self, name: str, value, size: int) -> np.ndarray:
        return np.ascontiguousarray(as_array(name, value, (size,), batch=False), dtype=np.float64).copy()

    def _check_q(self, name: str, value) -> np.ndarray:
        return unit_quaternions(name, self._check_vector(name, value, self.nq), self._quat_starts)

    def _check_external(self, value) -> np.ndarray:
        return np.ascontiguousarray(as_array("external", value, (len(self._links), 6), batch=False)).copy()

    def __repr__(self) -> str:
        label = f"{self.name!r}, " if self.name is not None else ""
        return (f"Articulation({label}links={len(self._links)}, nq={self.nq}, nv={self.nv}, "
                f"loop_closures={len(self._loops)}, time={self._time!r})")  # fmt: skip


def unit_quaternions(name: str, q: np.ndarray, quat_starts) -> np.ndarray:
    """``q`` (nq,) or (copies, nq), changed in place, with each joint quaternion (``quat_starts``: (first row, link)
    pairs) divided by its norm; a zero or non-finite one raises, naming it. The norm is summed term by term, so a
    row gets the same bits alone or among many (``np.linalg.norm`` may sum in another order)."""
    rows = q.reshape(-1, q.shape[-1])
    for start, link in quat_starts:
        quat = rows[:, start : start + 4]
        norms = np.sqrt(quat[:, 0] ** 2 + quat[:, 1] ** 2 + quat[:, 2] ** 2 + quat[:, 3] ** 2)
        usable = norms > 1e-12
        if not usable.all():
            bad = int(np.argmin(usable))
            where = f"{bad}, " if q.ndim == 2 else ""
            raise ValueError(f"{name}[{where}{start}:{start + 4}] (link {link}) must be a non-zero quaternion, "
                             f"got {_show(quat[bad])}")  # fmt: skip
        quat /= norms[:, None]
    return q


def _initial_coordinates(link: Link) -> np.ndarray:
    """A new link's coordinates: zero displacement (the identity for a ball; a free joint's initial pose)."""
    initial = np.zeros(link.joint.nq)
    if isinstance(link.joint, Ball):
        initial[:] = (1.0, 0.0, 0.0, 0.0)
    elif isinstance(link.joint, Free):
        initial[:3], initial[3:] = link.position, link.orientation
    return initial


def _check_integrator(integrator) -> int:
    if not isinstance(integrator, str) or integrator not in INTEGRATORS:
        raise ValueError(f"integrator must be one of {tuple(INTEGRATORS)}, got {_show(integrator)}")
    return INTEGRATORS[integrator]


def _joint_values(name: str, value, size: int) -> np.ndarray:
    if size == 1 and isinstance(value, numbers.Real) and not isinstance(value, bool):
        value = [value]
    return as_array(name, value, (size,), batch=False)


def _mass_properties(shape, mass, density, mass_properties, shape_position, shape_orientation):
    """The link's MassProperties in the link frame, or None for a massless link."""
    if mass_properties is not None:
        if not isinstance(mass_properties, MassProperties):
            raise TypeError(f"mass_properties must be a MassProperties, got {_show(mass_properties)}")
        if shape is not None or mass is not None or density is not None:
            raise TypeError("give either mass_properties= or shape= with mass=/density=, not both")
        return mass_properties
    if shape is not None:
        if not isinstance(shape, Shape):
            raise TypeError(f"shape must be a tumble shape (Sphere, Box, Capsule, ...), got {_show(shape)}")
        kind, value = mass_or_density(mass, density)
        local = shape.mass_properties(**{kind: value})
        return local.transformed(shape_orientation, shape_position)
    if density is not None:
        raise TypeError(f"density= needs a shape, got density={_show(density)} and shape=None")
    if mass is not None:
        return MassProperties(as_float("mass", mass, positive=True), shape_position, np.zeros((3, 3)))
    return None
