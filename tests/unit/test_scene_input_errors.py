"""Bad scene files give a located message and exit status 2, never a traceback (issue 21, the cases done so far):
strict numbers, finite vectors, any bytes and any depth. The CLI runs in-process, as ``tumble info`` would."""

from __future__ import annotations

import pytest

from tumble import scene_file
from tumble.cli import EXIT_BAD_INPUT, main

GOOD = """[world]
gravity = [0, 0, -9.81]

[[bodies]]
name = "ball"
shape = { type = "sphere", radius = 0.5 }
mass = 1.0
position = [0, 0, 1]

[recording]
every = 1
"""


def _fails_cleanly(capsys, path, *expected: str) -> str:
    status = main(["info", str(path)])
    out, err = capsys.readouterr()
    assert status == EXIT_BAD_INPUT, (status, out, err)
    assert "Traceback" not in out + err
    for text in expected:
        assert text in err, (text, err)
    return err


@pytest.mark.parametrize(
    ("old", "new", "expected"),
    [
        ("radius = 0.5", "radius = true", "bodies[0].shape.radius: Input should be a valid number (got True)"),
        ("mass = 1.0", 'mass = "1"', "bodies[0].mass: Input should be a valid number (got '1')"),
        ("gravity = [0, 0, -9.81]", "gravity = [nan, 0, -9.81]", "world.gravity[0]: Input should be a finite number"),
        ("gravity = [0, 0, -9.81]", "gravity = [0, 0, -inf]", "world.gravity[2]: Input should be a finite number"),
        ("position = [0, 0, 1]", "position = [0, false, 1]", "bodies[0].position[1]: Input should be a valid number"),
        ("every = 1", "every = 99999999999999999999", "recording.every: Input should be less than or equal to"),
        ("every = 1", "every = 2.0", "recording.every: Input should be a valid integer"),
        ("[recording]", "[recording]\npath = 'a.h5'\n[world.x]", "world.x: unknown key"),
        ("radius = 0.5", "radius = 1e200", "bodies[0]: Sphere(radius=1e+200) is too large: its volume overflows"),
        ("mass = 1.0", "mass = 1e-320", "bodies[0]: mass=1e-320 is too small for a dynamic body: 1/mass overflows"),
        ('shape = { type = "sphere", radius = 0.5 }', 'shape = { type = "capsule", radius = 1e103, length = 1 }',
         "bodies[0]: Capsule(radius=1e+103"),
    ],
)  # fmt: skip
def test_a_bad_value_is_named_with_its_place(capsys, tmp_path, old, new, expected):
    assert old in GOOD
    path = tmp_path / "bad.toml"
    path.write_text(GOOD.replace(old, new, 1))
    _fails_cleanly(capsys, path, f"bad.toml: {expected}")


def test_the_good_scene_loads(tmp_path):
    path = tmp_path / "good.toml"
    path.write_text(GOOD)
    assert scene_file.load(path).world.bodies[0].name == "ball"


@pytest.mark.parametrize(
    ("name", "data", "expected"),
    [
        ("utf16.toml", GOOD.encode("utf-16"), "not UTF-8 text (byte 0xff at offset 0"),
        ("latin1.toml", ("# café\n" + GOOD).encode("latin-1"), "not UTF-8 text (byte 0xe9 at offset 5"),
        ("binary.toml", bytes(range(256)), "not UTF-8 text (byte 0x80 at offset 128"),
        ("binary.json", bytes(range(255, -1, -1)), "not UTF-8 text (byte 0xff at offset 0"),
        ("deep.toml", ("a = " + "[" * 100_000 + "]" * 100_000 + "\n").encode(), "not valid TOML: nested too deeply"),
        ("deep.json", ('{"a": ' + "[" * 100_000 + "]" * 100_000 + "}").encode(), "not valid JSON: nested too deeply"),
        ("nul.toml", b"[world]\x00\n", "not valid TOML"),
        ("empty.json", b"", "not valid JSON"),
    ],
)
def test_any_bytes_at_any_depth_give_a_located_error(capsys, tmp_path, name, data, expected):
    path = tmp_path / name
    path.write_bytes(data)
    _fails_cleanly(capsys, path, f"{name}: {expected}")


def test_a_byte_order_mark_is_skipped(tmp_path):
    path = tmp_path / "bom.toml"
    path.write_bytes(b"\xef\xbb\xbf" + GOOD.encode())
    assert scene_file.load(path).world.bodies[0].name == "ball"


def test_a_dict_nested_thousands_deep_is_refused_with_its_first_levels_shown():
    nested: dict = {}
    inner = nested
    for _ in range(5000):
        inner["a"] = {}
        inner = inner["a"]
    with pytest.raises(scene_file.SceneError, match=r"^s: description: Input should be a valid string \(got \{'a': "):
        scene_file.from_dict({"description": nested}, label="s")


CONTACT = GOOD + '\n[[static]]\nshape = { type = "plane" }\n'


def _status(capsys, *argv: str) -> tuple[int, str]:
    try:
        status = main(list(argv))
    except SystemExit as exit_:  # argparse's own refusals
        status = exit_.code
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return status, err


@pytest.mark.parametrize("integrator", ["rk4", "euler", "midpoint"])
def test_an_integrator_for_free_bodies_only_is_refused_for_a_scene_with_contacts(capsys, tmp_path, integrator):
    path = tmp_path / "rk4.toml"
    path.write_text(CONTACT.replace("[world]", f'[world]\nintegrator = "{integrator}"'))
    for command in ("info", "run"):
        status, err = _status(capsys, command, str(path))
        assert status == EXIT_BAD_INPUT
        assert f"rk4.toml: world.integrator: '{integrator}' integrates free bodies only" in err
    for fine in ("auto", "symplectic"):
        path.write_text(CONTACT.replace("[world]", f'[world]\nintegrator = "{fine}"'))
        assert scene_file.load(path).world.integrator == fine


