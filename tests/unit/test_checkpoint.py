"""Checkpoints: ``world.save`` / ``World.load`` resume a run bit for bit, without pickle (issue 5.6)."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import tumble
from compiled import compiled_only
from tumble import scenes
from tumble.rotation import quat_from_axis_angle, quat_from_rotvec

DT = 1 / 60
BODY_FIELDS = ("body_pos", "body_quat", "body_linvel", "body_angmom", "body_sleep_time", "body_sleeping")


def _machine() -> tumble.World:
    """Contacts and every kind of joint: a motorised hinge chain with limits and a spring hanging from the
    world, a slider with a motor, a ball joint with a cone, a distance rope, a weld; a compound body, a
    hull, a body without geometry, and a ground the chain's end hits."""
    world = tumble.World()
    world.add_static(tumble.Plane(), name="ground")
    along_x = quat_from_axis_angle((0, 1, 0), np.pi / 2)
    links = []
    for k in range(4):
        links.append(world.add_body(tumble.Capsule(0.04, 0.22), density=500.0, position=(0.15 + 0.3 * k, 0.0, 1.0),
                                    orientation=along_x, name=f"link{k}"))  # fmt: skip
    world.add_joint(tumble.HingeJoint(links[0], None, (0.0, 0.0, 1.0), (0, 1, 0), motor_speed=1.5,
                                      max_motor_torque=4.0))  # fmt: skip
    for k in range(1, 4):
        world.add_joint(tumble.HingeJoint(links[k - 1], links[k], (0.3 * k, 0.0, 1.0), (0, 1, 0), lower=-1.0,
                                          upper=1.0, spring_hertz=2.0, spring_damping_ratio=0.3))  # fmt: skip
    rng = np.random.default_rng(5)
    cart = world.add_body(tumble.Box((0.3, 0.2, 0.1)), density=300.0, position=(-1.0, 0.0, 0.06), name="cart")
    world.add_joint(tumble.SliderJoint(cart, None, (1, 0, 0), lower=-0.5, upper=0.5, motor_speed=0.4,
                                       max_motor_force=20.0))  # fmt: skip
    compound = world.add_body(
        [(tumble.Box((0.2, 0.05, 0.05)), (0.0, 0.0, 0.0)),
         (tumble.Sphere(0.06), (0.12, 0.0, 0.0), quat_from_rotvec((0.1, 0.2, 0.3)))],
        density=700.0, position=(-1.0, 0.0, 0.6), angular_velocity=(0.0, 0.0, 3.0), name="compound",
    )  # fmt: skip
    world.add_joint(tumble.BallJoint(compound, cart, (-1.0, 0.0, 0.45), axis=(0, 0, 1), cone_angle=0.6))
    hull = world.add_body(tumble.ConvexHull(rng.normal(size=(14, 3)) * 0.07), density=900.0,
                          position=(0.5, 0.6, 0.4), velocity=(0.0, -0.5, 0.0), name="hull")  # fmt: skip
    world.add_joint(tumble.DistanceJoint(hull, None, (0.5, 0.6, 0.4), (0.5, 0.6, 1.2), min_length=0.0))
    ghost = world.add_body(None, mass=0.5, inertia=np.diag([0.01, 0.02, 0.03]), position=(2.0, 0.0, 2.0),
                           angular_velocity=(1.0, 2.0, 3.0), name="ghost")  # fmt: skip
    weld = world.add_body(tumble.Cylinder(0.05, 0.1), density=500.0, position=(2.0, 0.0, 1.8), name="weld")
    world.add_joint(tumble.FixedJoint(ghost, weld))
    world.set_solver(substeps=6, contact_hertz=45.0)
    return world


def _resume_matches(make, n_before: int, n_after: int, tmp_path) -> tumble.World:
    """Run ``n_before`` steps, save, step both the original and the loaded world ``n_after`` more: equal bits.
    Also equal to a fresh uninterrupted run. Returns the loaded world."""
    world = make()
    world.simulate(n_before * DT, DT)
    path = tmp_path / "checkpoint.npz"
    world.save(path)
    loaded = tumble.World.load(path)
    assert loaded.state.digest() == world.state.digest()
    world.simulate(n_after * DT, DT)
    loaded.simulate(n_after * DT, DT)
    assert loaded.state.digest() == world.state.digest()
    uninterrupted = make()
    uninterrupted.simulate((n_before + n_after) * DT, DT)
    assert uninterrupted.state.digest() == world.state.digest()
    return loaded


