"""Issue 22: the public API refuses overflowing and degenerate values with a ValueError naming the argument, and
a refused call or a failed step never leaves the world stuck; damaged files and environments give one clear error.
"""

from __future__ import annotations

import os
import subprocess
import sys
import warnings

import numpy as np
import pytest

import tumble
from tumble import recording, rotation
from tumble.dynamics.integrate import thread_count

# --- environment -----------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("setting", "cores", "threads"),
    [(None, 2, 2), ("", 4, 4), ("auto", 2, 2), (" AUTO ", 3, 3), ("1", 2, 1), ("2", 2, 2), ("8", 2, 2), ("1", None, 1)],
)
def test_tumble_threads_is_a_count_or_auto(setting, cores, threads):
    assert thread_count(setting, cores) == threads


@pytest.mark.parametrize("setting", ["0", "-3", "two", "1.5", "4 threads"])
def test_a_bad_tumble_threads_warns_and_uses_every_core(setting):
    with pytest.warns(RuntimeWarning, match=rf"TUMBLE_THREADS={setting!r}.*one per core \(2\)"):
        assert thread_count(setting, 2) == 2


def test_tumble_imports_and_steps_whatever_the_environment_says():
    env = dict(os.environ, PROJECT="myproject", TUMBLE_THREADS="auto")
    code = "import tumble; w = tumble.World(); w.add_body(tumble.Sphere(1.0), mass=1.0); w.step(0.01); print('ok')"
    result = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "ok"
    assert "Warning" not in result.stderr
    env["TUMBLE_THREADS"] = "lots"
    result = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    assert "TUMBLE_THREADS='lots'" in result.stderr


# --- refused calls change nothing --------------------------------------------------------------------------------

DT = 1e-3


def _world(mass: float = 1.0) -> tuple[tumble.World, tumble.Body]:
    world = tumble.World()
    world.add_static(tumble.Plane())
    body = world.add_body(tumble.Box((0.1, 0.2, 0.3)), mass=mass, position=(0.0, 0.0, 1.0), angular_velocity=(1, 2, 3))
    return world, body


def _refused(call, match: str, *, mass: float = 1.0, before=None) -> None:
    """``call(body)`` raises a ValueError matching ``match`` and changes nothing: the world that saw it steps to
    the digest of a twin that never did (``before(body)`` runs on both first)."""
    world, body = _world(mass)
    twin, twin_body = _world(mass)
    if before is not None:
        before(body)
        before(twin_body)
    digest, loads = world.state.digest(), world.inputs.body_force.copy()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no overflow warning on the way to the refusal either
        with pytest.raises(ValueError, match=match):
            call(body)
    assert world.state.digest() == digest
    np.testing.assert_array_equal(world.inputs.body_force, loads)
    for w in (world, twin):
        for _ in range(10):
            w.step(DT)
    assert world.state.digest() == twin.state.digest()
    assert np.isfinite(world.state.body_pos).all()


def test_an_impulse_whose_velocity_overflows_is_refused():
    _refused(lambda b: b.apply_impulse((1e308, 0.0, 0.0)), r"impulse=\[1e\+308, 0.0, 0.0\] on a body of 0.001 kg "
             r"gives the velocity \[inf", mass=1e-3)  # fmt: skip


def test_a_second_impulse_whose_sum_overflows_is_refused():
    _refused(lambda b: b.apply_impulse((1.75e308, 0, 0)), "gives the velocity", before=lambda b: b.apply_impulse((1e307,
             0, 0)))  # fmt: skip


def test_an_impulse_whose_moment_overflows_is_refused():
    _refused(lambda b: b.apply_impulse((1e300, 0, 0), point=(0, 1e300, 0)), r"gives the angular momentum")


def test_an_impulse_whose_angular_velocity_overflows_is_refused():
    # v = 1e200 m/s and L = 1e307 kg m²/s are finite, but ω = I⁻¹ L is not (I ≈ 0.01 kg m²).
    _refused(lambda b: b.apply_impulse((1e200, 0, 0), point=(0, 1e107, 1.0)), r"gives the angular velocity \[")


@pytest.mark.parametrize("method", ["apply_force", "apply_torque"])
def test_a_second_load_whose_sum_overflows_is_refused(method):
    _refused(
        lambda b: getattr(b, method)((1e308, 0, 0)),
        rf"{method}: adding \[1e\+308, 0.0, 0.0\] to the "
        r"\[1e\+308, 0.0, 0.0\] N( m)? already applied to body",
        before=lambda b: getattr(b, method)((1e308, 0, 0)),
        mass=1e300,
    )  # fmt: skip (heavy enough for either load to give a finite step)


