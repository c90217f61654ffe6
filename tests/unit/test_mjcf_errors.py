"""MJCF files that cannot be loaded give one error naming the file, the element and its line; what tumble reads but
does not simulate gives one warning per element and attribute. The reader's rules for defaults, orientations and
includes are checked here without MuJoCo (tests/peers/test_mjcf_models.py compares with MuJoCo's compiled models).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from tumble.articulation import from_mjcf
from tumble.models.mjcf import MJCFError, MJCFWarning, read_mjcf
from tumble.rotation import quat_from_axis_angle, quat_multiply


def model(body: str, head: str = "") -> str:
    return f"<mujoco>{head}<worldbody>{body}</worldbody></mujoco>"


def quiet(text):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MJCFWarning)
        return read_mjcf(text)


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("<mujoco><worldbody><body></worldbody></mujoco>", r"<string>, line 1: malformed XML \(mismatched tag\)"),
        ("<robot/>", r"<string>, line 1, <robot>: the root element must be <mujoco>"),
        (model('<body>\n<joint type="screw"/><geom size="1"/></body>'), r"line 2, <joint>: type='screw' must be one "
         "of hinge, slide, ball, free"),
        (model('<body><inertial pos="0 0 0" mass="1" diaginertia="1 1 3"/></body>'), r"line 1, <inertial>: "
         "non-physical inertia: .*triangle inequality"),
        (model('<body><inertial pos="0 0 0" mass="0" diaginertia="1 1 1"/></body>'), r"<inertial>: mass='0' must "
         "be > 0"),
        (model('<body><geom size="1 2 3 4"/></body>'), r"<geom>: size='1 2 3 4' must be 1 or 2 or 3 finite numbers"),
        (model('<body pos="0 nan 0"><geom size="1"/></body>'), r"<body>: pos='0 nan 0' must be 3 finite numbers"),
        (model('<body quat="1 0 0 0" euler="0 0 1"><geom size="1"/></body>'), r"give at most one orientation, got "
         "quat, euler"),
        (model('<body><geom class="nope" size="1"/></body>'), r"<geom>: class='nope' names no default class"),
        (model('<body><body><freejoint/><geom size="1"/></body></body>'), r"<freejoint>: a free joint can only be "
         "in a top-level body"),
        (model('<body><geom type="box" size="1 0 1"/></body>'), r"<geom>: size='1 0 1': a box needs 3 positive"),
        (model('<body><joint axis="0 0 0"/><geom size="1"/></body>'), r"<joint>: axis='0 0 0' is zero"),
        (model('<body><joint stiffness="-1"/><geom size="1"/></body>'), r"<joint>: stiffness='-1' must be >= 0"),
        (model('<body><geom type="capsule" fromto="0 0 0 0 0 0" size="1"/></body>'), r"fromto=.* has zero length"),
        (model("", '<compiler coordinate="global"/>'), r"coordinate='global' was removed"),
        (model('<include file="missing.xml"/>'), r"<include>: include file='missing.xml': no such file"),
        (model('<include file="../outside.xml"/>'), r"include file='../outside.xml' leaves the model's directory"),
    ],
)  # fmt: skip
def test_a_bad_file_gives_one_error_naming_the_element_and_line(text, match):
    with pytest.raises(MJCFError, match=match):
        quiet(text)


def test_a_missing_file_and_an_include_loop_name_the_files(tmp_path):
    with pytest.raises(MJCFError, match=r"no_such\.xml: no such model file"):
        read_mjcf(tmp_path / "no_such.xml")
    (tmp_path / "a.xml").write_text('<mujoco><include file="b.xml"/></mujoco>')
    (tmp_path / "b.xml").write_text('<mujoco>\n\n<include file="a.xml"/></mujoco>')
    with pytest.raises(MJCFError, match=r"b\.xml, line 3, <include>: include file='a\.xml' includes itself"):
        read_mjcf(tmp_path / "a.xml")


def test_includes_are_found_beside_the_main_file_first_then_beside_the_including_file(tmp_path):
    (tmp_path / "sub").mkdir()
    (tmp_path / "main.xml").write_text('<mujoco><worldbody><include file="sub/arm.xml"/></worldbody></mujoco>')
    (tmp_path / "sub" / "arm.xml").write_text('<mujoco><body name="arm"><geom size="0.1"/>'
                                              '<include file="hand.xml"/></body></mujoco>')  # fmt: skip
    (tmp_path / "sub" / "hand.xml").write_text('<mujoco><body name="hand_in_sub"><geom size="0.1"/></body></mujoco>')
    assert [b.name for b in read_mjcf(tmp_path / "main.xml").bodies] == ["arm", "hand_in_sub"]
    (tmp_path / "hand.xml").write_text('<mujoco><body name="hand_in_main"><geom size="0.1"/></body></mujoco>')
    assert [b.name for b in read_mjcf(tmp_path / "main.xml").bodies] == ["arm", "hand_in_main"]


def test_each_unsupported_element_and_attribute_warns_once_with_its_first_line_and_count():
    text = model(
        '<body>\n<joint frictionloss="1" damping="0.1"/>\n<joint frictionloss="2" bogus="3"/><geom size="1"/></body>',
        "<tendon><spatial/><spatial/></tendon><sensor/>",
    )
    with pytest.warns(MJCFWarning) as record:
        from_mjcf(text)
    messages = sorted(str(w.message) for w in record)
    assert messages == [
        "<string>: <joint> bogus (line 3): not supported by tumble; ignored",
        "<string>: <sensor> element (line 1): not loaded by tumble (yet); ignored",
        "<string>: <spatial> element (line 1 and 1 more): tumble loads fixed tendons only; not loaded",
    ]


def test_a_chain_of_bodies_deeper_than_pythons_recursion_limit_loads(tmp_path):
    depth = 1100  # Python's default limit is 1000 frames
    body = '<geom size="0.01"/>'
    for i in reversed(range(depth)):
        body = f'<body name="b{i}" pos="0 0 -0.1"><joint/>{body}</body>'
    (tmp_path / "chain.xml").write_text('<mujoco><worldbody><include file="links.xml"/></worldbody></mujoco>')
    (tmp_path / "links.xml").write_text(f"<mujoco>{body}</mujoco>")
    bodies = read_mjcf(tmp_path / "chain.xml").bodies
    assert [b.parent for b in bodies] == list(range(-1, depth - 1))
    assert bodies[-1].name == f"b{depth - 1}" and bodies[-1].mass_properties is not None


def test_a_supported_file_loads_without_a_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        art = from_mjcf(model('<body name="a"><joint/><geom size="0.1" rgba="1 0 0 1"/><site/></body>'))
    assert art.links[0].name == "a"


def test_defaults_nest_and_childclass_reaches_nested_bodies():
    head = ('<default><geom density="10"/><default class="a"><geom type="box" size="1 1 1"/>'
            '<default class="b"><geom density="20"/></default></default></default>')  # fmt: skip
    body = ('<body name="p" childclass="a"><geom/><body name="c"><geom class="b"/><geom class="main" size="1"/>'
            "</body></body>")  # fmt: skip
    bodies = quiet(model(body, head)).bodies
    assert bodies[0].mass_properties.mass == pytest.approx(10 * 8.0)  # class a: a 2 m box at main's density
    sphere = 4.0 / 3.0 * np.pi
    assert bodies[1].mass_properties.mass == pytest.approx(20 * 8.0 + 10 * sphere)  # b's box, main's sphere


@pytest.mark.parametrize(
    ("attribute", "expected"),
    [
        ('euler="90 0 0"', quat_from_axis_angle((1, 0, 0), np.pi / 2)),
        ('axisangle="0 0 2 90"', quat_from_axis_angle((0, 0, 1), np.pi / 2)),
        ('xyaxes="0 1 0 -1 0 0"', quat_from_axis_angle((0, 0, 1), np.pi / 2)),
        ('zaxis="1 0 0"', quat_from_axis_angle((0, 1, 0), np.pi / 2)),
        ('quat="2 0 0 0"', np.array([1.0, 0.0, 0.0, 0.0])),
    ],
)
def test_orientations_in_degrees(attribute, expected):
    body = quiet(model(f'<body {attribute}><geom size="1"/></body>')).bodies[0]
    np.testing.assert_allclose(body.quat, expected, atol=1e-15)


def test_euler_sequences_turn_with_the_frame_in_lowercase_and_about_fixed_axes_in_uppercase():
    head = '<compiler angle="radian" eulerseq="{}"/>'
    x, z = quat_from_axis_angle((1, 0, 0), 0.3), quat_from_axis_angle((0, 0, 1), 0.5)
    for seq, expected in (("xyz", quat_multiply(x, z)), ("XYZ", quat_multiply(z, x))):
        body = quiet(model('<body euler="0.3 0 0.5"><geom size="1"/></body>', head.format(seq))).bodies[0]
        np.testing.assert_allclose(body.quat, expected, atol=1e-15)


TETRA = "0 0 0 1 0 0 0 1 0 0 0 1"


def mesh_model(asset: str, geom: str = "type='mesh' mesh='m'") -> str:
    return f"<mujoco><asset>{asset}</asset><worldbody><body><freejoint/><geom {geom}/></body></worldbody></mujoco>"


@pytest.mark.parametrize(
    ("text", "match"),
    [
        (mesh_model(f"<mesh name='m' vertex='{TETRA}'/>", "type='mesh'"), r"<geom>: a mesh geom needs mesh=\.\.\."),
        (mesh_model(f"<mesh name='m' vertex='{TETRA}'/>", "type='mesh' mesh='n'"), r"<geom>: mesh='n' names no "
         "<mesh> asset"),
        (mesh_model("<mesh name='m' vertex='0 0 0 1 0 0 0 1 0'/>"), r"<mesh>: vertex holds 9 numbers: at least four"),
        (mesh_model(f"<mesh name='m' vertex='{TETRA}' face='0 1 7'/>"), r"<mesh>: face indexes vertices outside "
         r"0\.\.3"),
        (mesh_model(f"<mesh name='m' vertex='{TETRA}' face='0 1 2.5'/>"), r"<mesh>: face=.* is not a list of integer"),
        (mesh_model("<mesh name='m' vertex='0 0 0 1 0 0 0 1 0 1 1 0'/>"), r"line 1, <mesh>: mesh 'm': its vertices "
         "span no volume"),
        (mesh_model(f"<mesh name='m' vertex='{TETRA}' face='0 1 2 0 1 3 0 2 3 1 2 3' inertia='exact'/>"),
         r"<mesh>: mesh 'm' \(<string>\): its faces are inconsistently wound"),
        (mesh_model(f"<mesh name='m' vertex='{TETRA}' face='0 1 2 0 3 1 0 2 3 1 3 2' inertia='exact'/>"),
         r"its volume is negative .*: the faces point inwards"),
        (mesh_model(f"<mesh name='m' vertex='{TETRA}' face='0 2 1'/>"), r"its volume is too small"),
        (mesh_model(f"<mesh name='m' vertex='{TETRA}' inertia='hollow'/>"), r"inertia='hollow' must be one of legacy"),
        (mesh_model(f"<mesh name='m' vertex='{TETRA}'/><mesh name='m' vertex='{TETRA}'/>"), r"mesh 'm' is defined "
         "twice"),
        (mesh_model(f"<mesh name='m' vertex='{TETRA}'/>", "type='mesh' mesh='m' shellinertia='true'"), r"shellinertia"
         " on a mesh geom"),
        (mesh_model(f"<mesh name='m' vertex='{TETRA}' file='a.stl'/>"), r"from a file or from vertex=\.\.\., one"),
        (mesh_model("<mesh file='missing.stl'/>", "type='mesh' mesh='missing'"), r"<mesh>: file='missing\.stl': no "
         "such mesh file"),
        (mesh_model("<mesh file='../../etc/passwd.stl'/>"), r"file='\.\./\.\./etc/passwd\.stl' leaves the mesh "
         "directory"),
        (model("<body><geom type='capsule' pos='0 0 1' fromto='0 0 0 0 0 1' size='0.1'/></body>"), r"give pos or "
         "fromto, not both"),
    ],
)  # fmt: skip
def test_a_bad_mesh_gives_one_error_naming_the_element_and_line(text, match):
    with pytest.raises(MJCFError, match=match):
        quiet(text)


def test_a_mesh_file_of_an_unknown_kind_or_unreadable_is_an_error_naming_it(tmp_path):
    (tmp_path / "part.ply").write_text("ply")
    (tmp_path / "model.xml").write_text(mesh_model("<mesh file='part.ply'/>", "type='mesh' mesh='part'"))
    with pytest.raises(MJCFError, match=r"model\.xml, line 1, <mesh>: file='part\.ply': a mesh file is \.stl"):
        read_mjcf(tmp_path / "model.xml")
    (tmp_path / "part.msh").write_bytes(b"\x04\x00\x00\x00")
    (tmp_path / "model.xml").write_text(mesh_model("<mesh file='part.msh'/>", "type='mesh' mesh='part'"))
    with pytest.raises(MJCFError, match=r"part\.msh is not an MSH file: 4 bytes"):
        read_mjcf(tmp_path / "model.xml")


def test_a_mesh_used_by_no_geom_loads_and_vertices_alone_are_their_hull():
    text = mesh_model(f"<mesh name='m' vertex='{TETRA}'/>", "type='sphere' size='0.1'")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        description = read_mjcf(text)
    assert description.meshes["m"].faces.shape == (4, 3)
    assert description.bodies[0].mass_properties.mass == pytest.approx(1000 * 4 / 3 * np.pi * 0.001)


ARM = """<mujoco><compiler autolimits="{autolimits}"/>
  <default><motor gear="50" ctrlrange="-1 1"/><default class="servo"><position kp="20" kv="2"/></default></default>
  <worldbody><body><joint name="shoulder" axis="0 1 0"/><geom size="0.1"/>
    <body pos="0 0 -0.5"><joint name="twist" type="ball"/><joint name="slide" type="slide" pos="0 0 0.1"/>
      <geom size="0.1"/></body></body></worldbody>
  <actuator>{actuators}</actuator></mujoco>"""


def arm(actuators: str, autolimits: str = "true") -> str:
    return ARM.format(actuators=actuators, autolimits=autolimits)


def test_motors_servos_and_general_actuators_read_with_their_default_classes():
    actuators = ('<motor name="m" joint="shoulder"/>'
                 '<position class="servo" joint="slide" gear="2" ctrlrange="-0.3 0.3"/>'
                 '<velocity joint="shoulder" kv="4" ctrllimited="false"/>'
                 '<general joint="slide" gainprm="3" biastype="affine" biasprm="0.1 -2 -0.5"/>')  # fmt: skip
    description = read_mjcf(arm(actuators))
    motor, servo, speed, general = description.actuators
    assert (motor.name, motor.kind, motor.joint, motor.gear, motor.gain, motor.ctrl_range) == (
        "m", "motor", "shoulder", 50.0, 1.0, (-1.0, 1.0))  # fmt: skip
    assert (servo.gear, servo.gain, servo.bias.tolist(), servo.ctrl_range) == (2.0, 20.0, [0, -20, -2], (-0.3, 0.3))
    assert (speed.gain, speed.bias.tolist(), speed.ctrl_range) == (4.0, [0, 0, -4], None)
    assert (general.gain, general.bias.tolist(), general.gear) == (3.0, [0.1, -2, -0.5], 50.0)
    art = from_mjcf(arm('<motor joint="shoulder"/><position class="servo" joint="slide"/>'))
    assert [a.link for a in art.actuators] == [0, 2]  # the shoulder's link; the slide's, after the ball's
    assert art.actuators[1].bias.tolist() == [0.0, -20.0, -2.0]


@pytest.mark.parametrize(
    ("actuators", "match"),
    [
        ('<motor site="s"/>', r"<motor> site \(line 6\): tumble drives joints and fixed tendons only; not loaded"),
        ('<motor joint="twist"/>', r"<motor> joint .*tumble drives hinges and slides, not a ball; not loaded"),
        ('<general joint="shoulder" dyntype="filter"/>', r"<general> element .*dyntype='filter': activation dynamics"),
        ('<muscle joint="shoulder"/>', r"<muscle> element .*this actuator is not simulated by tumble; not loaded"),
    ],
)  # fmt: skip
def test_actuators_tumble_does_not_simulate_are_named_and_not_loaded(actuators, match):
    with pytest.warns(MJCFWarning, match=match):
        description = read_mjcf(arm(actuators))
    assert len(description.actuators) == 0


@pytest.mark.parametrize(
    ("actuators", "autolimits", "match"),
    [
        ('<motor joint="elbow"/>', "true", r"line 6, <motor>: joint='elbow' names no joint"),
        ('<motor tendon="t"/>', "true", r"line 6, <motor>: tendon='t' names no fixed tendon"),
        ('<motor joint="shoulder" tendon="t"/>', "true", r"line 6, <motor>: an actuator has one transmission"),
        ('<motor joint="shoulder" ctrlrange="1 -1"/>', "true", r"ctrlrange='1 -1' must have its lower bound below"),
        ('<velocity joint="shoulder" ctrlrange="-1 1"/>', "false", r"ctrlrange without ctrllimited=\.\.\. needs "
         "compiler autolimits"),
        ('<position joint="shoulder" kp="-1"/>', "true", r"<position>: kp='-1' must be >= 0"),
        ('<motor joint="shoulder" class="nope"/>', "true", r"<motor>: class='nope' names no default class"),
    ],
)  # fmt: skip
def test_a_bad_actuator_gives_an_error_naming_it(actuators, autolimits, match):
    with pytest.raises(MJCFError, match=match):
        quiet(arm(actuators, autolimits))
