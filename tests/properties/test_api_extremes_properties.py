"""The public API under extreme finite values (issue 22): ±1e±300, subnormals, the largest float, zero.

Every call either gives finite results (and leaves the world finite) or raises a ValueError or TypeError whose
message names one of the arguments it was given. A step may also end in a SimulationError, the documented outcome
when the physics itself leaves float range (a velocity of 1e308 m/s moves a body out of it); the world then keeps
its state from before, which the test checks is finite.
"""

from __future__ import annotations

import warnings

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import tumble
from tumble import mass, rotation
from tumble.shapes import Shape

EXTREMES = (0.0, -0.0, 5e-324, -5e-324, 1e-310, 1e-300, -1e-300, 1e-150, 1e-12, 1.0, -1.0, 1e150, 1e300, -1e300,
            1e308, -1e308, 1.7976931348623157e308, -1.7976931348623157e308)  # fmt: skip
numbers = st.one_of(st.sampled_from(EXTREMES), st.floats(allow_nan=False, allow_infinity=False))
positive = st.one_of(st.sampled_from([x for x in EXTREMES if x > 0]), st.floats(min_value=0.0, exclude_min=True,
                                                                                 allow_infinity=False))  # fmt: skip
vectors = st.tuples(numbers, numbers, numbers)
quaternions = st.tuples(numbers, numbers, numbers, numbers)


def _finite(value) -> bool:
    """Every number in ``value`` (arrays, tuples, a hit's fields) is finite."""
    if value is None or isinstance(value, (str, tumble.Body)):
        return True
    if isinstance(value, Shape):
        return _finite(value.params)
    if isinstance(value, mass.MassProperties):
        return _finite((value.mass, value.com, value.inertia))
    if isinstance(value, (tuple, list)):
        return all(_finite(v) for v in value)
    if hasattr(value, "__dataclass_fields__") or hasattr(value, "_fields"):
        return all(_finite(getattr(value, name)) for name in getattr(value, "_fields", value.__dict__))
    return bool(np.isfinite(np.asarray(value, dtype=np.float64)).all())


