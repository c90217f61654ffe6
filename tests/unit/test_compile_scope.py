"""What a world compiles (issue 23): only the code it runs, once per argument type.

- Every world with contacts or joints steps through one compiled loop (issue 45), compiled once for all of them: the
  narrow phase's loop of every pair type and the joint solver are in it, so that no new kind of world compiles a
  second copy of the step (a minute each); checked in a fresh interpreter, where a kernel has signatures only once
  something asked for it (compiled, or loaded from the cache).
- A constant argument (``True``, an index ``0``, a shape code) does not compile a copy of the callee for its value:
  no compiled function of tumble has a literal type in a signature after a contact world, a jointed world and a hull
  world have stepped.
- Helpers have no Python-callable wrapper; a call from Python runs their Python source and agrees with the compiled
  code bit for bit.
"""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from compiled import compiled_only
from tumble import math3d, scenes
from tumble._jit import inline, kernel
from tumble.geometry import narrow_phase
from tumble.shapes import ShapeType

needs_jit = compiled_only("about compiled code")

_PROBE = """
import json, numpy as np, tumble
from tumble import runner
worlds = []
for shape in (tumble.Sphere(0.1), tumble.ConvexHull(np.random.default_rng(0).normal(size=(12, 3)) * 0.1)):
    world = tumble.World()
    world.add_static(tumble.Plane())
    world.add_body(shape, mass=1.0, position=(0, 0, 0.3))
    worlds.append(world)
chain = tumble.World()
a = chain.add_body(tumble.Box((0.1, 0.1, 0.1)), mass=1.0, position=(0, 0, 1.0))
b = chain.add_body(tumble.Box((0.1, 0.1, 0.1)), mass=1.0, position=(0.2, 0, 1.0))
chain.add_joint(tumble.HingeJoint(a, b, (0.1, 0, 1.0), (0, 1, 0)))
worlds.append(chain)
for world in worlds:
    for _ in range(3):
        world.step(1 / 60)
    world.simulate(0.05, 1 / 240)
tumble.Batch(worlds[0], 3).step(1 / 60, steps=2)
print(json.dumps({"loops": len(runner._plain_contact_loop.signatures)}))
"""


@needs_jit
def test_every_contact_or_jointed_world_steps_through_one_compiled_loop():
    result = subprocess.run([sys.executable, "-c", _PROBE], capture_output=True, text=True, timeout=900)
    assert result.returncode == 0, result.stderr[-3000:]
    assert json.loads(result.stdout.strip().splitlines()[-1]) == {"loops": 1}


def _literal_signatures() -> list[str]:
    """Every signature of a compiled tumble function that holds a literal type (a copy for one constant)."""
    from numba.core import types
    from numba.core.registry import CPUDispatcher

    found = []
    for name, module in list(sys.modules.items()):
        if not name.startswith("tumble"):
            continue
        for value in vars(module).values():
            if isinstance(value, CPUDispatcher):
                for signature in value.signatures:
                    if any(isinstance(t, types.Literal) for t in signature):
                        found.append(f"{value.py_func.__module__}.{value.__name__}{signature}")
    return sorted(set(found))


@needs_jit
def test_no_compiled_function_is_copied_for_a_constant_argument():
    worlds = [scenes.box_pile(count=4), scenes.pendulum_chain(links=3), scenes.mixed_pile(count=6)]
    for world in worlds:
        for _ in range(5):
            world.step(1 / 60)
    assert _literal_signatures() == []


@kernel
def _rotate_rows(quat, vec, out):
    for i in range(quat.shape[0]):
        math3d.store3(out, i, math3d.quat_rotate(math3d.load4(quat, i), math3d.load3(vec, i)))


def test_a_helper_called_from_python_agrees_with_the_compiled_one_bit_for_bit():
    rng = np.random.default_rng(3)
    quat = rng.normal(size=(50, 4))
    quat /= np.linalg.norm(quat, axis=1, keepdims=True)
    vec = rng.normal(size=(50, 3)) * 10.0
    compiled = np.empty_like(vec)
    _rotate_rows(quat, vec, compiled)
    from_python = np.array([math3d.quat_rotate(tuple(q), tuple(v)) for q, v in zip(quat, vec, strict=True)])
    assert np.array_equal(from_python, compiled)


def test_every_type_pair_goes_to_its_collision_function():
    s, c, b, cyl, hull, plane, mesh = (int(t) for t in ShapeType)
    expected = {
        (s, s): "sphere_sphere", (s, c): "sphere_capsule", (s, b): "sphere_box", (c, c): "capsule_capsule",
        (c, b): "capsule_box", (b, b): "box_box", (s, plane): "sphere_plane", (c, plane): "capsule_plane",
        (b, plane): "box_plane", (cyl, plane): "cylinder_plane", (hull, plane): "hull_plane",
        (s, cyl): "convex_convex", (b, hull): "convex_convex", (cyl, hull): "convex_convex",
        (hull, hull): "convex_convex", (s, mesh): "convex_trimesh", (hull, mesh): "convex_trimesh",
    }  # fmt: skip
    for (ta, tb), name in expected.items():
        assert narrow_phase._PAIR_KERNELS[narrow_phase.COLLIDER_OF[ta, tb]].__name__ == f"pairs_{name}"


