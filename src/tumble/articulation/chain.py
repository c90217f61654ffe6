"""The short-chain path of :class:`~tumble.articulation.ArticulationBatch`: many copies of a serial chain of hinges
and slides, stepped side by side (issue 49).

``kernels.batch_kernel`` hands its copies here when the articulation is a :func:`serial_chain` (link ``i``'s parent
is link ``i - 1``, every joint a hinge or a slide, nothing to solve: no limits, dry friction, contacts, loop
closures, actuators or tendons) and no readout is asked: the pendulums and the cart-poles. It steps them
:data:`BLOCK` at a time, side by side. A block lives in one flat array, ``lanes``: a *group* of :data:`LINK_ROWS`
rows for the base and for each link, a row holding one number of every copy. Every stage of a step is a loop over the
copies whose body is straight-line arithmetic, and LLVM vectorises it (eight copies an instruction with AVX-512, four
with AVX2) on three conditions, each learnt the hard way:

- every address of the loop is a constant distance from one base, so a loop reads and writes a view of two adjacent
  groups (the link's and its parent's or child's) at constant rows (the state a stage reads is always ``Q_STAGE``);
- the body does not branch on anything that varies: the joint type is a constant of each compiled copy of a stage,
  and the last link's and the base's cases are loops apart;
- every helper is inlined into it (``inline(into_callers=True)``), and no division can raise
  (``inline(ieee_division=True)``).

A copy's arithmetic is that of ``integrators.step`` on a tree, through the same helpers of ``kinematics.py`` and
``aba.py`` in the same order, so a copy moves bit for bit as it does alone or on the per-copy path, on any CPU. Only
the order of work between copies changes, and where the branches are: a hinge's ``sin`` and ``cos`` (``elementary``,
which branch on the quadrant) run in a loop of their own, and a singular pivot or a non-finite value is flagged
rather than returned. A block in which any copy meets one is left as it was; :func:`chain_steps` hands it back to
the caller, which steps it again copy by copy on the per-copy path, which stops that copy and says where and why.
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import inline
from ..elementary import SIN_COS_RANGE
from ..math3d import scale
from .aba import add_articulated, dof_inwards, dof_outwards, eliminate_dof, handed_bias, link_articulated, pivot_scale
from .dynamics import SINGULAR_RTOL
from .integrators import EULER, RK4, SYMPLECTIC, rk4_stage
from .joints import JointType
from .kinematics import axis_angle_quat, axis_angle_quat_near, one_dof_link
from .model import AXIS, BASE_POS, BASE_QUAT, COM, GRAVITY, JOINT, MASS, ORIGIN_POS, ORIGIN_QUAT, PARENT
from .model import INERTIA as INERTIA_LOCAL
from .spatial import ZERO6, add6, get3, get4, get9, inertia_world, vec3, vec4

__all__ = ["BLOCK", "chain_steps", "serial_chain", "takes_short_chain"]

BLOCK = 64  # copies side by side: a three-link chain's block (300 kB) stays in the L2 cache; 32 or 128 run slower
_REVOLUTE = int(JointType.REVOLUTE)
_PRISMATIC = int(JointType.PRISMATIC)
_NO_TURN = (1.0, 0.0, 0.0, 0.0)

# A group's rows. Group 0 is the base (its pose, zero velocity, -g as its acceleration, 0 as the pivots' scale), group
# i + 1 link i. The kinematics: pose, velocity, velocity product, motion column, spatial inertia, hinge turn. The
# ABA: U, pivot, the articulated inertia and bias the link hands its parent, its acceleration, the pivots' scale
# (running outwards, then the chain's inwards), and whether a pivot was singular. The state of the link's degree of
# freedom: coordinate, velocity, force, and the integrators' start, stage and sums (integrators.step).
POS, QUAT, VEL, PRODUCT, MOTION, INERTIA, TURN = 0, 3, 7, 13, 19, 25, 35
U, PIVOT, HANDED_INERTIA, HANDED_BIAS, ACC, LARGEST, BAD = 39, 45, 46, 67, 73, 79, 80
Q, QD, TAU, Q_START, QD_START, Q_STAGE, QD_STAGE, QDD, QDD_SUM, QD_SUM, CHART = range(81, 92)
ARTICULATED = 92  # the articulated inertia (21) and bias (6) of the link and its subtree so far
LINK_ROWS = 119
GROUP, OWN = LINK_ROWS * BLOCK, LINK_ROWS  # a group's numbers; the row of the second group of a view of two


@inline
def takes_short_chain(m, method, reading):
    """Whether ``batch_kernel`` steps the copies here: a :func:`serial_chain`, an explicit integrator (not MuJoCo's
    implicit damping), and no readout (``reading``)."""
    return not reading and (method == EULER or method == SYMPLECTIC or method == RK4) and serial_chain(m)


@inline
def serial_chain(m):
    """Whether the model takes this path: a serial chain of hinges and slides with nothing to solve."""
    if m.loop_ints.shape[0] > 0 or m.scalar_reals.shape[0] > 0 or m.act_ints.shape[0] > 0:
        return False
    if m.pair_ints.shape[0] > 0:
        return False
    link_ints = m.link_ints
    for i in range(link_ints.shape[0]):
        kind = link_ints[i, JOINT]
        if (kind != _REVOLUTE and kind != _PRISMATIC) or link_ints[i, PARENT] != i - 1:
            return False
    return True


# Copy c's numbers in rows row, row + 1, ... of a view of groups (row r of copy c at r * BLOCK + c).
@inline(into_callers=True)
def _get3(lanes, row, c):
    return (lanes[row * BLOCK + c], lanes[(row + 1) * BLOCK + c], lanes[(row + 2) * BLOCK + c])


@inline(into_callers=True)
def _get4(lanes, row, c):
    return _get3(lanes, row, c) + (lanes[(row + 3) * BLOCK + c],)


@inline(into_callers=True)
def _get6(lanes, row, c):
    return (_get3(lanes, row, c), _get3(lanes, row + 3, c))


@inline(into_callers=True)
def _get10(lanes, row, c):
    return _get4(lanes, row, c) + _get3(lanes, row + 4, c) + _get3(lanes, row + 7, c)


@inline(into_callers=True)
def _get21(lanes, row, c):
    return _get10(lanes, row, c) + _get10(lanes, row + 10, c) + (lanes[(row + 20) * BLOCK + c],)


@inline(into_callers=True)
def _put3(lanes, row, c, v):
    lanes[row * BLOCK + c] = v[0]
    lanes[(row + 1) * BLOCK + c] = v[1]
    lanes[(row + 2) * BLOCK + c] = v[2]


@inline(into_callers=True)
def _put4(lanes, row, c, v):
    _put3(lanes, row, c, (v[0], v[1], v[2]))
    lanes[(row + 3) * BLOCK + c] = v[3]


@inline(into_callers=True)
def _put6(lanes, row, c, v):
    _put3(lanes, row, c, v[0])
    _put3(lanes, row + 3, c, v[1])


@inline(into_callers=True)
def _put10(lanes, row, c, v):
    _put4(lanes, row, c, (v[0], v[1], v[2], v[3]))
    _put6(lanes, row + 4, c, ((v[4], v[5], v[6]), (v[7], v[8], v[9])))


@inline(into_callers=True)
def _put21(lanes, row, c, v):
    _put10(lanes, row, c, (v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8], v[9]))
    _put10(lanes, row + 10, c, (v[10], v[11], v[12], v[13], v[14], v[15], v[16], v[17], v[18], v[19]))
    lanes[(row + 20) * BLOCK + c] = v[20]


# The stages of an evaluation, each a loop over the copies without branches on the copies' values (a branch keeps
# LLVM from vectorising it), in a function of its own so that nothing it computes outlives it.
@inline(into_callers=True, ieee_division=True)
def _turns(pair, b, axis):
    """A hinge's turn of each copy (``kinematics.axis_angle_quat``): branch-free (``elementary.sin_cos``), which
    vectorises, when every angle of the block is in its range, else copy by copy."""
    near = True
    for c in range(b):
        near = near and abs(0.5 * pair[(OWN + Q_STAGE) * BLOCK + c]) <= SIN_COS_RANGE  # false for inf and NaN
    if near:
        for c in range(b):
            _put4(pair, OWN + TURN, c, axis_angle_quat_near(axis, pair[(OWN + Q_STAGE) * BLOCK + c]))
        return
    for c in range(b):
        _put4(pair, OWN + TURN, c, axis_angle_quat(axis, pair[(OWN + Q_STAGE) * BLOCK + c]))


@inline(into_callers=True, ieee_division=True)
def _kinematics(pair, b, kind, axis, rel_pos, rel_quat, mass, com, inertia_local):
    """A link's pose, motion column, velocity, velocity product and spatial inertia from its parent's
    (``kinematics.forward_kinematics``), and the pivots' scale so far."""
    for c in range(b):
        turn = _get4(pair, OWN + TURN, c) if kind == _REVOLUTE else _NO_TURN
        pos, quat, s, vel, product = one_dof_link(
            kind, _get3(pair, POS, c), _get4(pair, QUAT, c), _get6(pair, VEL, c), rel_pos, rel_quat, axis, turn,
            pair[(OWN + Q_STAGE) * BLOCK + c], pair[(OWN + QD_STAGE) * BLOCK + c],
        )  # fmt: skip
        inertia = inertia_world(mass, com, inertia_local, pos, quat)
        _put3(pair, OWN + POS, c, pos)
        _put4(pair, OWN + QUAT, c, quat)
        _put6(pair, OWN + VEL, c, vel)
        _put6(pair, OWN + PRODUCT, c, product)
        _put6(pair, OWN + MOTION, c, s)
        _put10(pair, OWN + INERTIA, c, inertia)
        pair[(OWN + LARGEST) * BLOCK + c] = pivot_scale(pair[LARGEST * BLOCK + c], inertia)


