"""Issue 22: the public API refuses overflowing and degenerate values with a ValueError naming the argument, and
a refused call or a failed step never leaves the world stuck; damaged files and environments give one clear error.
"""

from __future__ import annotations

import json
import os
import random
import re
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
        body.angular_velocity = (1e300, 0, 0)

    def too_fast(body):
        body.angular_velocity = (1e301, 0, 0)

    _refused(spin, r"angular_velocity=\[1e\+300, 0.0, 0.0\] gives the angular momentum \[inf", mass=1e12)
    _refused(too_fast, r"angular_velocity must have components of at most 1e\+300 rad/s, got \[1e\+301")
    with pytest.raises(ValueError, match="angular_velocity must have components of at most 1e"):
        tumble.World().add_body(tumble.Sphere(1.0), mass=1.0, angular_velocity=(0, 0, -2e300))


def test_setting_a_position_whose_centre_of_mass_overflows_is_refused():
    world = tumble.World()
    body = world.add_body(None, mass_properties=tumble.MassProperties(1.0, (1e308, 0, 0), np.eye(3)))
    with pytest.raises(ValueError, match=r"position=\[1e\+308, 0.0, 0.0\] puts the centre of mass at \[inf"):
        body.position = (1e308, 0, 0)
    assert body.position.tolist() == [0.0, 0.0, 0.0]


def test_a_step_that_overflows_drops_its_loads_so_the_world_is_never_stuck():
    world, twin = tumble.World(), tumble.World()  # free bodies
    body = world.add_body(tumble.Sphere(0.1), mass=1e-3)
    twin.add_body(tumble.Sphere(0.1), mass=1e-3)
    body.apply_force((1e308, 0.0, 0.0))  # F/m = 1e311 overflows: no step of any size survives this load
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


# --- damaged files -----------------------------------------------------------------------------------------------


def _saved_world(tmp_path):
    world = tumble.World()
    world.add_static(tumble.Plane(), name="ground")
    a = world.add_body(tumble.Box((0.2, 0.2, 0.2)), mass=1.0, position=(0, 0, 0.3), name="a")
    b = world.add_body(tumble.Sphere(0.1), mass=1.0, position=(0.5, 0, 0.3), name="b")
    world.add_joint(tumble.HingeJoint(a, b, (0.25, 0, 0.3), (0, 1, 0), lower=-1, upper=1))
    world.simulate(0.05, 0.01)
    path = tmp_path / "world.npz"
    world.save(path)
    with np.load(path, allow_pickle=False) as data:
        members = {k: data[k] for k in data.files}
    return json.loads(str(members.pop("manifest"))), members


def _tree_paths(node, prefix=()):
    """Every path into a JSON tree, the root's children first."""
    if isinstance(node, dict):
        items = node.items()
    elif isinstance(node, list):
        items = enumerate(node)
    else:
        return
    for key, child in items:
        yield (*prefix, key)
        yield from _tree_paths(child, (*prefix, key))


_DAMAGE = ("delete", None, "x", -1, 0, [], {}, 1e308, float("nan"), True, [1, 2])


def _load_damaged(manifest, members, path, damage, out) -> None:
    edited = json.loads(json.dumps(manifest))
    parent = edited
    for key in path[:-1]:
        parent = parent[key]
    if damage == "delete":
        del parent[path[-1]]
    else:
        parent[path[-1]] = damage
    np.savez(out, manifest=np.array(json.dumps(edited)), **members)
    try:
        world = tumble.World.load(out)
    except ValueError as error:
        assert str(error).startswith(repr(str(out))), (path, damage, error)
        return
    try:  # a file the checks let through holds values the API accepts: the world steps, or says why it cannot
        world.step(0.01)
    except (tumble.SimulationError, ValueError) as error:
        assert "checkpoint" not in str(error), (path, damage, error)


@pytest.mark.parametrize("sample", [pytest.param(400, id="sampled"), pytest.param(None, marks=pytest.mark.slow,
                                                                                   id="every")])  # fmt: skip
