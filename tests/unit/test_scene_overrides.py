"""Changing a scene's values by their place (tumble.scene_file.overrides): what tumble sweep and tumble.ensemble
build their members with."""

from __future__ import annotations

import numpy as np
import pytest

from tumble import scene_file
from tumble.scene_file import SceneError
from tumble.scene_file.overrides import apply, parse_place

BLOCK = scene_file.shipped_scene("sliding_block")


@pytest.mark.parametrize(
    ("place", "steps"),
    [
        ("friction", ["friction"]),
        ("bodies[0].friction", ["bodies", 0, "friction"]),
        ("bodies[12].shape.extents[2]", ["bodies", 12, "shape", "extents", 2]),
        ("materials.surface.friction", ["materials", "surface", "friction"]),
        ("world.gravity[2]", ["world", "gravity", 2]),
    ],
)
def test_places_parse_as_errors_name_them(place, steps):
    assert parse_place(place) == steps


@pytest.mark.parametrize("place", ["", "[0]", "bodies..x", "bodies[0]friction", "bodies[-1].mass", "bodies.", ".a",
                                   "bodies[x]", "a b", 3])  # fmt: skip
def test_malformed_places_are_refused(place):
    with pytest.raises(SceneError, match="place in a scene"):
        parse_place(place)


def test_apply_copies_only_along_the_places_and_leaves_the_input_alone():
    data = {"world": {"gravity": [0.0, 0.0, -9.81], "dt": 0.01}, "bodies": [{"mass": 1.0}, {"mass": 2.0}]}
    out = apply(data, {"world.gravity[2]": -1.62, "bodies[1].mass": 3.0})
    assert out == {"world": {"gravity": [0.0, 0.0, -1.62], "dt": 0.01}, "bodies": [{"mass": 1.0}, {"mass": 3.0}]}
    assert data["world"]["gravity"][2] == -9.81 and data["bodies"][1]["mass"] == 2.0
    assert out["bodies"][0] is data["bodies"][0]  # untouched branches are shared


def test_load_with_overrides_equals_the_edited_file(tmp_path):
    text = BLOCK.read_text()
    edited = tmp_path / "edited.toml"
    edited.write_text(
        text.replace("friction = 0.5", "friction = 0.3").replace("[world]", "[world]\ngravity = [0.0, 0.0, -1.62]")
    )
    changed = scene_file.load(BLOCK, {"materials.surface.friction": 0.3, "world.gravity[2]": -1.62})
    direct = scene_file.load(edited)
    assert changed.scene == direct.scene
    np.testing.assert_array_equal(changed.world.model.gravity, [0.0, 0.0, -1.62])  # a default filled, then changed
    np.testing.assert_array_equal(changed.world.model.shape_friction, direct.world.model.shape_friction)
    assert scene_file.load(BLOCK).world.model.shape_friction.tolist() == [0.5, 0.5]  # the file is unchanged


@pytest.mark.parametrize(
    ("overrides", "match"),
    [
        (
            {"bodies[3].mass": 2.0},
            r"sliding_block.toml: bodies\[3\].mass: bodies\[3\] is past the end \(bodies has 1 item\)",
        ),
        ({"bodies[0].frction": 0.2}, r"sliding_block.toml: bodies\[0\].frction: unknown key"),
        ({"wind.mean": [1.0, 0.0, 0.0]}, r"wind.mean: the scene has no wind"),
        ({"world.gravity.z": 1.0}, r"world.gravity is a list, not a table of keys"),
        ({"world[0]": 1.0}, r"world\[0\]: world is not a list"),
        (
            {"materials.surface.friction": -1.0},
            r"materials.surface.friction: Input should be greater than or equal to 0",
        ),
        ({"world.substeps": 2.5}, r"world.substeps: Input should be a valid integer"),
    ],
)
def test_overrides_the_scene_cannot_take_are_named(overrides, match):
    with pytest.raises(SceneError, match=match):
        scene_file.check(BLOCK, overrides)
    with pytest.raises(SceneError, match=match):
        scene_file.load(BLOCK, overrides)
