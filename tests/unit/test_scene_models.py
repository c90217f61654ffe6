"""Model files in scenes and on the command line: ``[[models]]`` in a scene file puts an MJCF model into the world
with ``tumble.load_mjcf``, a URDF robot with ``tumble.load_urdf``; ``tumble run model.xml`` and ``tumble info
robot.urdf`` take one directly (a scene of that model, its gravity, its timestep as the step); what tumble does not
simulate is a note, bad input exit status 2."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from compiled import compiled_only
from tumble import scene_file

PENDULUM = """<mujoco model="swing">
  <option timestep="0.005" gravity="0 0 -9.8"/>
  <worldbody>
    <geom name="floor" type="plane" size="5 5 0.1"/>
    <body name="bob" pos="0 0 1"><joint name="pivot" axis="0 1 0" pos="0 0 0.5" armature="0.1"/>
      <geom type="sphere" size="0.1" pos="0.3 0 0" mass="2"/></body>
  </worldbody>
  <actuator><motor name="push" joint="pivot" gear="2" ctrlrange="-1 1"/></actuator>
</mujoco>"""

SCENE = """description = "A model beside a crate"
[[models]]
path = "parts/swing.xml"
position = [1.0, 0.0, 0.0]
orientation = [0.7071067811865476, 0.0, 0.0, 0.7071067811865476]

[[bodies]]
name = "crate"
shape = { type = "box", extents = [0.2, 0.2, 0.2] }
mass = 1.0
position = [1.3, 0.0, 0.5]

[[joints]]
type = "ball"
a = "crate"
b = "bob"
anchor = [1.3, 0.0, 0.6]
"""


ARM = """<robot name="arm">
  <link name="base">
    <inertial><mass value="4"/><inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.03"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
  </link>
  <link name="upper">
    <inertial><origin xyz="0.25 0 0"/><mass value="1.5"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.03"/></inertial>
    <collision><origin xyz="0.25 0 0" rpy="0 1.5707963267948966 0"/>
      <geometry><cylinder radius="0.03" length="0.5"/></geometry></collision>
  </link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 1 0"/><limit lower="-1.5" upper="1.5" effort="10" velocity="2"/></joint>
</robot>"""


@pytest.fixture
def folder(tmp_path):
    (tmp_path / "parts").mkdir()
    (tmp_path / "parts" / "swing.xml").write_text(PENDULUM)
    (tmp_path / "parts" / "arm.urdf").write_text(ARM)
    (tmp_path / "scene.toml").write_text(SCENE)
    return tmp_path


def test_a_scene_places_a_model_and_joins_its_bodies_by_name(folder):
    with pytest.warns(UserWarning, match="a tumble World's joints do not simulate joint armature"):
        loaded = scene_file.load(folder / "scene.toml")
    world = loaded.world
    bob = next(b for b in world.bodies if b.name == "bob")
    # turned a quarter about z and moved 1 m along x: the bob's sphere, 0.3 m along the model's x, is along y
    np.testing.assert_allclose(bob.center_of_mass, (1.0, 0.3, 1.0), atol=1e-12)
    assert [j.kind for j in world.joints] == ["hinge", "ball"]
    assert {b.name for b in world.bodies} == {"floor", "bob", "crate"}
    assert loaded.source["models"] == [{"path": "parts/swing.xml", "position": [1.0, 0.0, 0.0],
                                        "orientation": [0.7071067811865476, 0.0, 0.0, 0.7071067811865476]}]  # fmt: skip


def test_a_model_file_is_a_scene_of_its_own_with_its_gravity_and_timestep(folder):
    loaded = scene_file.load(folder / "parts" / "swing.xml")
    assert loaded.run.dt == 0.005
    np.testing.assert_array_equal(loaded.world.gravity, (0.0, 0.0, -9.8))


@pytest.mark.parametrize(
    ("models", "match"),
    [
        ('[[models]]\npath = "missing.xml"', r"scene.toml: models\[0\].path: no model file 'missing.xml'"),
        ('[[models]]\npath = "scene.toml"', r"models\[0\].path: a model file is MJCF \(.xml\) or URDF \(.urdf\)"),
        ('[[models]]\npath = "parts/swing.xml"\nfloating_base = true',
         r"models\[0\]: floating_base and package_dirs are a URDF's; 'parts/swing.xml' is MJCF"),
        ('[[models]]\npath = "parts/arm.urdf"\nfloating_base = "maybe"', r"models\[0\].floating_base"),
        ('[[models]]\npath = "bad.xml"', r"scene.toml: models\[0\]: .*bad.xml, line 1, <joint>: type='screw'"),
        ('[[models]]\npath = "parts/swing.xml"\nposition = [1, 2]', r"models\[0\].position"),
    ],
)  # fmt: skip
def test_bad_models_in_a_scene_are_scene_errors_naming_the_place(folder, models, match):
    (folder / "bad.xml").write_text('<mujoco><worldbody><body><joint type="screw"/></body></worldbody></mujoco>')
    (folder / "scene.toml").write_text(models)
    with pytest.raises(scene_file.SceneError, match=match):
        scene_file.load(folder / "scene.toml")


def test_a_scene_places_a_urdf_robot_welded_or_free(folder):
    (folder / "robots.toml").write_text("""[[models]]