@pytest.mark.parametrize(
    ("options", "expected"),
    [
        (["--dt", "1e-300", "--duration", "1e300"], "--duration 1e+300 at --dt 1e-300 is inf steps"),
        (["--dt", "1e-10", "--duration", "1e6"], "is 1e+16 steps; a run takes at most 1e+15"),
        (["--every", "99999999999999999999"], "argument --every: must be an integer from 1 to 2147483647"),
        (["--out", "/proc/tumble-test.h5"], "/proc/tumble-test.h5: cannot write it:"),
        (["--html", "/proc/tumble-test.html"], "/proc/tumble-test.html: cannot write it:"),
        (["--plot", "/proc/tumble-test.png"], "/proc/tumble-test.png: cannot write it:"),
    ],
)
def test_run_options_that_cannot_run_or_be_written_are_refused_before_the_run(capsys, tmp_path, options, expected):
    path = tmp_path / "good.toml"
    path.write_text(GOOD)
    status, err = _status(capsys, "run", str(path), "--duration", "0.05", "-q", *options)
    assert status == EXIT_BAD_INPUT and expected in err, err
    assert "simulated" not in err  # nothing ran


def test_a_write_that_fails_after_the_run_names_the_path(capsys, tmp_path, monkeypatch):
    from tumble import viewer

    def full_disk(*args, **kwargs):
        raise OSError(28, "No space left on device", str(tmp_path / "replay.html"))

    monkeypatch.setattr(viewer, "write_html", full_disk)
    path = tmp_path / "good.toml"
    path.write_text(GOOD)
    status, err = _status(capsys, "run", str(path), "--duration", "0.05", "-q", "--html", str(tmp_path / "replay.html"))
    assert status == EXIT_BAD_INPUT
    assert "replay.html: cannot write it: No space left on device" in err


@pytest.mark.parametrize(
    ("old", "new", "expected"),
    [
        ('name = "ball"', 'name = "ba\\u0000ll"', "bodies[0].name: Value error, must not hold a NUL character"),
        ("every = 1", 'every = 1\npath = "out\\u0000.h5"', "recording.path: Value error, must not hold a NUL"),
    ],
)
def test_names_and_paths_with_a_nul_are_refused(capsys, tmp_path, old, new, expected):
    path = tmp_path / "nul.toml"
    path.write_text(GOOD.replace(old, new, 1))
    status, err = _status(capsys, "run", str(path), "--duration", "0.05", "-q")
    assert status == EXIT_BAD_INPUT and f"nul.toml: {expected}" in err, err


def test_the_api_refuses_a_body_name_with_a_nul():
    import tumble

    with pytest.raises(ValueError, match=r"name must not hold a NUL character .* got 'a\\x00b'"):
        tumble.World().add_body(tumble.Sphere(0.1), mass=1.0, name="a\x00b")


def test_a_quaternion_of_huge_components_is_normalised_not_zeroed():
    import numpy as np

    import tumble

    body = tumble.World().add_body(tumble.Sphere(0.1), mass=1.0, orientation=[8.66e299, 0.0, 0.0, 5e299])
    np.testing.assert_allclose(body.orientation, np.array([8.66, 0.0, 0.0, 5.0]) / np.hypot(8.66, 5.0), rtol=1e-15)
    assert np.isfinite(body.angular_velocity).all()


@pytest.mark.parametrize(
    ("make", "expected"),
    [
        (
            lambda m: m.capsule(0.04, 3.5e299, mass=1.0),
            r"capsule\(radius=0.04, length=3.5e\+299, mass=1.0\): the moments of inertia \[inf",
        ),  # length² overflowed: OverflowError
        (lambda m: m.capsule(4e-302, 0.1, mass=1.0), "the sizes give a volume of 0.0: too small"),  # 0 division
        (lambda m: m.solid_sphere(1e-200, density=1.0), "the sizes give a volume of 0.0: too small"),
        (lambda m: m.box((1e200, 1e200, 1e200), mass=1.0), "the sizes give a volume of inf: too large"),
    ],
)
def test_mass_properties_of_sizes_past_the_float_range_are_refused_by_name(make, expected):
    from tumble import mass

    with pytest.raises(ValueError, match=expected):
        make(mass)


def test_a_scene_of_too_many_steps_says_whose_values_they_are(capsys, tmp_path):
    path = tmp_path / "long.toml"
    path.write_text(GOOD.replace("[world]", "[world]\ndt = 1e-300\nduration = 1e300"))
    status, err = _status(capsys, "run", str(path), "-q")
    assert status == EXIT_BAD_INPUT
    assert "the scene's duration 1e+300 s at the scene's dt 1e-300 s is inf steps" in err


def test_an_unwritable_recording_path_or_view_output_is_refused_before_anything_runs(capsys, tmp_path):
    path = tmp_path / "good.toml"
    path.write_text(GOOD.replace("every = 1", 'every = 1\npath = "/proc/tumble-test.h5"'))
    status, err = _status(capsys, "run", str(path), "--duration", "0.05", "-q")
    assert status == EXIT_BAD_INPUT and "/proc/tumble-test.h5: cannot write it:" in err
    trajectory = tmp_path / "run.h5"
    status, err = _status(capsys, "run", str(path), "--duration", "0.05", "-q", "--out", str(trajectory))
    assert status == 0, err
    status, err = _status(capsys, "view", str(trajectory), "-o", "/proc/tumble-test.html")
    assert status == EXIT_BAD_INPUT and "/proc/tumble-test.html: cannot write it:" in err
