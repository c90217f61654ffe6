"""Scene files: every shipped scene loads, runs and round-trips; bad files give clean errors naming the place."""

from __future__ import annotations

import copy
import json
import math
import tomllib

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import tumble
from scene_fuzz import _places
from tumble import scene_file, scenes
from tumble.scene_file import SceneError

SHIPPED = scene_file.shipped()


def test_the_package_ships_a_scene_for_every_capability():
    names = {path.stem for path in SHIPPED}
    assert {
        "pendulum",
        "dzhanibekov",
        "box_pile",
        "pyramid",
        "dominoes",
        "newtons_cradle",
        "pendulum_chain",
        "slider_crank",
        "four_bar",
        "hinged_door",
        "rope_bridge",
        "ragdoll_stairs",
        "mixed_pile",
    } <= names
    assert scenes.files() == SHIPPED


@pytest.mark.slow  # stepping 13 scenes is minutes without the JIT
@pytest.mark.parametrize("path", SHIPPED, ids=[p.stem for p in SHIPPED])
def test_every_shipped_scene_loads_runs_and_round_trips(path):
    loaded = scene_file.load(path)
    world = loaded.world
    assert tomllib.loads(path.read_text())["description"]
    again = scene_file.from_dict(tomllib.loads(scene_file.dumps(world.to_scene(dt=loaded.run.dt))), base=path.parent)
    twin = again.world
    # The scene lists dynamic bodies before static ones: the twin's rows follow that order.
    order = [b.index for b in world.bodies if not b.is_static] + [b.index for b in world.bodies if b.is_static]
    np.testing.assert_allclose(twin.model.body_mass, world.model.body_mass[order], rtol=1e-12)
    np.testing.assert_allclose(twin.model.body_inertia_local, world.model.body_inertia_local[order], rtol=1e-9,
                               atol=1e-15)  # fmt: skip
    np.testing.assert_allclose(twin.state.body_pos, world.state.body_pos[order], atol=1e-12)
    for mine, theirs in enumerate(order):
        np.testing.assert_allclose(twin.model.shape_params[twin.model.shape_body == mine],
                                   world.model.shape_params[world.model.shape_body == theirs], atol=1e-12)  # fmt: skip
    assert len(twin.joints) == len(world.joints) and again.run.dt == loaded.run.dt
    for w in (world, twin):
        for _ in range(3):
            w.step(loaded.run.dt)
    np.testing.assert_allclose(twin.state.body_pos, world.state.body_pos[order], atol=1e-9)


def test_json_and_toml_are_the_same_structure(tmp_path):
    data = tomllib.loads(scene_file.shipped_scene("slider_crank").read_text())
    path = tmp_path / "crank.json"
    path.write_text(json.dumps(data))
    from_json = scene_file.load(path)
    from_toml = scene_file.load(scene_file.shipped_scene("slider_crank"))
    assert from_json.source == from_toml.source
    assert tumble.load_scene(path).state.digest() == from_toml.world.state.digest()


