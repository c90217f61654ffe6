"""tumble.viewer, the Python side of the HTML replay: geometry, data encoding, page assembly, errors.

The trajectories here are made up from known paths (no stepping), so these tests stay fast with and without
Numba's JIT; the browser side is ``tests/browser/test_replay_browser.py``.
"""

from __future__ import annotations

import base64
import re

import numpy as np
import pytest

import tumble
from tumble import scenes, viewer
from tumble.rotation import quat_from_axis_angle, quat_from_rotvec, quat_multiply, quat_rotate
from tumble.viewer.page import decode_array, encode_array, read_page_data, select_frames

HULL_POINTS = np.array(
    [[0.1, 0.0, 0.0], [-0.1, 0.02, 0.0], [0.0, 0.12, 0.01], [0.0, -0.1, 0.03], [0.01, 0.0, 0.1], [0.0, 0.01, -0.1]]
)


def all_kinds_world() -> tumble.World:
    """One body of every shape kind, a compound with its COM off the frame origin, and three static bodies."""
    world = tumble.World()
    world.add_static(tumble.Plane(normal=(0.0, 0.2, 1.0), offset=-0.1), name="ground")
    world.add_static(scenes.bowl_mesh(radius=0.5, depth=0.2, segments=8, rings=2), position=(3, 0, 0), name="bowl")
    world.add_static(tumble.Box((1.0, 1.0, 0.1)), position=(0.0, 0.0, -1.0), name="shelf")
    world.add_body(tumble.Sphere(0.1), density=1000.0, position=(0, 0, 1), name="ball")
    crate_q = quat_from_axis_angle((1, 0, 0), 0.4)
    world.add_body(tumble.Box((0.2, 0.4, 0.6)), density=500.0, position=(1, 0, 1), orientation=crate_q, name="crate")
    world.add_body(tumble.Capsule(0.05, 0.3), density=900.0, position=(0, 1, 1), name="pill")
    world.add_body(tumble.Cylinder(0.1, 0.2), density=700.0, position=(1, 1, 1), name="can")
    world.add_body(tumble.ConvexHull(HULL_POINTS), density=2500.0, position=(2, 0, 1), name="rock1")
    world.add_body(tumble.ConvexHull(HULL_POINTS), density=2500.0, position=(2, 1, 1), name="rock2")
    part_q = quat_from_axis_angle((0, 1, 0), 0.7)
    world.add_body(
        [(tumble.Box((0.1, 0.1, 0.1)), (0.5, 0.0, 0.0)), (tumble.Sphere(0.1), (0.0, 0.0, 0.2), part_q)],
        density=1000.0,
        position=(-1, 0, 1),
        orientation=quat_from_axis_angle((0, 0, 1), 0.3),
        name="compound",
    )
    return world


def made_up_trajectory(world: tumble.World, frames: int = 6, dt: float = 0.1, still=()) -> tumble.Trajectory:
    """Every body with mass drifts and spins at its own constant rate, except those named in ``still``."""
    model = world.model
    n = model.body_count
    bodies = world.bodies
    pos0 = np.array([b.position for b in bodies])
    quat0 = np.array([b.orientation for b in bodies])
    moves = (model.body_mass > 0.0) & np.array([b.name not in still for b in bodies])
    t = dt * np.arange(frames)
    velocity = np.where(moves[:, None], np.array([0.1, -0.2, 0.3]) * (1.0 + np.arange(n))[:, None], 0.0)
    omega = np.where(moves[:, None], np.array([0.5, 1.0, -2.0]) / (1.0 + np.arange(n))[:, None], 0.0)
    position = pos0[None] + t[:, None, None] * velocity[None]
    spin = quat_from_rotvec(t[:, None, None] * omega[None])
    orientation = quat_multiply(spin, np.broadcast_to(quat0, (frames, n, 4)))
    return tumble.Trajectory(
        time=t,
        position=position,
        orientation=orientation,
        velocity=np.broadcast_to(velocity, (frames, n, 3)).copy(),
        angular_velocity=np.broadcast_to(omega, (frames, n, 3)).copy(),
        kinetic_energy=10.0 + t,
        potential_energy=5.0 - 2.0 * t,
        body_mass=model.body_mass.copy(),
        body_inertia=model.body_inertia_local.copy(),
        body_com_local=model.body_com_local.copy(),
        gravity=model.gravity.copy(),
        body_names=[b.name or "" for b in bodies],
    )


@pytest.fixture(scope="module")
def world():
    return all_kinds_world()