path = "parts/arm.urdf"
position = [0.0, 1.0, 0.0]

[[models]]
path = "parts/arm.urdf"
position = [0.0, -1.0, 2.0]
""")
    with pytest.raises(scene_file.SceneError, match=r"models\[1\]: .*the name 'upper' is taken in the world"):
        scene_file.load(folder / "robots.toml")
    (folder / "robots.toml").write_text("""[[models]]
path = "parts/arm.urdf"
position = [0.0, 1.0, 0.0]
""")
    world = scene_file.load(folder / "robots.toml").world
    upper = next(b for b in world.bodies if b.name == "upper")
    np.testing.assert_allclose(upper.center_of_mass, (0.25, 1.0, 0.1), atol=1e-12)
    assert upper.mass == 1.5 and [j.kind for j in world.joints] == ["hinge"]
    assert world.joints[0].body_b is None  # the base is welded: the world's
    (folder / "robots.toml").write_text("""[[models]]
path = "parts/arm.urdf"
position = [0.0, 0.0, 2.0]
floating_base = true
package_dirs = ["parts"]
""")
    loaded = scene_file.load(folder / "robots.toml")
    base = next(b for b in loaded.world.bodies if b.name == "base")
    assert base.mass == 4.0 and not base.is_static
    loaded.world.simulate(0.5, 0.01)
    assert base.position[2] == pytest.approx(2.0 - 0.5 * 9.81 * 0.25, abs=0.01)  # falling freely with its arm
    alone = scene_file.load(folder / "parts" / "arm.urdf")  # a URDF alone: MuJoCo's default gravity and step
    assert alone.run.dt == 0.002 and alone.world.gravity[2] == -9.81


def tumble_cli(*args, cwd):
    return subprocess.run([sys.executable, "-m", "tumble", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, timeout=300)  # fmt: skip


@compiled_only("five commands in fresh processes: 10 s as plain Python, stepping what the other tests step")
def test_tumble_run_and_info_take_a_model_file(folder):
    info = tumble_cli("info", "parts/swing.xml", cwd=folder)
    assert info.returncode == 0, info.stderr
    assert "bob" in info.stdout and "hinge" in info.stdout and "0.005" in info.stdout
    assert "actuators (1, world.ctrl)" in info.stdout and "push" in info.stdout and "[-1, 1]" in info.stdout
    assert "tumble: " in info.stderr and "do not simulate joint armature" in info.stderr
    assert "Traceback" not in info.stderr and "warn(" not in info.stderr
    run = tumble_cli("run", "parts/swing.xml", "--duration", "0.1", "--out", "swing.h5", "--quiet", cwd=folder)
    assert run.returncode == 0, run.stderr
    assert (folder / "swing.h5").is_file()
    urdf = tumble_cli("info", "parts/arm.urdf", cwd=folder)
    assert urdf.returncode == 0, urdf.stderr
    assert "upper" in urdf.stdout and "hinge" in urdf.stdout
    run = tumble_cli("run", "parts/arm.urdf", "--duration", "0.1", "--out", "arm.h5", "--quiet", cwd=folder)
    assert run.returncode == 0, run.stderr
    (folder / "bad.xml").write_text("<mujoco><worldbody>")
    bad = tumble_cli("info", "bad.xml", cwd=folder)
    assert bad.returncode == 2 and "bad.xml, line 1: malformed XML" in bad.stderr and "Traceback" not in bad.stderr