def test_pairs_are_grouped_by_collision_function_in_pair_order():
    rng = np.random.default_rng(7)
    shape_type = rng.integers(0, 7, size=40)
    pairs_a, pairs_b = rng.integers(0, 40, size=300), rng.integers(0, 40, size=300)
    low = np.minimum(shape_type[pairs_a], shape_type[pairs_b]) == shape_type[pairs_a]
    pairs_a, pairs_b = np.where(low, pairs_a, pairs_b), np.where(low, pairs_b, pairs_a)  # lower shape type first
    order, starts = np.empty(300, np.int64), np.zeros(len(narrow_phase._COLLIDERS) + 1, np.int64)
    narrow_phase._group_by_collider(shape_type, pairs_a, pairs_b, narrow_phase.COLLIDER_OF, order, starts)
    which = narrow_phase.COLLIDER_OF[shape_type[pairs_a], shape_type[pairs_b]]
    assert np.array_equal(order, np.argsort(which, kind="stable"))
    assert np.array_equal(np.diff(starts), np.bincount(which, minlength=len(narrow_phase._COLLIDERS)))


def test_touching_manifolds_move_to_the_front_in_pair_order():
    rng = np.random.default_rng(8)
    manifolds = narrow_phase.allocate_manifolds(50)
    for field in manifolds:
        field[...] = rng.integers(1, 1000, size=field.shape)
    manifolds.point_count[:] = rng.integers(0, 3, size=50)
    manifolds.point_count[40:] = 1  # beyond n: not counted, not moved
    before = type(manifolds)(*(field.copy() for field in manifolds))
    touching = np.flatnonzero(before.point_count[:40] > 0)
    count = narrow_phase.keep_touching(manifolds, 40)
    assert 0 < count == touching.size < 40
    for field, old in zip(manifolds, before, strict=True):
        assert np.array_equal(field[:count], old[touching])
        assert np.array_equal(field[40:], old[40:])


@needs_jit
def test_the_free_body_integrator_compiles_its_per_body_calls_into_the_row_loop():
    """A compiled call reference-counts every array it receives: the per-body functions of the free-body integrator
    are compiled into their callers (Numba's ``inline="always"``), or every body would pay that once per call."""
    from tumble import pipeline, runner
    from tumble.dynamics import integrate

    for helper in (integrate._body_steps, runner._save_row, runner._restore_row, pipeline.contact_stages):
        assert helper.targetoptions.get("inline") == "always", helper.py_func.__name__
    # Once per call, not per body: it takes the record and holds its arrays itself (its docstring says why).
    assert "inline" not in integrate.advance_rows.targetoptions
    assert "inline" not in math3d.dot.targetoptions  # the other helpers are left to LLVM


@inline(counted=False)
def _a_view_of(a):
    return a[1:]


@kernel
def _sum_of_a_view(a):
    return _a_view_of(a).sum()


@inline(counted=False)
def _the_same(a):
    return a, 1.0


@kernel
def _sum_of_the_same(a):
    return _the_same(a)[0].sum()


@inline(counted=False)
def _a_sum_of_zeros(n):
    return np.zeros(n).sum()


@kernel
def _sum_of_zeros(n):
    return _a_sum_of_zeros(n)


@inline(counted=False)
def _doubled_in_place(a):
    for i in range(a.shape[0]):
        a[i] *= 2.0


@kernel
def _doubled(a):
    _doubled_in_place(a[1:])
    return a


@needs_jit
def test_a_helper_without_reference_counts_may_not_return_an_array_nor_allocate_one():
    """Its caller would release a reference it never got (a view's memory freed under it): refused at compile time,
    as an allocation is (there would be nothing to free it)."""
    with pytest.raises(Exception, match="may not return arrays"):  # refused by _jit
        _sum_of_the_same(np.ones(3))
    with pytest.raises(Exception, match="returning of array passed"):  # refused by Numba
        _sum_of_a_view(np.ones(3))
    with pytest.raises(Exception, match="returning of array passed|NRT required"):
        _sum_of_zeros(3)
    a = np.ones(4)
    assert _doubled(a) is a and a.tolist() == [1.0, 2.0, 2.0, 2.0]  # what it may do: write the arrays it is given


def test_the_contact_substeps_run_without_reference_counts():
    """The functions a soft step calls per substep, and once per step over many arrays, count no references: each
    array a counted function holds costs two atomic operations a call (three quarters of a box's step on a plane)."""
    from tumble.dynamics import contact_solver, islands, joint_solver, substep
    from tumble.geometry import narrow_phase as narrow

    uncounted = (substep.integrate_velocities, substep.integrate_positions, substep.to_angular_momentum,
                 contact_solver.warm_start_contacts, contact_solver.solve_contacts, contact_solver.accumulate_impulses,
                 contact_solver.resolve_impacts, contact_solver.prepare_contacts, contact_solver.store_impulses,
                 contact_solver.apply_restitution, joint_solver.warm_start_joints, narrow.match_warm_start,
                 narrow.passes_due, islands.update_sleep, islands.wake_touched)  # fmt: skip
    for helper in uncounted:
        options = getattr(helper, "targetoptions", {"_nrt": False})  # plain Python without Numba
        assert options.get("_nrt") is False, helper.__name__