@pytest.fixture(scope="module")
def trajectory(world):
    return made_up_trajectory(world)


@pytest.fixture(scope="module")
def page(world, trajectory):
    return viewer.replay_html(trajectory, world=world, title="all kinds")


# --- the page ------------------------------------------------------------------------------------------------


def test_page_is_self_contained(page):
    assert page.startswith("<!DOCTYPE html>")
    lowered = page.lower()
    assert "http://" not in lowered and "https://" not in lowered
    assert "<script src" not in lowered and not re.search(r"<script[^>]*\ssrc\s*=", lowered)
    assert "<link" not in lowered and "@import" not in lowered and "url(" not in lowered
    assert "<iframe" not in lowered
    # Exactly the data block and the inlined script.
    assert lowered.count("<script") == 2 and lowered.count("</script>") == 2
    assert "{{" not in page.replace("{{" + "}}", "")  # every placeholder filled
    assert "<title>all kinds</title>" in page


def test_title_and_body_names_cannot_break_out_of_the_page():
    world = tumble.World()
    nasty = '</script><script>alert("x")</script>&amp;'
    world.add_body(tumble.Sphere(0.1), mass=1.0, name=nasty)
    page = viewer.replay_html(made_up_trajectory(world, frames=3), world=world, title="<b>pile</b> & co")
    assert page.lower().count("<script") == 2
    assert "<b>pile</b>" not in page and "&lt;b&gt;pile&lt;/b&gt; &amp; co" in page
    data = read_page_data(page)
    assert data["names"] == [nasty] and data["title"] == "<b>pile</b> & co"


def test_data_round_trip(trajectory, page):
    data = read_page_data(page)
    n, frames = trajectory.body_count, len(trajectory)
    assert data["bodyCount"] == n and data["frameCount"] == frames
    assert data["names"] == trajectory.body_names
    np.testing.assert_array_equal(data["mass"], trajectory.body_mass)
    np.testing.assert_array_equal(data["time"], trajectory.time)
    np.testing.assert_allclose(data["kinetic"], trajectory.kinetic_energy, rtol=1e-7)
    np.testing.assert_allclose(data["potential"], trajectory.potential_energy, rtol=1e-7)
    moving = data["moving"]
    np.testing.assert_array_equal(moving, np.flatnonzero(trajectory.body_mass > 0.0))
    # Positions are float32, body-major (M, T, 3).
    np.testing.assert_allclose(data["pos"], trajectory.position[:, moving].transpose(1, 0, 2), rtol=1e-7, atol=1e-7)
    # Orientations are round(32767 q): at most half a step off per component.
    quat = data["quat"] / 32767.0
    expected = trajectory.orientation[:, moving].transpose(1, 0, 2)
    assert np.max(np.abs(quat - expected)) <= 0.5 / 32767.0 + 1e-12
    # Speeds are float16 (relative step 2^-11).
    speed = np.linalg.norm(trajectory.velocity[:, moving], axis=-1).T
    np.testing.assert_allclose(data["speed"], speed, rtol=2**-11)
    # Every body's first pose, for the ones that do not move.
    np.testing.assert_allclose(data["restPos"], trajectory.position[0], rtol=1e-7, atol=1e-7)
    np.testing.assert_allclose(data["restQuat"], trajectory.orientation[0], atol=1e-7)


def test_bodies_that_never_move_store_no_frames(world):
    trajectory = made_up_trajectory(world, frames=20, still=("ball", "can"))
    data = read_page_data(viewer.replay_html(trajectory, world=world))
    names = [trajectory.body_names[i] for i in data["moving"]]
    assert "ball" not in names and "can" not in names
    assert not {"ground", "bowl", "shelf"} & set(names)  # static bodies
    assert data["pos"].shape == (len(names), 20, 3) and data["quat"].shape == (len(names), 20, 4)


def test_size_is_the_packed_frames_plus_a_fixed_overhead():
    """The uncompressed page holds 22 bytes per moving body and frame (3 float32, 4 int16, 1 float16) in base64,
    plus the script, the styles and the geometry, which do not grow with the frames."""
    world = scenes.box_pile(60)
    sizes = {}
    for frames in (10, 110):
        trajectory = made_up_trajectory(world, frames=frames)
        sizes[frames] = len(viewer.replay_html(trajectory, world=world, compress=False).encode())
    per_frame = (sizes[110] - sizes[10]) / 100
    expected = (60 * 22 + 8 + 4 + 4) * 4 / 3  # + the time (f8) and two energies (f4) of each frame
    assert per_frame == pytest.approx(expected, rel=0.01)
    assert sizes[10] < 150_000  # script, styles and 61 bodies' geometry (measured 72 kB)