def test_a_force_whose_moment_overflows_is_refused():
    _refused(lambda b: b.apply_force((1e300, 0, 0), point=(0, 1e300, 0)), r"at point \[0.0, 1e\+300, 0.0\] has the "
             "moment")  # fmt: skip


def test_setting_an_angular_velocity_whose_momentum_overflows_is_refused():
    def spin(body):
        body.angular_velocity = (1e308, 0, 0)

    _refused(spin, r"angular_velocity=\[1e\+308, 0.0, 0.0\] gives the angular momentum", mass=1e3)


def test_setting_a_position_whose_centre_of_mass_overflows_is_refused():
    world = tumble.World()
    body = world.add_body(None, mass_properties=tumble.MassProperties(1.0, (1e308, 0, 0), np.eye(3)))
    with pytest.raises(ValueError, match=r"position=\[1e\+308, 0.0, 0.0\] puts the centre of mass at \[inf"):
        body.position = (1e308, 0, 0)
    assert body.position.tolist() == [0.0, 0.0, 0.0]


def test_a_step_that_overflows_drops_its_loads_so_the_world_is_never_stuck():
    world, twin = tumble.World(), tumble.World()  # free bodies: RK4
    body = world.add_body(tumble.Sphere(0.1), mass=1.0)
    twin.add_body(tumble.Sphere(0.1), mass=1.0)
    body.apply_force((1e308, 0.0, 0.0))  # RK4 sums four stages of it: no step of any size survives this load
    digest = world.state.digest()
    with pytest.raises(tumble.SimulationError, match="the loads applied for it are dropped"):
        world.step(DT)
    assert world.state.digest() == digest
    assert not world.inputs.body_force.any() and not world.inputs.body_torque.any()
    for w in (world, twin):
        w.simulate(10 * DT, DT)
    assert world.state.digest() == twin.state.digest()


@pytest.mark.parametrize(
    ("make", "match"),
    [
        (lambda w: w.add_body(tumble.Box((1, 1, 1)), mass=1e-320), r"mass=1e-320 is too small.*1/mass overflows"),
        (lambda w: w.add_body(tumble.Box((1, 1, 1)), mass=1.0, inertia=1e-310 * np.eye(3)), "inertia must be "
         "invertible"),
        (lambda w: w.add_body(tumble.Sphere(1e200), mass=1.0), r"Sphere\(radius=1e\+200\) is too large"),
        (lambda w: w.add_body(tumble.Capsule(1e200, 1.0), mass=1.0), r"Capsule\(radius=1e\+200.*too large"),
    ],
)  # fmt: skip
def test_masses_inertias_and_sizes_that_overflow_are_refused(make, match):
    world = tumble.World()
    with pytest.raises(ValueError, match=match):
        make(world)
    assert world.bodies == []


# --- huge but finite values work ----------------------------------------------------------------------------------


def test_huge_quaternions_and_axes_give_their_rotation():
    half = np.sqrt(0.5)
    world = tumble.World()
    body = world.add_body(None, mass=1.0, inertia=np.eye(3), orientation=(1e200, 1e200, 0, 0))
    np.testing.assert_allclose(body.orientation, [half, half, 0, 0], rtol=1e-15)
    huge = np.array([3e307, 4e307, 0, 0])
    with pytest.raises(ValueError, match="q must be a non-zero quaternion"):  # near zero: no rotation to speak of
        rotation.quat_normalize(huge * 1e-320)
    for q in (huge, np.array([1.7e308, 1.7e308, 1.7e308, 1.7e308]), np.array([1e200, 1e-200, 0, 0])):
        expected = q / np.max(np.abs(q))
        expected /= np.linalg.norm(expected)
        np.testing.assert_allclose(rotation.quat_normalize(q), expected, rtol=1e-15)
        np.testing.assert_allclose(rotation.quat_to_matrix(q), rotation.quat_to_matrix(expected), atol=1e-15)
        np.testing.assert_allclose(rotation.quat_rotate(q, [1, 2, 3]), rotation.quat_rotate(expected, [1, 2, 3]),
                                   atol=1e-14)  # fmt: skip
        np.testing.assert_allclose(rotation.quat_to_rotvec(q), rotation.quat_to_rotvec(expected), atol=1e-15)
    np.testing.assert_allclose(rotation.quat_inverse(huge), [0.6e-307 / 5, -0.8e-307 / 5, 0, 0], rtol=1e-14)
    np.testing.assert_allclose(rotation.quat_from_axis_angle([0, 0, 1e300], np.pi), [0, 0, 0, 1], atol=1e-15)
    np.testing.assert_allclose(rotation.quat_from_axis_angle([0, 0, 1e-300], np.pi), [0, 0, 0, 1], atol=1e-15)
    assert np.isfinite(rotation.quat_from_rotvec([1e300, 1e300, 0])).all()
    world.add_joint(tumble.HingeJoint(body, None, (0, 0, 0), (0, 0, 1e300)))
    body.angular_velocity = (0, 0, 1)
    world.simulate(0.1, 0.01)  # turns about z, the hinge's axis, and about nothing else
    np.testing.assert_allclose(body.angular_velocity, [0, 0, 1], atol=1e-9)