def _write(tmp_path, text: str, name: str = "bad.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


GOOD = """
[world]
dt = 0.01
[materials.rubber]
friction = 0.9
restitution = 0.7
[[static]]
shape = { type = "plane" }
[[bodies]]
name = "ball"
shape = { type = "sphere", radius = 0.1 }
mass = 1.0
position = [0, 0, 1]
material = "rubber"
[[bodies]]
name = "box"
shape = { type = "box", extents = [0.2, 0.2, 0.2] }
density = 500.0
position = [1, 0, 1]
"""


@pytest.mark.parametrize(
    ("edit", "expected"),
    [
        (
            lambda t: t.replace("extents = [0.2, 0.2, 0.2]", 'extents = [0.2, "x", 0.2]'),
            r"bad.toml: bodies\[1\].shape.extents\[1\]: .*number",
        ),
        (lambda t: t.replace("radius = 0.1", "radius = -0.1"), r"bad.toml: bodies\[0\].shape.radius: .*greater than 0"),
        (lambda t: t.replace("mass = 1.0", "mass = -2.0"), r"bad.toml: bodies\[0\].mass: .*greater than 0"),
        (
            lambda t: t.replace("density = 500.0", "density = 500.0\ncolour = 3"),
            r"bad.toml: bodies\[1\].colour: unknown key",
        ),
        (
            lambda t: t.replace('material = "rubber"', 'material = "steel"'),
            r"bad.toml: bodies\[0\].material: no material 'steel'; materials: \['rubber'\]",
        ),
        (lambda t: t.replace("[world]", "[world"), r"bad.toml: not valid TOML"),
        (
            lambda t: t.replace('shape = { type = "plane" }', 'shape = { type = "mesh", path = "bowl.stl" }'),
            r"bad.toml: static\[0\].shape.path: no mesh file 'bowl.stl'",
        ),
        (lambda t: t.replace('type = "sphere"', 'type = "blob"'), r"bad.toml: bodies\[0\].shape: .*sphere"),
        (
            lambda t: t + '[[joints]]\ntype = "hinge"\na = "nobody"\nanchor = [0, 0, 0]\naxis = [0, 1, 0]\n',
            r"bad.toml: joints\[0\].a: no body named 'nobody'",
        ),
        (
            lambda t: t + '[[joints]]\ntype = "hinge"\na = "ball"\nanchor = [0, 0, 0]\naxis = [0, 0, 0]\n',
            r"bad.toml: joints\[0\]: axis must be a non-zero vector",
        ),
        (
            lambda t: t.replace(
                'shape = { type = "box", extents = [0.2, 0.2, 0.2] }',
                'shape = { type = "hull", points = [[0,0,0],[1,0,0],[0,1,0],[1,1,0]] }',
            ),
            r"bad.toml: bodies\[1\]: points must span a volume",
        ),
    ],
)
def test_bad_files_name_the_file_and_the_place(tmp_path, edit, expected):
    with pytest.raises(SceneError, match=expected):
        scene_file.load(_write(tmp_path, edit(GOOD)))


def test_a_good_file_builds_what_it_says(tmp_path):
    loaded = scene_file.load(_write(tmp_path, GOOD, "good.toml"))
    world = loaded.world
    assert loaded.run.dt == 0.01 and loaded.run.duration == 5.0
    ball, box = world.body("ball"), world.body("box")
    assert ball.mass == 1.0 and box.mass == pytest.approx(500.0 * 0.008)
    ball_shape = int(np.flatnonzero(world.model.shape_body == ball.index)[0])
    assert world.model.shape_restitution[ball_shape] == 0.7 and world.model.shape_friction[ball_shape] == 0.9
    with pytest.raises(SceneError, match=r"missing.toml: cannot read the file"):
        scene_file.load(tmp_path / "missing.toml")
    with pytest.raises(SceneError, match=r"scene.yaml: a scene file must end in .toml or .json"):
        scene_file.load(tmp_path / "scene.yaml")


JUNK = st.one_of(st.none(), st.booleans(), st.integers(-3, 3), st.floats(allow_nan=True, allow_infinity=True),
                 st.text(max_size=3), st.lists(st.floats(-2, 2), max_size=4), st.dictionaries(st.text(max_size=2),
                 st.integers(), max_size=2))  # fmt: skip


def _paths(node):
    return (path for path, _ in _places(node))


BASE = tomllib.loads(
    GOOD + '[[joints]]\ntype = "hinge"\na = "ball"\nb = "box"\nanchor = [0.5, 0, 1]\naxis = [0, 1, 0]\n'
)
PATHS = [p for p in _paths(BASE) if p]


VEHICLES = tomllib.loads(
    '[[vehicles]]\ntype = "quadrotor"\nname = "cf"\nposition = [0, 0, 1]\nrotor_speeds = "hover"\n'
    'controller = { type = "se3", rate = 100.0, kp_pos = [6.5, 6.5, 15.0] }\n'
    'trajectory = { type = "minimum_snap", waypoints = [[0, 0, 1], [1, 0, 1]], times = [0.0, 2.0] }\n'
    '[[vehicles]]\ntype = "quadrotor"\nparams = { base = "hummingbird", mass = 0.6 }\ncommands = [1, 2, 3, 4]\n'
    '[wind]\ntype = "dryden"\nmean = [2.0, 0.0, 0.0]\nsigma = 0.5\nlength_scale = 10.0\nseed = 1\n'
)
VEHICLE_PATHS = [p for p in _paths(VEHICLES) if p]


def _mutant_builds_or_fails_cleanly(base: dict, mutations) -> None:
    data = copy.deepcopy(base)
    for path, junk in mutations:
        node = data
        try:
            for key in path[:-1]:
                node = node[key]
            node[path[-1]] = junk
        except (KeyError, IndexError, TypeError):
            continue
    try:
        world = scene_file.from_dict(data, label="mutant").world
    except SceneError as error:
        assert str(error).startswith("mutant:")
        return
    assert all(math.isfinite(m) for m in world.model.body_mass)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.tuples(st.sampled_from(PATHS), JUNK), min_size=1, max_size=3))