def test_compression_shrinks_bodies_at_rest():
    world = scenes.box_pile(60)
    trajectory = made_up_trajectory(world, frames=200, still=tuple(f"box{k}" for k in range(30, 60)))
    # Half the boxes rest for the whole run (stored once); the other half only move: gzip still gains.
    raw = viewer.replay_html(trajectory, world=world, compress=False)
    packed = viewer.replay_html(trajectory, world=world, compress=True)
    assert len(packed) < 0.9 * len(raw)
    for key in ("pos", "quat", "speed", "time"):
        np.testing.assert_array_equal(read_page_data(packed)[key], read_page_data(raw)[key])


def test_blobs_round_trip_every_dtype():
    rng = np.random.default_rng(3)
    values = rng.normal(size=(50, 7))
    for dtype, tol in (("f8", 0.0), ("f4", 1e-7), ("f2", 1e-3)):
        for compress in (False, True):
            blob = encode_array(values, dtype, compress=compress)
            np.testing.assert_allclose(decode_array(blob), values, rtol=tol, atol=tol)
    ints = rng.integers(-30000, 30000, size=(3000,))
    for dtype in ("i2", "i4"):
        np.testing.assert_array_equal(decode_array(encode_array(ints, dtype)), ints)
    np.testing.assert_array_equal(decode_array(encode_array(np.abs(ints), "u4")), np.abs(ints))
    blob = encode_array(np.zeros(10_000), "f4")
    assert blob["gzip"] and len(base64.b64decode(blob["data"])) < 1000


def test_max_frames_keeps_the_first_and_last(world):
    trajectory = made_up_trajectory(world, frames=50)
    data = read_page_data(viewer.replay_html(trajectory, world=world, max_frames=7))
    assert data["frameCount"] == 7 == len(data["time"])
    assert data["time"][0] == trajectory.time[0] and data["time"][-1] == trajectory.time[-1]
    np.testing.assert_array_equal(select_frames(5, 10), np.arange(5))
    np.testing.assert_array_equal(select_frames(5, None), np.arange(5))


def test_bounds_hold_every_body(trajectory, page):
    data = read_page_data(page)
    lo, hi = np.array(data["bounds"]["min"]), np.array(data["bounds"]["max"])
    dynamic = trajectory.body_mass > 0.0
    assert np.all(trajectory.position[:, dynamic] >= lo) and np.all(trajectory.position[:, dynamic] <= hi)
    view_lo, view_hi = np.array(data["view"]["min"]), np.array(data["view"]["max"])
    assert np.all(view_lo >= lo - 1e-12) and np.all(view_hi <= hi + 1e-12)


# --- geometry ------------------------------------------------------------------------------------------------


def test_geometry_describes_every_kind(world):
    geometry = viewer.scene_geometry(world)
    assert geometry["body_count"] == len(world.bodies)
    by_body = {}
    for shape in geometry["shapes"]:
        by_body.setdefault(world.bodies[shape["body"]].name, []).append(shape)
    assert [s["kind"] for s in by_body["ground"]] == ["plane"]
    assert [s["kind"] for s in by_body["bowl"]] == ["mesh"]
    assert [s["kind"] for s in by_body["compound"]] == ["box", "sphere"]
    np.testing.assert_allclose(by_body["ground"][0]["size"][:3], np.array([0, 0.2, 1]) / np.hypot(0.2, 1))
    assert by_body["ground"][0]["size"][3] == pytest.approx(-0.1)
    np.testing.assert_allclose(by_body["crate"][0]["size"], [0.1, 0.2, 0.3])  # half extents
    assert by_body["ball"][0]["size"] == [0.1]
    assert by_body["pill"][0]["size"] == pytest.approx([0.05, 0.15])  # radius, half length
    assert by_body["can"][0]["size"] == pytest.approx([0.1, 0.1])  # radius, half height
    # The two equal hulls share one mesh; the bowl has its own.
    assert by_body["rock1"][0]["mesh"] == by_body["rock2"][0]["mesh"] != by_body["bowl"][0]["mesh"]
    assert len(geometry["meshes"]) == 2
    hull = geometry["meshes"][by_body["rock1"][0]["mesh"]]
    assert hull["vertices"].dtype == np.float32 and hull["faces"].dtype == np.uint32
    assert hull["faces"].max() < len(hull["vertices"])


