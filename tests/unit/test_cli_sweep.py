"""``tumble sweep``'s values (PLACE=VALUES: grids, lists, random ranges) and its errors, called in this process
(tests/test_cli.py runs the command as a user does)."""

from __future__ import annotations

import pytest

from tumble import cli, scene_file
from tumble.cli_common import BadInput
from tumble.cli_sweep import parse_param
from tumble.ensemble import executors

BLOCK = scene_file.shipped_scene("sliding_block")


@pytest.mark.parametrize(
    ("text", "sampled", "parsed"),
    [
        (
            "bodies[0].friction=0.1:0.9:9",
            False,
            ("bodies[0].friction", "values", [0.1 + 0.1 * k for k in range(8)] + [0.9]),
        ),
        ("world.gravity[2]=-9.81,-1.62", False, ("world.gravity[2]", "values", [-9.81, -1.62])),
        ("world.substeps=4:16:4", False, ("world.substeps", "values", [4, 8, 12, 16])),
        ("world.substeps=8", False, ("world.substeps", "values", [8])),
        ("world.integrator=rk4,symplectic", False, ("world.integrator", "values", ["rk4", "symplectic"])),
        ("world.sleep=true,false", False, ("world.sleep", "values", [True, False])),
        ("a=1:2:1", False, ("a", "values", [1])),
        ("a=0:1:3", False, ("a", "values", [0.0, 0.5, 1.0])),
        ("bodies[0].friction=0.1:0.9", True, ("bodies[0].friction", "uniform", (0.1, 0.9))),
        ("world.gravity[2]=-9.81,-1.62", True, ("world.gravity[2]", "values", [-9.81, -1.62])),
    ],
)
def test_values_parse(text, sampled, parsed):
    place, kind, values = parse_param(text, sampled)
    assert (place, kind) == parsed[:2]
    assert len(values) == len(parsed[2])
    for got, expected in zip(values, parsed[2], strict=True):
        assert type(got) is type(expected)
        assert got == (pytest.approx(expected, abs=1e-15) if isinstance(expected, float) else expected)


@pytest.mark.parametrize(
    ("text", "sampled", "match"),
    [
        ("friction", False, "write PLACE=VALUES"),
        ("=0.5", False, "write PLACE=VALUES"),
        ("friction=", False, "write PLACE=VALUES"),
        ("friction=0.1:0.9", False, "a range is LOW:HIGH:N"),
        ("friction=0.1:0.9:2.5", False, "a range is LOW:HIGH:N"),
        ("friction=0.1:0.9:0", False, "a range is LOW:HIGH:N"),
        ("friction=a:b:3", False, "a range is LOW:HIGH:N"),
        ("friction=0.1:0.9:9", True, "with --samples a range is LOW:HIGH"),
        ("friction=0.9:0.1", True, "with --samples a range is LOW:HIGH"),
        ("friction=nan", False, "not a finite number"),
    ],
)
def test_bad_values_are_named(text, sampled, match):
    with pytest.raises(BadInput, match=match):
        parse_param(text, sampled)


def test_an_unreachable_scheduler_is_named_as_the_option(tmp_path, monkeypatch, capsys):
    pytest.importorskip("distributed")
    monkeypatch.setattr(executors, "CONNECT_TIMEOUT", 0.5)
    status = cli.main(["sweep", str(BLOCK), "--param", "materials.surface.friction=0.2,0.4", "--scheduler",
                       "tcp://127.0.0.1:1", "--out", str(tmp_path / "out"), "--quiet"])  # fmt: skip
    assert status == 2
    error = capsys.readouterr().err
    assert "tumble: error: --scheduler: cannot reach the Dask scheduler at 'tcp://127.0.0.1:1'" in error
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


def test_the_same_place_twice_is_refused(tmp_path, capsys):
    status = cli.main(["sweep", str(BLOCK), "-p", "world.dt=0.01", "-p", "world.dt=0.02", "--out", str(tmp_path)])
    assert status == 2 and "--param: world.dt is given twice" in capsys.readouterr().err


def test_the_summary_line_is_one_line_however_long_the_scene_path():
    # A title on the table wrapped at the table's width: CI's checkout path broke "(6 from an earlier run)" in two.
    import argparse
    import io

    from rich.console import Console

    from tumble.cli_sweep import _print_table

    scene = "/a/checkout/far/down/" + "deep/" * 30 + "sliding_block.toml"
    args = argparse.Namespace(scene=scene, out="/tmp/" + "sweep" * 30)
    rows = [{"member": k, "bodies[0].friction": 0.1 * k, "status": "done", "reused": k < 2, "wall_s": 0.5}
            for k in range(3)]  # fmt: skip
    printed = io.StringIO()
    _print_table(Console(file=printed, width=160), args, rows, ["bodies[0].friction"])
    lines = printed.getvalue().splitlines()
    assert f"{scene}: 3 members, 3 done, 0 failed (2 from an earlier run)" in lines
    assert f"every row in {args.out}/results.csv" in lines