def test_random_mutations_give_clean_errors_or_valid_worlds(mutations):
    _mutant_builds_or_fails_cleanly(BASE, mutations)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.tuples(st.sampled_from(VEHICLE_PATHS), JUNK), min_size=1, max_size=3))
def test_random_mutations_of_vehicles_and_wind_give_clean_errors_or_valid_worlds(mutations):
    _mutant_builds_or_fails_cleanly(VEHICLES, mutations)


def test_an_articulation_in_a_scene_becomes_bodies_and_joints(tmp_path):
    loaded = scene_file.load(scene_file.shipped_scene("robot_arm"))
    world = loaded.world
    assert [b.name for b in world.bodies if b.name.startswith("arm/")] == ["arm/shoulder", "arm/elbow", "arm/wrist"]
    assert [j.kind for j in world.joints] == ["hinge"] * 3
    assert world.joints[0].body_a.name == "arm/shoulder" and world.joints[0].body_b is None
    bad = GOOD + '[[articulations]]\nname = "a"\n[[articulations.links]]\nname = "l"\nparent = "nope"\n'
    bad += 'joint = { type = "revolute", axis = [0, 1, 0] }\nmass = 1.0\n'
    with pytest.raises(SceneError, match=r"bad.toml: articulations\[0\].links\[0\].parent: no earlier link named"):
        scene_file.load(_write(tmp_path, bad))
    bad = GOOD + '[[articulations]]\nname = "a"\n[[articulations.links]]\nname = "l"\n'
    bad += 'joint = { type = "ball", axis = [0, 1, 0] }\n'
    with pytest.raises(SceneError, match=r"articulations\[0\].links\[0\].joint: .*take none"):
        scene_file.load(_write(tmp_path, bad))


def test_joint_aliases_build_ropes_and_springs(tmp_path):
    text = GOOD + (
        '[[joints]]\ntype = "rope"\na = "ball"\nanchor_a = [0, 0, 1]\nanchor_b = [0, 0, 2]\n'
        '[[joints]]\ntype = "spring"\na = "box"\nb = "ball"\nanchor_a = [1, 0, 1]\nanchor_b = [0, 0, 1]\n'
        "spring_hertz = 2.0\n"
    )
    world = scene_file.load(_write(tmp_path, text, "ropes.toml")).world
    rope, spring = (world._builder.joints[j.index].drive for j in world.joints)
    assert rope[0] == 0.0 and rope[1] == 1.0  # slack down to 0, taut at its length
    assert spring[4] == 2.0 and spring[6] == 1.0  # a spring towards the length at creation


def test_the_fast_toml_parser_reads_every_shipped_scene_as_the_standard_one_does(monkeypatch):
    import sys
    import tomllib

    from tumble.scene_file import _parse_toml

    for path in scene_file.shipped():
        text = path.read_text()
        assert _parse_toml(text) == tomllib.loads(text), path.name
    # Without rtoml the standard parser reads them, and a malformed file is reported as it reports it either way.
    text = scene_file.shipped_scene("pendulum").read_text()
    monkeypatch.setitem(sys.modules, "rtoml", None)
    assert _parse_toml(text) == tomllib.loads(text)
    monkeypatch.delitem(sys.modules, "rtoml")
    with pytest.raises(tomllib.TOMLDecodeError, match=r"Cannot overwrite a value \(at line 3"):
        _parse_toml("[world]\na = 1\na = 2\n")
