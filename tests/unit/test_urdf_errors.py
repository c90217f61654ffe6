"""A URDF file that cannot be loaded raises a :class:`URDFError` naming the file, the element and its line; what
tumble reads past is named in a :class:`URDFWarning`; the loaders' own arguments are checked by name."""

from __future__ import annotations

import pytest

import tumble
from tumble.articulation import from_urdf
from tumble.models.mjcf import MJCFError
from tumble.models.urdf import URDFError, URDFWarning, read_urdf

INERTIAL = '<inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>'


def _robot(tmp_path, body: str, name: str = "robot.urdf"):
    path = tmp_path / name
    path.write_text(f'<robot name="r">\n{body}\n</robot>\n')
    return path


def _link(name: str, extra: str = "") -> str:
    return f'<link name="{name}">{INERTIAL}{extra}</link>'


def _hinge(name: str, parent: str, child: str, extra: str = "", kind: str = "revolute") -> str:
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
            f'<axis xyz="0 0 1"/>{extra}</joint>')  # fmt: skip


def test_a_good_file_loads_and_its_errors_are_model_file_errors(tmp_path):
    path = _robot(tmp_path, _link("base") + "\n" + _link("arm") + "\n" + _hinge("j", "base", "arm",
                  '<limit lower="-1" upper="1"/><dynamics damping="0.2"/>'))  # fmt: skip
    model = read_urdf(path)
    assert [b.name for b in model.bodies] == ["base", "arm"] and model.bodies[1].joints[0].range == (-1.0, 1.0)
    assert issubclass(URDFError, MJCFError) and issubclass(URDFWarning, UserWarning)
    assert from_urdf(path).nq == 1 and len(tumble.load_urdf(path).joints) == 1


@pytest.mark.parametrize(
    ("body", "message"),
    [
        (_link("a") + "\n<link", r"line 4: malformed XML"),
        (_link("a") + "\n" + _link("a"), r"line 3, <link>: link 'a' is defined twice \(first on line 2\)"),
        (_link("a") + "\n" + _link("b"), r"line 1, <robot>: a robot is a tree with one root link; found 2 \(a, b\)"),
        (_link("a") + "\n" + _link("b") + "\n" + _link("c") + "\n" + _hinge("j1", "a", "b") + "\n"
         + _hinge("j2", "c", "b"), r"line 6, <joint>: link 'b' has two parents: joints 'j1' and 'j2'"),
        (_link("a") + "\n" + _link("b") + "\n" + _link("c") + "\n" + _hinge("j1", "b", "c") + "\n"
         + _hinge("j2", "c", "b"), r"links 'b', 'c' are not connected to the root 'a': their joints make a loop"),
        (_link("a") + "\n" + _hinge("j", "world", "a"), r"line 3, <parent>: joint 'j': no link named 'world'"),
        (_link("a") + "\n" + _link("b") + "\n" + _hinge("j", "a", "b", kind="screw"),
         r"line 4, <joint>: joint 'j': type='screw' must be one of revolute, continuous"),
        (_link("a") + "\n" + _link("b") + "\n" + _hinge("j", "a", "b", kind="planar"),
         r"line 4, <joint>: joint 'j': type='planar' is not supported"),
        (_link("a") + "\n" + _link("b") + "\n" + _hinge("j", "a", "b", '<limit lower="1" upper="-1"/>'),
         r"<limit>: joint 'j': lower=1.0 is above upper=-1.0"),
        (_link("a") + "\n" + _link("b") + "\n" + _hinge("j", "a", "b").replace('xyz="0 0 1"', 'xyz="0 0 0"'),
         r"<axis>: joint 'j': axis xyz='0 0 0' has no direction"),
        (_link("a") + "\n" + _link("b") + "\n" + _hinge("j", "a", "b").replace('xyz="0 0 1"', 'xyz="0 nan 1"'),
         r"<axis>: xyz='0 nan 1' must be 3 finite numbers"),
        ('<link name="a"><inertial><mass value="-1"/></inertial></link>', r"line 2, <mass>: link 'a': value=-1.0"),
        ('<link name="a"><inertial><mass value="1"/></inertial></link>',
         r"line 2, <inertial>: link 'a': an <inertial> needs an <inertia>"),
        ('<link name="a"><inertial><mass value="1"/><inertia ixx="-1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/>'
         "</inertial></link>", r"line 2, <inertia>: link 'a': a non-physical inertia: inertia must be positive"),
        ('<link name="a"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" '
         'izz="0.3"/></inertial></link>', r"<inertia>: link 'a': a non-physical inertia: .* triangle inequality"),
        ('<link name="a"><collision><geometry><cone radius="1"/></geometry></collision></link>',
         r"<cone>: <cone> is not a URDF shape: box, cylinder, sphere or mesh"),
        ('<link name="a"><collision><geometry><box size="1 0 1"/></geometry></collision></link>',
         r"<box>: a shape's sizes must be > 0"),
        ('<link name="a"><collision><geometry><mesh filename="gone.stl"/></geometry></collision></link>',
         r"<mesh>: filename='gone.stl': no such mesh file"),
        ('<link name="a"><collision><geometry><mesh filename="package://parts/gone.stl"/></geometry></collision>'
         "</link>", r"<mesh>: filename='package://parts/gone.stl': package 'parts' not found"),
    ],
)  # fmt: skip
def test_bad_files_are_refused_naming_the_file_element_and_line(tmp_path, body, message):
    path = _robot(tmp_path, body)
    with pytest.raises(URDFError, match=(r"robot\.urdf, " if message.startswith("line") else "") + message):
        read_urdf(path)
    with pytest.raises(URDFError):
        tumble.load_urdf(path)