@inline(into_callers=True, ieee_division=True)
def _own_articulated(pair, b):
    """A link's own articulated inertia and bias (``aba.link_articulated``)."""
    for c in range(b):
        inertia, bias = link_articulated(_get10(pair, INERTIA, c), _get6(pair, VEL, c))
        _put21(pair, ARTICULATED, c, inertia)
        _put6(pair, ARTICULATED + 21, c, bias)


@inline(into_callers=True, ieee_division=True)
def _add_child(pair, b):
    """The articulated inertia and bias its child handed the link, and the chain's pivot scale."""
    for c in range(b):
        _put21(
            pair, ARTICULATED, c, add_articulated(_get21(pair, ARTICULATED, c), _get21(pair, OWN + HANDED_INERTIA, c))
        )
        _put6(pair, ARTICULATED + 21, c, add6(_get6(pair, ARTICULATED + 21, c), _get6(pair, OWN + HANDED_BIAS, c)))
        pair[LARGEST * BLOCK + c] = pair[(OWN + LARGEST) * BLOCK + c]


@inline(into_callers=True, ieee_division=True)
def _pivot(pair, b, params):
    """The link's ``U``, pivot ``D`` and ``u`` (``aba.dof_inwards``, ``u`` into ``QDD``); ``BAD`` where ``D`` is
    singular."""
    for c in range(b):
        u_vec, pivot, u = dof_inwards(_get21(pair, ARTICULATED, c), _get6(pair, ARTICULATED + 21, c),
                                      _get6(pair, MOTION, c), params, pair[TAU * BLOCK + c], pair[Q_STAGE * BLOCK + c],
                                      pair[QD_STAGE * BLOCK + c])  # fmt: skip
        singular = not pivot > SINGULAR_RTOL * pair[LARGEST * BLOCK + c]
        pair[BAD * BLOCK + c] = 1.0 if singular else pair[BAD * BLOCK + c]
        _put6(pair, U, c, u_vec)
        pair[PIVOT * BLOCK + c] = pivot
        pair[QDD * BLOCK + c] = u