def _check(call, names: tuple[str, ...]):
    """``call()``'s result if finite, else the error it raised must be a ValueError/TypeError naming one of
    ``names``; returns the result, or None after an error."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # the refusals may compute an overflow to find it
            result = call()
    except (ValueError, TypeError) as error:
        assert any(name in str(error) for name in names), (names, error)
        return None
    assert _finite(result), (names, result)
    return result


def _world_is_finite(world: tumble.World) -> None:
    s = world.state
    for array in (s.body_pos, s.body_quat, s.body_linvel, s.body_angmom, world.inputs.body_force,
                  world.inputs.body_torque):  # fmt: skip
        assert np.isfinite(array).all()


SHAPES = {
    "sphere": (lambda a, b: tumble.Sphere(a), ("radius",)),
    "box": (lambda a, b: tumble.Box((a, b, a)), ("size", "half", "extent", "Box")),
    "capsule": (lambda a, b: tumble.Capsule(a, b), ("radius", "length", "Capsule")),
    "cylinder": (lambda a, b: tumble.Cylinder(a, b), ("radius", "length", "height", "Cylinder")),
}


@settings(max_examples=60)
@given(
    kind=st.sampled_from(sorted(SHAPES)), size=st.tuples(positive, positive), body_mass=positive,
    position=vectors, orientation=quaternions, velocity=vectors, spin=vectors,
)  # fmt: skip
def test_adding_a_body_gives_a_finite_body_or_names_the_argument(kind, size, body_mass, position, orientation,
                                                                 velocity, spin):  # fmt: skip
    make, shape_names = SHAPES[kind]
    world = tumble.World()
    shape = _check(lambda: make(*size), shape_names)
    if shape is None:
        return
    names = ("mass", "inertia", "position", "orientation", "velocity", "angular_velocity", *shape_names)
    body = _check(lambda: world.add_body(shape, mass=body_mass, position=position, orientation=orientation,
                                         velocity=velocity, angular_velocity=spin), names)  # fmt: skip
    if body is not None:
        _world_is_finite(world)
        assert _finite((body.position, body.orientation, body.velocity, body.angular_velocity, body.inertia_world))


OPERATIONS = ("force", "torque", "impulse", "position", "velocity", "angular_velocity", "orientation", "step",
              "ray", "gravity")  # fmt: skip


def _operation(world, body, name, v, point):
    """The call ``name`` with the vector ``v`` (and ``point``), and the names of its arguments."""
    return {
        "force": (lambda: body.apply_force(v, point), ("force", "point")),
        "torque": (lambda: body.apply_torque(v), ("torque",)),
        "impulse": (lambda: body.apply_impulse(v, point), ("impulse", "point")),
        "position": (lambda: setattr(body, "position", v), ("position",)),
        "velocity": (lambda: setattr(body, "velocity", v), ("velocity",)),
        "angular_velocity": (lambda: setattr(body, "angular_velocity", v), ("angular_velocity",)),
        "gravity": (lambda: setattr(world, "gravity", v), ("gravity",)),
        "ray": (lambda: world.query_ray(v, (0, 0, -1) if point is None else point), ("origin", "direction")),
    }[name]


@settings(max_examples=60)
@given(data=st.data(), heavy=st.booleans())
def test_loads_settings_and_steps_keep_the_world_finite_or_name_the_argument(data, heavy):
    world = tumble.World()
    world.add_static(tumble.Plane())
    body = world.add_body(tumble.Box((0.2, 0.3, 0.4)), mass=1e6 if heavy else 0.5, position=(0, 0, 0.21))
    world.step(1e-3)
    for _ in range(6):
        operation = data.draw(st.sampled_from(OPERATIONS))
        v, point = data.draw(vectors), data.draw(st.one_of(st.none(), vectors))
        if operation == "step":
            dt, before = data.draw(positive), world.state.copy()
            try:
                _check(lambda dt=dt: world.step(dt), ("dt",))
            except tumble.SimulationError:
                assert world.state.digest() == before.digest()
        elif operation == "orientation":
            q = data.draw(quaternions)
            _check(lambda q=q: setattr(body, "orientation", q), ("orientation",))
        else:
            call, names = _operation(world, body, operation, v, point)
            _check(call, names)
        _world_is_finite(world)


@settings(max_examples=100)
@given(q=quaternions, v=vectors, angle=numbers)
def test_rotations_of_extreme_inputs_are_finite_or_refused_by_name(q, v, angle):
    for call in (
        lambda: rotation.quat_normalize(q),
        lambda: rotation.quat_to_matrix(q),
        lambda: rotation.quat_rotate(q, v),
        lambda: rotation.quat_inverse(q),
        lambda: rotation.quat_to_rotvec(q),
        lambda: rotation.quat_to_axis_angle(q),
    ):
        _check(call, ("q", "v"))
    unit = _check(lambda: rotation.quat_normalize(q), ("q",))
    if unit is not None:
        np.testing.assert_allclose(np.linalg.norm(unit), 1.0, rtol=1e-14)
    _check(lambda: rotation.quat_from_axis_angle(v, angle), ("axis", "angle"))
    _check(lambda: rotation.quat_from_rotvec(v), ("r",))


@settings(max_examples=60)
@given(size=st.tuples(positive, positive), body_mass=positive)
def test_mass_properties_of_extreme_sizes_are_finite_or_refused_by_name(size, body_mass):
    a, b = size
    for call, names in (
        (lambda: mass.solid_sphere(a, mass=body_mass), ("radius", "mass", "sphere")),
        (lambda: mass.box((a, b, a), mass=body_mass), ("extents", "mass", "box")),
        (lambda: mass.solid_cylinder(a, b, mass=body_mass), ("radius", "height", "mass", "cylinder")),
        (lambda: mass.capsule(a, b, mass=body_mass), ("radius", "length", "mass", "capsule")),
        (lambda: mass.solid_sphere(a, density=body_mass), ("radius", "density", "sphere")),
    ):
        result = _check(call, names)
        if result is not None:
            assert _finite((result.mass, result.com, result.inertia))