def test_a_damaged_checkpoint_gives_one_error_naming_the_file(tmp_path, sample):
    manifest, members = _saved_world(tmp_path)
    cases = [(path, damage) for path in _tree_paths(manifest) for damage in _DAMAGE]
    if sample is not None:
        cases = random.Random(22).sample(cases, sample)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # values of 1e308 overflow in the bounds of a step
        for path, damage in cases:
            _load_damaged(manifest, members, path, damage, tmp_path / "damaged.npz")


@pytest.mark.parametrize(
    ("damage", "match"),
    [
        (lambda m: m.pop("shapes"), r"is not a valid tumble checkpoint: no entry 'shapes'"),
        (lambda m: m.__setitem__("params", [1, 2]), r"params is list, expected Params"),
        (lambda m: m["params"]["fields"]["solver"]["fields"].__setitem__("substeps", 0), r"substeps must be an "
         "integer"),
        (lambda m: m["state"]["fields"]["body_quat"]["$small"][0].__setitem__(0, 7.0), r"body_quat holds a quaternion "
         "of norm"),
        (lambda m: m["state"]["fields"].__setitem__("time", "soon"), r"state: time 'soon'"),
        (lambda m: m["builder"]["fields"]["rows"][1]["fields"].__setitem__("linear_damping", -1.0), r"body 1: "
         "linear_damping holds -1.0"),
        (lambda m: m["builder"]["fields"]["joints"][0]["fields"].__setitem__("kind", 9), r"joint 0: 9 is not a valid "
         "JointKind"),
        (lambda m: m["builder"]["fields"]["joints"][0]["fields"].__setitem__("local_frame_a", []), r"joint 0: "
         r"local_frame_a of shape \(0,\), expected \(4,\)"),
    ],
)  # fmt: skip
def test_damaged_checkpoints_say_what_is_wrong(tmp_path, damage, match):
    manifest, members = _saved_world(tmp_path)
    damage(manifest)
    out = tmp_path / "damaged.npz"
    np.savez(out, manifest=np.array(json.dumps(manifest)), **members)
    with pytest.raises(ValueError, match=rf"^{re.escape(repr(str(out)))} .*{match}"):
        tumble.World.load(out)