@inline(into_callers=True, ieee_division=True)
def _hand_inwards(pair, b):
    """What the link hands its parent: its articulated inertia and bias with its degree of freedom made free."""
    for c in range(b):
        inertia, bias = eliminate_dof(_get21(pair, ARTICULATED, c), _get6(pair, ARTICULATED + 21, c),
                                      _get6(pair, U, c), pair[PIVOT * BLOCK + c], pair[QDD * BLOCK + c])  # fmt: skip
        _put21(pair, HANDED_INERTIA, c, inertia)
        _put6(pair, HANDED_BIAS, c, handed_bias(inertia, bias, _get6(pair, PRODUCT, c)))


@inline(into_callers=True, ieee_division=True)
def _accelerate(pair, b):
    """The link's ``q̈`` (into ``QDD``) and acceleration from its parent's (``aba.dof_outwards``)."""
    for c in range(b):
        acc = add6(_get6(pair, ACC, c), _get6(pair, OWN + PRODUCT, c))
        qdd, acc = dof_outwards(acc, _get6(pair, OWN + U, c), _get6(pair, OWN + MOTION, c),
                                pair[(OWN + PIVOT) * BLOCK + c], pair[(OWN + QDD) * BLOCK + c])  # fmt: skip
        pair[(OWN + QDD) * BLOCK + c] = qdd
        _put6(pair, OWN + ACC, c, acc)