def test_the_root_must_be_a_robot_and_the_file_must_exist(tmp_path):
    path = tmp_path / "model.urdf"
    path.write_text('<mujoco model="m"/>')
    with pytest.raises(URDFError, match=r"model\.urdf, line 1, <mujoco>: the root element must be <robot>"):
        read_urdf(path)
    with pytest.raises(URDFError, match=r"nothing\.urdf: no such URDF file"):
        tumble.load_urdf(tmp_path / "nothing.urdf")


def test_a_mesh_is_found_in_package_dirs_and_beside_the_file(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    (tmp_path / "pkgs" / "parts" / "meshes").mkdir(parents=True)
    trimesh.creation.box((0.2, 0.2, 0.2)).export(tmp_path / "pkgs" / "parts" / "meshes" / "cube.stl")
    body = ('<link name="a"><collision><geometry><mesh filename="package://parts/meshes/cube.stl" scale="2 1 1"/>'
            "</geometry></collision></link>")  # fmt: skip
    path = _robot(tmp_path, body)
    model = read_urdf(path, package_dirs=[tmp_path / "pkgs"])
    vertices = next(iter(model.meshes.values())).vertices
    assert vertices[:, 0].max() == pytest.approx(0.2) and vertices[:, 1].max() == pytest.approx(0.1)
    beside = _robot(tmp_path / "pkgs" / "parts", body)  # the package folder is the file's own
    assert len(read_urdf(beside).meshes) == 1


def test_what_is_not_simulated_is_warned_about_and_arguments_are_checked(tmp_path):
    path = _robot(tmp_path, _link("a") + "\n" + _link("b") + "\n" + _link("c") + "\n" + _hinge("j", "a", "b")
                  + "\n" + _hinge("m", "a", "c", '<mimic joint="j" multiplier="2"/>'))  # fmt: skip
    with pytest.warns(URDFWarning, match=r"robot\.urdf, line 6, <joint>: joint 'm': <mimic> is not simulated"):
        read_urdf(path)
    dry = _robot(tmp_path, _link("a") + "\n" + _link("b") + "\n" + _hinge("j", "a", "b", '<dynamics friction="0.3"/>'),
                 "dry.urdf")  # fmt: skip
    with pytest.warns(URDFWarning, match=r"dry\.urdf, line 4, <dynamics>: joint 'j': friction=0.3 \(dry friction\)"):
        from_urdf(dry)
    with pytest.raises(TypeError, match="floating_base must be True or False, got 'yes'"):
        tumble.load_urdf(path, floating_base="yes")
    with pytest.raises(TypeError, match="floating_base"):
        from_urdf(path, floating_base=1)
    with pytest.raises(ValueError, match="position"):
        tumble.load_urdf(path, position=(0, 0))
    with pytest.raises(TypeError, match="world must be a tumble.World"):
        tumble.load_urdf(path, world="here")