@pytest.mark.slow  # 60 s with NUMBA_DISABLE_JIT=1 (1 s compiled)
def test_box_pile_resumes_bit_identically(tmp_path):
    world = scenes.box_pile(64)
    world.simulate(40 * DT, DT)
    assert world.state.contact_count > 50  # the checkpoint is taken with warm-start impulses in the state
    loaded = _resume_matches(lambda: scenes.box_pile(64), 40, 30, tmp_path)
    assert [b.name for b in loaded.bodies] == ["ground"] + [f"box{k}" for k in range(64)]


@compiled_only("20 s as plain Python; the fresh process's test resumes the same machine")
def test_jointed_machine_resumes_bit_identically(tmp_path):
    loaded = _resume_matches(_machine, 45, 45, tmp_path)
    reference = _machine()
    reference.simulate(90 * DT, DT)
    assert [j.kind for j in loaded.joints] == ["hinge"] * 4 + ["slider", "ball", "distance", "fixed"]
    assert loaded.joints[0].motor_speed == 1.5 and loaded.joints[4].max_motor_force == 20.0
    assert loaded.joints[1].angle == reference.joints[1].angle
    assert loaded.solver == reference.solver and loaded.solver.substeps == 6
    assert loaded.body("hull").inertia_body.tolist() == reference.body("hull").inertia_body.tolist()


def test_pending_forces_and_changed_settings_are_kept(tmp_path):
    world = _machine()
    world.simulate(10 * DT, DT)
    world.body("cart").apply_force((5.0, 0.0, 0.0), point=(-1.0, 0.1, 0.1))
    world.joints[0].motor_speed = -2.0
    world.gravity = (0.0, 0.5, -9.0)
    world.save(tmp_path / "c.npz")
    loaded = tumble.World.load(tmp_path / "c.npz")
    np.testing.assert_array_equal(loaded.inputs.body_force, world.inputs.body_force)
    for w in (world, loaded):
        w.step(DT)
        w.simulate(20 * DT, DT)
    assert loaded.state.digest() == world.state.digest()
    assert loaded.gravity.tolist() == [0.0, 0.5, -9.0] and loaded.joints[0].motor_speed == -2.0


def test_a_fresh_process_resumes_bit_identically(tmp_path):
    world = _machine()
    world.simulate(30 * DT, DT)
    world.save(tmp_path / "c.npz")
    world.simulate(30 * DT, DT)
    script = textwrap.dedent(f"""
        import tumble
        world = tumble.World.load({str(tmp_path / "c.npz")!r})
        world.simulate(30 * {DT!r}, {DT!r})
        print(world.state.digest())
    """)
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == world.state.digest()


def _mesh_scene() -> tumble.World:
    world = tumble.World()
    world.add_static(scenes.bowl_mesh(segments=8, rings=2), name="bowl")
    rng = np.random.default_rng(3)
    for k in range(6):
        shape = (tumble.Box((0.14, 0.1, 0.08)), tumble.Sphere(0.08), tumble.Capsule(0.05, 0.1))[k % 3]
        world.add_body(shape, density=800.0, position=(*rng.uniform(-0.3, 0.3, 2), 0.3 + 0.2 * k),
                       orientation=quat_from_rotvec(rng.normal(size=3)), name=f"b{k}")  # fmt: skip
    return world


def _mesh_run(tmp_path) -> tuple[tumble.World, tumble.World]:
    world = _mesh_scene()
    world.simulate(60 * DT, DT)
    world.save(tmp_path / "mesh.npz")
    loaded = tumble.World.load(tmp_path / "mesh.npz")
    world.simulate(30 * DT, DT)
    loaded.simulate(30 * DT, DT)
    return world, loaded


def test_mesh_scene_resumes_with_identical_bodies(tmp_path):
    world, loaded = _mesh_run(tmp_path)
    for name in BODY_FIELDS:
        np.testing.assert_array_equal(getattr(loaded.state, name), getattr(world.state, name), err_msg=name)