@inline(ieee_division=True)
def _evaluate(m, lanes, b):
    """``q̈`` into the rows ``QDD`` at the copies' coordinates and velocities in rows ``Q_STAGE`` and ``QD_STAGE``
    under ``TAU``: the kinematics and the articulated-body algorithm of a tree (``kinematics.forward_kinematics``,
    ``aba.aba``), link by link. A copy whose pivot is singular gets ``BAD`` set. A view of two groups (``pair``) is
    a link's and its parent's or child's: one base for every address of a loop, which LLVM needs to vectorise it."""
    link_ints, link_reals, dof_params = m.link_ints, m.link_reals, m.dof_params
    n = link_ints.shape[0]
    for i in range(n):  # outwards: the kinematics
        kind, axis = link_ints[i, JOINT], get3(link_reals, i, AXIS)
        pair = lanes[i * GROUP : (i + 2) * GROUP]  # the parent's group, then the link's (row OWN on)
        rel_pos, rel_quat = get3(link_reals, i, ORIGIN_POS), get4(link_reals, i, ORIGIN_QUAT)
        mass, com, inertia_local = link_reals[i, MASS], get3(link_reals, i, COM), get9(link_reals, i, INERTIA_LOCAL)
        if kind == _REVOLUTE:  # the joint type a constant in each copy of the loop, which has no branch then
            _turns(pair, b, axis)
            _kinematics(pair, b, _REVOLUTE, axis, rel_pos, rel_quat, mass, com, inertia_local)
        else:
            _kinematics(pair, b, _PRISMATIC, axis, rel_pos, rel_quat, mass, com, inertia_local)
    for i in range(n - 1, -1, -1):  # inwards: each link hands its articulated inertia and bias to its parent
        pair = lanes[(i + 1) * GROUP : (i + 3) * GROUP]  # the link's group (row 0 on), then its child's (row OWN on)
        _own_articulated(pair, b)
        if i < n - 1:
            _add_child(pair, b)
        _pivot(pair, b, get4(dof_params, i, 0))
        if i > 0:
            _hand_inwards(pair, b)
    for i in range(n):  # outwards: the accelerations, from the base's -g
        _accelerate(lanes[i * GROUP : (i + 2) * GROUP], b)


@inline(ieee_division=True)
def _step(m, lanes, h, method, b):
    """One step of ``h`` seconds of the block's copies: ``integrators.step`` on a tree of one-degree-of-freedom
    joints, whose configuration update ``q ⊕ h v`` is ``q + h v``."""
    n = m.link_ints.shape[0]
    for i in range(n):
        own = lanes[(i + 1) * GROUP : (i + 2) * GROUP]
        for c in range(b):
            own[Q_START * BLOCK + c] = own[Q * BLOCK + c]
            own[QD_START * BLOCK + c] = own[QD * BLOCK + c]
    if method == RK4:
        for i in range(n):
            own = lanes[(i + 1) * GROUP : (i + 2) * GROUP]
            for c in range(b):
                own[Q_STAGE * BLOCK + c] = own[Q * BLOCK + c]
                own[QD_STAGE * BLOCK + c] = own[QD * BLOCK + c]
                own[QDD_SUM * BLOCK + c] = 0.0
                own[QD_SUM * BLOCK + c] = 0.0
                own[CHART * BLOCK + c] = 0.0
        for stage in range(4):
            _evaluate(m, lanes, b)
            weight, reach = rk4_stage(stage, h)
            for i in range(n):
                own = lanes[(i + 1) * GROUP : (i + 2) * GROUP]
                for c in range(b):
                    rate = own[QD_STAGE * BLOCK + c]
                    own[QD_SUM * BLOCK + c] += weight * rate  # integrators._chart_rates of a hinge or slide
                    own[CHART * BLOCK + c] = reach * rate
                    own[QDD_SUM * BLOCK + c] += weight * own[QDD * BLOCK + c]
                    if stage < 3:
                        own[Q_STAGE * BLOCK + c] = own[Q_START * BLOCK + c] + 1.0 * own[CHART * BLOCK + c]
                        own[QD_STAGE * BLOCK + c] = own[QD_START * BLOCK + c] + reach * own[QDD * BLOCK + c]
        for i in range(n):
            own = lanes[(i + 1) * GROUP : (i + 2) * GROUP]
            for c in range(b):
                own[QD_SUM * BLOCK + c] /= 6.0
                own[QD * BLOCK + c] = own[QD_START * BLOCK + c] + (h / 6.0) * own[QDD_SUM * BLOCK + c]
                own[Q * BLOCK + c] = own[Q_START * BLOCK + c] + h * own[QD_SUM * BLOCK + c]
        return
    for i in range(n):
        own = lanes[(i + 1) * GROUP : (i + 2) * GROUP]
        for c in range(b):
            own[Q_STAGE * BLOCK + c] = own[Q * BLOCK + c]
            own[QD_STAGE * BLOCK + c] = own[QD * BLOCK + c]
    _evaluate(m, lanes, b)
    rate_row = QD if method == SYMPLECTIC else QD_START
    for i in range(n):
        own = lanes[(i + 1) * GROUP : (i + 2) * GROUP]
        for c in range(b):
            own[QD * BLOCK + c] += h * own[QDD * BLOCK + c]
            own[Q * BLOCK + c] = own[Q_START * BLOCK + c] + h * own[rate_row * BLOCK + c]