def test_a_ray_along_a_huge_direction_hits_as_along_its_unit():
    world, _ = _world()
    for direction in ((0, 0, -1e300), (0, 0, -1.7e308), (0, 0, -1e-300), (0, 0, -5e-324)):
        hit = world.query_ray((0, 0, 10), direction)
        assert hit is not None and hit.distance == pytest.approx(10 - 1.15)
        np.testing.assert_array_equal(hit.normal, [0, 0, 1])


# --- steps and durations ------------------------------------------------------------------------------------------


def test_steps_too_small_to_advance_time_are_refused():
    world, _ = _world()
    for dt in (5e-324, 1e-310):
        with pytest.raises(ValueError, match=rf"dt={dt!r} is too small to advance time from t = 0.0 s"):
            world.step(dt)
    world.step(1e-300)  # the smallest step taken: it moves nothing, but it is a step
    assert world.step_count == 1
    world.simulate(0.1, 0.01)
    with pytest.raises(ValueError, match=r"dt=1e-20 is too small to advance time from t = 0.0999"):
        world.step(1e-20)
    with pytest.raises(ValueError, match=r"dt=1e-20 is too small"):
        world.simulate(1e-18, 1e-20)
    assert world.step_count == 11


def test_absurd_durations_are_refused_with_what_they_would_take():
    world, _ = _world()
    with pytest.raises(ValueError, match=r"recording 1000000000000 frames of 2 bodies .* would take 37\d TiB, more "
                       r"than this machine's .* of memory: record fewer frames"):  # fmt: skip
        world.simulate(1e9, 1e-3)
    with pytest.raises(ValueError, match=r"duration=1e\+300 at dt=1e-300 is inf steps; one call takes at most 1e\+15"):
        world.simulate(1e300, 1e-300)
    with pytest.raises(ValueError, match=r"is 1e\+16 steps"):
        world.simulate(1e13, 1e-3, record_every=2**31 - 1)
    with pytest.raises(ValueError, match=r"record_every must be an integer from 1 to 2147483647, got 2\*\*70|got "
                       r"1180591620717411303424"):  # fmt: skip
        world.simulate(1.0, 1e-3, record_every=2**70)
    assert world.step_count == 0


def test_recording_refuses_absurd_counts_before_writing(tmp_path):
    world, _ = _world()
    path = tmp_path / "run.h5"
    for kwargs, match in (
        ({"every": 2**70}, r"every must be an integer from 1 to 2147483647, got 1180591620717411303424"),
        ({"chunk_frames": 0}, r"chunk_frames must be an integer from 1"),
    ):
        with pytest.raises(ValueError, match=match):
            recording.record(world, 1.0, 1e-3, path, **kwargs)
    with pytest.raises(ValueError, match=r"is inf steps"):
        recording.record(world, 1e300, 1e-300, path)
    assert not path.exists() and world.step_count == 0


def test_an_articulation_refuses_absurd_steps_and_durations():
    art = tumble.Articulation()
    art.add_link(tumble.Revolute((0, 1, 0)), shape=tumble.Sphere(0.1), mass=1.0, shape_position=(0, 0, -1))
    with pytest.raises(ValueError, match=r"dt=5e-324 is too small to advance time"):
        art.step(5e-324)
    with pytest.raises(ValueError, match=r"is inf steps"):
        art.simulate(1e300, 1e-300)
    with pytest.raises(ValueError, match=r"recording 1000000000001 frames would take .* TiB"):
        art.simulate(1e9, 1e-3)
    art.simulate(0.01, 1e-3)