def test_shapes_are_placed_from_the_body_frame_origin(world):
    """The model keeps shapes relative to the COM; the geometry must put them back relative to the frame origin,
    which is what ``Trajectory.position`` records."""
    geometry = viewer.scene_geometry(world)
    model = world.model
    assert geometry["shapes"][-2]["position"] == pytest.approx([0.5, 0.0, 0.0])  # as the user placed them
    for k, shape in enumerate(geometry["shapes"]):
        body = world.bodies[shape["body"]]
        from_origin = body.position + quat_rotate(body.orientation, np.array(shape["position"]))
        from_com = body.center_of_mass + quat_rotate(body.orientation, model.shape_pos_local[k])
        np.testing.assert_allclose(from_origin, from_com, atol=1e-12)


def test_planes_become_squares_on_the_plane_around_the_scene(trajectory, page):
    data = read_page_data(page)
    (quad,) = data["planes"]
    normal = np.array([0.0, 0.2, 1.0]) / np.hypot(0.2, 1.0)
    assert float(np.dot(quad["center"], normal)) == pytest.approx(-0.1)
    np.testing.assert_allclose(quat_rotate(np.array(quad["quat"]), np.array([0.0, 0.0, 1.0])), normal, atol=1e-12)
    size = np.linalg.norm(np.array(data["bounds"]["max"]) - np.array(data["bounds"]["min"]))
    assert quad["half"] >= size
    assert all(s["kind"] != "plane" for s in data["shapes"])


def test_without_a_world_bodies_are_drawn_as_balls_of_their_inertia():
    world = tumble.World()
    world.add_static(tumble.Plane())
    world.add_body(tumble.Sphere(0.25), mass=3.0, position=(0, 0, 1))
    world.add_body(tumble.Box((0.1, 0.2, 0.3)), mass=1.0, position=(1, 0, 1))
    data = read_page_data(viewer.replay_html(made_up_trajectory(world, frames=3)))
    assert [s["kind"] for s in data["shapes"]] == ["sphere", "sphere"]
    assert [s["body"] for s in data["shapes"]] == [1, 2]
    assert data["shapes"][0]["size"][0] == pytest.approx(0.25)  # a ball's own radius comes back


# --- entry points and errors ---------------------------------------------------------------------------------


def test_write_html_and_show(tmp_path, world, trajectory):
    path = viewer.write_html(trajectory, tmp_path / "replay.html", world=world, title="written")
    assert path.read_text(encoding="utf-8") == viewer.replay_html(trajectory, world=world, title="written")
    shown = viewer.show(trajectory, world, title="shown", height=300)
    frame = shown._repr_html_() if hasattr(shown, "_repr_html_") else shown.data
    assert frame.startswith("<iframe srcdoc=") and "height:300px" in frame
    # The page is escaped into the attribute: no raw tag inside it.
    srcdoc = frame[len('<iframe srcdoc="') : frame.index('" style=')]
    assert "<" not in srcdoc and "&lt;!DOCTYPE html&gt;" in srcdoc


def test_geometry_can_be_passed_instead_of_the_world(world, trajectory, page):
    geometry = viewer.scene_geometry(world)
    assert viewer.replay_html(trajectory, geometry=geometry, title="all kinds") == page


def test_bad_input_is_named(world, trajectory):
    with pytest.raises(TypeError, match="trajectory must be a tumble.Trajectory"):
        viewer.replay_html({"time": []})
    with pytest.raises(ValueError, match="max_frames"):
        viewer.replay_html(trajectory, world=world, max_frames=1)
    with pytest.raises(ValueError, match="max_frames"):
        viewer.replay_html(trajectory, world=world, max_frames=2.5)
    with pytest.raises(ValueError, match="not both"):
        viewer.replay_html(trajectory, world=world, geometry=viewer.scene_geometry(world))
    with pytest.raises(TypeError, match="title"):
        viewer.replay_html(trajectory, world=world, title=3)
    with pytest.raises(TypeError, match="world must be a tumble.World"):
        viewer.scene_geometry("world")
    other = tumble.World()
    other.add_body(tumble.Sphere(0.1), mass=1.0)
    with pytest.raises(ValueError, match="geometry describes 1 bodies but the trajectory has 10"):
        viewer.replay_html(trajectory, world=other)
    bad = viewer.scene_geometry(world)
    bad["shapes"][0] = {**bad["shapes"][0], "kind": "torus"}
    with pytest.raises(ValueError, match=r"geometry\['shapes'\]\[0\]\['kind'\]"):
        viewer.replay_html(trajectory, geometry=bad)