def test_a_cut_or_reshaped_checkpoint_member_is_refused(tmp_path):
    manifest, members = _saved_world(tmp_path)
    out = tmp_path / "damaged.npz"
    np.savez(out, manifest=np.array(json.dumps(manifest)), **members)
    data = out.read_bytes()
    for cut in (len(data) // 2, 100, 10):
        (tmp_path / "cut.npz").write_bytes(data[:cut])
        with pytest.raises(ValueError, match=r"cut.npz' is not a readable tumble checkpoint"):
            tumble.World.load(tmp_path / "cut.npz")
    for key in members:
        np.savez(out, manifest=np.array(json.dumps(manifest)), **{**members, key: members[key].ravel()[:-1]})
        with pytest.raises(ValueError, match=r"damaged.npz' is not a (valid|consistent) tumble checkpoint"):
            tumble.World.load(out)


def _trajectory_file(tmp_path, suffix: str):
    world, _ = _world()
    path = tmp_path / f"run{suffix}"
    world.simulate(0.1, 0.01).save(path)
    return path


@pytest.mark.parametrize("suffix", [".npz", ".h5"])
def test_a_cut_trajectory_file_gives_one_error_naming_it(tmp_path, suffix):
    path = _trajectory_file(tmp_path, suffix)
    data = path.read_bytes()
    cut = tmp_path / f"cut{suffix}"
    for size in (len(data) // 2, 600, 20):
        cut.write_bytes(data[:size])
        with pytest.raises(ValueError, match=rf"^'{re.escape(str(cut))}' is not a (readable|valid) tumble trajectory"):
            tumble.Trajectory.load(cut)


def test_files_that_are_not_trajectories_are_named_as_such(tmp_path):
    junk = tmp_path / "junk.npz"
    junk.write_bytes(b"\x80\x04 not a zip, not a pickle either")
    with pytest.raises(ValueError, match=r"junk.npz' is not a readable tumble trajectory: not an .npz or HDF5 file "
                       r"of numbers \(tumble never reads pickled Python objects\)"):  # fmt: skip
        tumble.Trajectory.load(junk)
    path = _trajectory_file(tmp_path, ".npz")
    with np.load(path, allow_pickle=False) as data:
        members = {k: data[k] for k in data.files}
    for key, value, match in (
        ("position", np.array([{"x": 1}], dtype=object), "never reads pickled Python objects"),
        ("position", members["position"][:, :1], r"position has shape \(11, 1, 3\), expected \(11, 2, 3\)"),
        ("time", members["time"][:-1], r"position has shape \(11, 2, 3\), expected \(10, 2, 3\)"),
        ("orientation", members["orientation"].astype(np.complex128), "orientation holds complex128 values"),
        ("gravity", np.zeros(4), r"gravity has shape \(4,\), expected \(3,\)"),
        ("metadata_json", np.array("[1, 2]"), "metadata is a JSON list, not an object"),
        ("metadata_json", np.array("{not json"), "JSONDecodeError"),
    ):
        np.savez(tmp_path / "bad.npz", **{**members, key: value})
        with pytest.raises(ValueError, match=rf"bad.npz' is not a (readable|valid) tumble trajectory: .*{match}"):
            tumble.Trajectory.load(tmp_path / "bad.npz")


@pytest.mark.parametrize("dt", [1 / 60, 1 / 240, 1e-3])
@pytest.mark.parametrize("body_mass", [1e-300, 1e-150, 1e150, 1e300])
def test_bodies_of_extreme_mass_step_with_contacts(body_mass, dt):
    # The implicit gyroscopic step solves with the inertia's determinant, a product of three moments: it is scaled
    # by a power of two where it would leave float range (math3d.solve33).
    def dropped(mass):
        world = tumble.World()
        world.add_static(tumble.Plane())
        body = world.add_body(tumble.Box((0.1, 0.2, 0.3)), mass=mass, position=(0, 0, 0.16), angular_velocity=(1, 2, 3))
        world.simulate(0.05, dt)
        return body

    body, reference = dropped(body_mass), dropped(1.0)
    assert np.isfinite([*body.position, *body.angular_velocity]).all()
    assert 0.04 < body.position[2] < 0.17  # resting on or falling to the plane, not through it
    if 1e-200 < body_mass < 1e200:
        # Mass scales out of rigid-body motion under gravity and contact: the same motion to round-off. (At 1e±300
        # the solver's products of masses leave float range: the motion is still finite, no longer the same.)
        np.testing.assert_allclose(body.position, reference.position, atol=1e-9)
        np.testing.assert_allclose(body.angular_velocity, reference.angular_velocity, rtol=1e-7, atol=1e-9)


def test_a_refused_call_does_not_wake_a_sleeping_body():
    world = tumble.World()
    world.add_static(tumble.Plane())
    body = world.add_body(tumble.Box((0.2, 0.2, 0.2)), mass=1e12, position=(0, 0, 0.1))
    world.simulate(2.0, 1 / 60)
    assert body.sleeping
    digest = world.state.digest()
    for refused in (
        lambda: body.apply_impulse((1e300, 0, 0), point=(0, 1e300, 0)),
        lambda: body.apply_force((1e300, 0, 0), point=(0, 1e300, 0)),
        lambda: setattr(body, "angular_velocity", (1e300, 0, 0)),  # L = I ω overflows for 1e12 kg
    ):
        with pytest.raises(ValueError, match="overflows"):
            refused()
        assert body.sleeping and world.state.digest() == digest
    body.apply_impulse((1.0, 0, 0))  # an accepted one wakes it
    assert not body.sleeping