@inline
def _start(m, lanes, q, qd, tau, block):
    """The base's group and the copies ``block``'s states into ``lanes``; every flag cleared."""
    b, n = block.shape[0], m.link_ints.shape[0]
    base, base_acc = lanes[:GROUP], ((0.0, 0.0, 0.0), scale(vec3(m.world, GRAVITY), -1.0))
    for c in range(b):
        _put3(base, POS, c, vec3(m.world, BASE_POS))
        _put4(base, QUAT, c, vec4(m.world, BASE_QUAT))
        _put6(base, VEL, c, ZERO6)
        _put6(base, ACC, c, base_acc)
        base[LARGEST * BLOCK + c] = 0.0
    for i in range(n):
        own = lanes[(i + 1) * GROUP : (i + 2) * GROUP]
        for c in range(b):
            copy = block[c]
            own[Q * BLOCK + c], own[QD * BLOCK + c], own[TAU * BLOCK + c] = q[copy, i], qd[copy, i], tau[copy, i]
            own[BAD * BLOCK + c] = 0.0


@inline
def _block_failed(lanes, n, b):
    """Whether any copy of the block has a singular pivot or a non-finite coordinate or velocity."""
    for i in range(n):
        own = lanes[(i + 1) * GROUP : (i + 2) * GROUP]
        for c in range(b):
            finite = math.isfinite(own[Q * BLOCK + c]) and math.isfinite(own[QD * BLOCK + c])
            if own[BAD * BLOCK + c] != 0.0 or not finite:
                return True
    return False


@inline
def chain_steps(m, q, qd, tau, h, method, steps, copies, unfinished):
    """``steps`` steps of ``h`` seconds of the copies ``copies`` (indices) of a :func:`serial_chain` under their
    forces ``tau`` (held), in blocks of :data:`BLOCK`. A block in which a copy meets a singular pivot or a non-finite
    value is left as it was, its copies written to the front of ``unfinished``; returns how many there are."""
    n = m.link_ints.shape[0]
    lanes = np.zeros((n + 2) * GROUP)  # the base, the links, and an empty child of the last
    left = 0
    for start in range(0, copies.shape[0], BLOCK):
        block = copies[start : start + BLOCK]
        b = block.shape[0]
        _start(m, lanes, q, qd, tau, block)
        failed = False
        for _ in range(steps):
            _step(m, lanes, h, method, b)
            failed = _block_failed(lanes, n, b)
            if failed:
                break
        if failed:
            for j in range(b):
                unfinished[left + j] = block[j]
            left += b
            continue
        for i in range(n):
            own = lanes[(i + 1) * GROUP : (i + 2) * GROUP]
            for c in range(b):
                copy = block[c]
                q[copy, i], qd[copy, i] = own[Q * BLOCK + c], own[QD * BLOCK + c]
    return left