def test_mesh_scene_resumes_with_an_identical_digest(tmp_path):
    world, loaded = _mesh_run(tmp_path)
    assert loaded.state.digest() == world.state.digest()


def test_a_checkpoint_holds_no_pickle_and_refuses_tampering(tmp_path):
    world = _machine()
    world.simulate(20 * DT, DT)
    path = tmp_path / "c.npz"
    world.save(path)
    with np.load(path, allow_pickle=False) as data:  # every member reads without pickle
        members = {k: data[k] for k in data.files}
    manifest = json.loads(str(members.pop("manifest")))
    assert manifest["format"] == "tumble.checkpoint" and manifest["tumble_version"] == tumble.__version__

    def tampered(change) -> str:
        edited = json.loads(json.dumps(manifest))
        change(edited)
        out = tmp_path / "tampered.npz"
        np.savez(out, manifest=np.array(json.dumps(edited)), **members)
        return out

    def unknown_class(m):
        m["params"]["$type"] = "os.system"

    def face_out_of_range(m):
        hull = next(s for s in m["shapes"] if s["type"] == "ConvexHull")
        hull["faces"] = {"$small": [[0, 1, 999]], "dtype": "<i8", "shape": [1, 3]}

    def island_out_of_range(m):
        n = len(m["builder"]["fields"]["rows"])
        m["state"]["fields"]["body_island"] = {"$small": [10**6] * n, "dtype": "<i8", "shape": [n]}

    def wrong_body_rows(m):
        m["state"]["fields"]["body_sleeping"] = {"$small": [True], "dtype": "|b1", "shape": [1]}

    for change, message in (
        (unknown_class, "unknown type 'os.system'"),
        (face_out_of_range, "face indices outside"),
        (island_out_of_range, "body_island outside -1..9"),
        (wrong_body_rows, "body_sleeping is"),
    ):
        with pytest.raises(ValueError, match=message):
            tumble.World.load(tampered(change))
    np.savez(tmp_path / "object.npz", manifest=np.array(json.dumps(manifest)), a0=np.array([{"x": 1}], object))
    with pytest.raises(ValueError, match="allow_pickle"):
        tumble.World.load(tmp_path / "object.npz")


def test_a_checkpoint_written_before_joint_damping_loads_undamped(tmp_path):
    """Joints' drives grew a ninth column (damping) in issue 26: an eight-column drive reads as undamped."""
    world = tumble.World()
    bob = world.add_body(tumble.Sphere(0.1), mass=1.0, position=(1.0, 0.0, 0.0))
    world.add_joint(tumble.HingeJoint(bob, None, (0, 0, 0), (0, 0, 1), damping=0.2))
    world.save(tmp_path / "new.npz")
    with np.load(tmp_path / "new.npz", allow_pickle=False) as data:
        members = {k: data[k] for k in data.files}
    manifest = json.loads(str(members.pop("manifest")))
    drive = manifest["builder"]["fields"]["joints"][0]["fields"]["drive"]
    assert drive["shape"] == [9] and drive["$small"][8] == 0.2
    drive.update({"$small": drive["$small"][:8], "shape": [8]})
    np.savez(tmp_path / "old.npz", manifest=np.array(json.dumps(manifest)), **members)
    old = tumble.World.load(tmp_path / "old.npz")
    assert old.joints[0].damping == 0.0 and tumble.World.load(tmp_path / "new.npz").joints[0].damping == 0.2
    old.step(1 / 60)


def test_save_and_load_refuse_the_wrong_files(tmp_path):
    world = scenes.box_pile(2)
    with pytest.raises(ValueError, match="checkpoints are .npz files"):
        world.save(tmp_path / "c.h5")
    world.simulate(0.1, DT).save(tmp_path / "traj.npz")
    with pytest.raises(ValueError, match="not a tumble checkpoint"):
        tumble.World.load(tmp_path / "traj.npz")
    (tmp_path / "junk.npz").write_bytes(b"not a zip file")
    with pytest.raises(ValueError, match="not a readable tumble checkpoint"):
        tumble.World.load(tmp_path / "junk.npz")
