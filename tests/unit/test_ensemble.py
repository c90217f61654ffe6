"""tumble.ensemble: members on a local process pool against a serial loop and against Coulomb's law, resuming,
failures that cost no other member (a member's own error, a worker killed mid-run), and bad input named.

The Dask side (a LocalCluster of two worker processes) is in tests/peers/test_ensemble_dask.py."""

from __future__ import annotations

import io
import os
import re
import signal
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest

import tumble
from compiled import compiled_only
from tumble import ensemble, scene_file
from tumble.dynamics import integrate
from tumble.ensemble import executors
from tumble.ensemble.member import member_path
from tumble.trajectory import Trajectory

BLOCK = scene_file.shipped_scene("sliding_block")
SPEED = 2.0  # the block's start speed in the file [m/s]
FRICTION = "materials.surface.friction"
GRAVITY = "world.gravity[2]"
DURATION, DT = 1.0, 1.0 / 240.0


def _rows(table) -> list[dict]:
    """The table as a list of dicts, missing values as None (pandas reads None as NaN in a column of numbers)."""
    if hasattr(table, "to_dict"):
        return table.astype(object).where(table.notna(), None).to_dict("records")
    return list(table)


def _without(rows: list[dict], *names: str) -> list[dict]:
    """The rows less the columns that differ between equal runs (wall time, folder, reuse)."""
    return [{k: v for k, v in row.items() if k not in names} for row in rows]


def _slid(mu: float, g: float, t: float) -> float:
    """Coulomb friction on a block sliding at SPEED: distance after t (it stops at SPEED / (mu g))."""
    stop = SPEED / (mu * g)
    t = min(t, stop)
    return SPEED * t - 0.5 * mu * g * t * t


def block_world(friction: float, gravity: float) -> tumble.World:
    """The sliding block built through the API (a function for the pool to call)."""
    world = tumble.World(gravity=(0.0, 0.0, gravity))
    world.add_static(tumble.Plane(), friction=friction)
    world.add_body(tumble.Box((0.2, 0.2, 0.2)), mass=1.0, position=(0.0, 0.0, 0.1), velocity=(SPEED, 0.0, 0.0),
                   friction=friction, name="block")  # fmt: skip
    return world


def failing_world(friction: float, gravity: float) -> tumble.World:
    """Member friction = 0.7 fails in its build; gravity = 1e308 fails in its simulation (non-finite)."""
    if friction == 0.7:
        raise RuntimeError("no such material")
    return block_world(friction, gravity)


def killing_world(friction: float, gravity: float, marker: str) -> tumble.World:
    """The member of friction 0.6 kills its worker process the first time it runs (``marker`` records that)."""
    if friction == 0.6 and not os.path.exists(marker):
        Path(marker).write_text("killed once")
        os.kill(os.getpid(), signal.SIGKILL)
    return block_world(friction, gravity)


def flaky_world(friction: float, gravity: float, marker: str) -> tumble.World:
    """Fails the first time it is called (``marker`` records that), then builds the block."""
    if not os.path.exists(marker):
        Path(marker).write_text("failed once")
        raise RuntimeError("first try")
    return block_world(friction, gravity)


def travelled(world) -> dict:
    return {"x": float(world.state.body_pos[0, 0]), "vx": float(world.state.body_linvel[0, 0])}


def threads_in_worker(world) -> dict:
    return {"threads": integrate.threads()}


MEMBERS = ensemble.grid({FRICTION: [0.3, 0.6], GRAVITY: [-9.81, -3.71]})

# The ensemble has no kernels of its own: its members step through those the other tests also run as plain Python,
# where these runs would take a minute and a half.
runs_members = compiled_only("members step for minutes as plain Python")


# --- grid and sample ------------------------------------------------------------------------------------------


def test_grid_is_every_combination_first_axis_slowest():
    members = ensemble.grid({"a": [1, 2, 3], "b": np.array([0.5, 1.5])})
    assert members == [{"a": a, "b": b} for a in (1, 2, 3) for b in (0.5, 1.5)]
    assert all(type(m["b"]) is float for m in members)  # NumPy scalars made plain


def test_sample_draws_in_range_and_repeats_for_a_seed():
    one = ensemble.sample(200, seed=3, uniform={"mu": (0.1, 0.9)}, choice={"g": [-9.81, -1.62]})
    assert one == ensemble.sample(200, seed=3, uniform={"mu": (0.1, 0.9)}, choice={"g": [-9.81, -1.62]})
    assert one != ensemble.sample(200, seed=4, uniform={"mu": (0.1, 0.9)}, choice={"g": [-9.81, -1.62]})
    mus = np.array([m["mu"] for m in one])
    assert mus.min() >= 0.1 and mus.max() < 0.9 and mus.std() > 0.15
    assert {m["g"] for m in one} == {-9.81, -1.62}


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: ensemble.grid({}), "non-empty mapping"),
        (lambda: ensemble.grid({"a": []}), r"axes\['a'\]: no values"),
        (lambda: ensemble.grid({"a": 0.5}), "sequence of values"),
        (lambda: ensemble.sample(0, uniform={"a": (0, 1)}), "count must be"),
        (lambda: ensemble.sample(3), "give the names"),
        (lambda: ensemble.sample(3, uniform={"a": (1, 0)}), r"uniform\['a'\]: give \(low, high\)"),
        (lambda: ensemble.sample(3, uniform={"a": (0, 1)}, choice={"a": [1]}), "both as uniform and as choice"),
    ],
)
def test_grid_and_sample_refuse_bad_input(call, match):
    with pytest.raises((ValueError, TypeError), match=match):
        call()


# --- the proofs -----------------------------------------------------------------------------------------------


@runs_members
def test_local_pool_equals_a_serial_loop_and_coulombs_law(tmp_path):
    table = _rows(ensemble.run(BLOCK, MEMBERS, DURATION, DT, tmp_path / "pool", workers=2, summary=travelled))
    assert [row["member"] for row in table] == [0, 1, 2, 3]
    for row, member in zip(table, MEMBERS, strict=True):
        assert row[FRICTION] == member[FRICTION] and row[GRAVITY] == member[GRAVITY]
        assert row["status"] == "done" and row["error"] is None and row["reused"] is False
        # The serial loop: the same scene loaded here and stepped here gives the same bits.
        loaded = scene_file.load(BLOCK, member)
        start = loaded.world.total_energy()
        loaded.world.simulate(DURATION, DT)
        assert row["x"] == loaded.world.state.body_pos[0, 0]
        assert row["energy_change"] == loaded.world.total_energy() - start
        assert row["time"] == pytest.approx(DURATION, abs=1e-12)
        # Coulomb: the block slides v t - mu g t^2 / 2 until it stops at v^2 / (2 mu g) (to 1 mm: the step).
        expected = _slid(member[FRICTION], -member[GRAVITY], DURATION)
        assert row["x"] == pytest.approx(expected, abs=1e-3)
        assert row["max_displacement"] == pytest.approx(expected, abs=1e-3)
        trajectory = Trajectory.load(row["path"])
        assert len(trajectory) == round(DURATION / DT) + 1
        assert trajectory.position[-1, 0, 0] == row["x"]
        assert trajectory.metadata["ensemble"]["request"]["params"] == member
    assert sorted(p.name for p in (tmp_path / "pool").iterdir()) == [
        "member_00000.h5", "member_00001.h5", "member_00002.h5", "member_00003.h5", "results.csv",
    ]  # fmt: skip
    csv = (tmp_path / "pool" / "results.csv").read_text().splitlines()
    assert csv[0].startswith(f"member,{FRICTION},{GRAVITY},status,error,") and len(csv) == 5


@runs_members
def test_coulombs_law_holds_at_every_step_size_to_the_first_substeps_slide(tmp_path):
    """The step is one more place to sweep: at 60 Hz, 240 Hz and 1 kHz (8 substeps each) the block lands within
    v h / 2 of Coulomb's distance, h the substep (friction takes hold over the first substep), and closer in
    proportion to the step."""
    members = ensemble.grid({"world.dt": [1 / 60, 1 / 240, 1 / 1000], FRICTION: [0.3, 0.6], GRAVITY: [-9.81, -3.71]})
    table = _rows(ensemble.run(BLOCK, members, DURATION, None, tmp_path, executor=ThreadPoolExecutor(2)))
    worst = {}
    for row in table:
        dt = row["world.dt"]
        error = abs(row["max_displacement"] - _slid(row[FRICTION], -row[GRAVITY], DURATION))
        assert error <= SPEED * (dt / 8) / 2 + 1e-5, (row, error)
        worst[dt] = max(worst.get(dt, 0.0), error)
    assert worst[1 / 240] < worst[1 / 60] / 3.5 and worst[1 / 1000] < worst[1 / 240] / 3.5  # first order


@runs_members
def test_a_function_building_worlds_runs_as_the_same_scene(tmp_path):
    members = [{"friction": m[FRICTION], "gravity": m[GRAVITY]} for m in MEMBERS]
    table = _rows(ensemble.run(block_world, members, DURATION, DT, tmp_path, workers=1, record_every=4,
                               summary=threads_in_worker))  # fmt: skip
    assert all(row["threads"] == 1 for row in table)  # the pool's workers share the cores: one thread each
    for row, member in zip(table, MEMBERS, strict=True):
        assert row["max_displacement"] == pytest.approx(_slid(member[FRICTION], -member[GRAVITY], DURATION), abs=1e-3)
        assert len(Trajectory.load(row["path"])) == 61  # 240 steps, one frame in 4, and the first


@runs_members
def test_any_executor_gives_the_same_table(tmp_path):
    pool = _rows(ensemble.run(BLOCK, MEMBERS, DURATION, DT, tmp_path / "a", workers=2))
    before = integrate.threads()
    with ThreadPoolExecutor(max_workers=2) as threads:
        threaded = _rows(ensemble.run(BLOCK, MEMBERS, DURATION, DT, tmp_path / "b", executor=threads))
    assert integrate.threads() == before  # this process's setting is its own
    assert _without(pool, "wall_s", "path") == _without(threaded, "wall_s", "path")


@runs_members
def test_a_rerun_runs_only_the_members_not_finished(tmp_path):
    first = _rows(ensemble.run(BLOCK, MEMBERS, DURATION, DT, tmp_path, executor=ThreadPoolExecutor(1)))
    member_path(tmp_path, 2).unlink()
    again = _rows(ensemble.run(BLOCK, MEMBERS, DURATION, DT, tmp_path, executor=ThreadPoolExecutor(1)))
    assert [row["reused"] for row in again] == [True, True, False, True]
    assert _without(first, "wall_s", "reused") == _without(again, "wall_s", "reused")


@runs_members
def test_a_failing_member_is_reported_and_costs_no_other(tmp_path):
    members = [{"friction": 0.3, "gravity": -9.81}, {"friction": 0.7, "gravity": -9.81},
               {"friction": 0.5, "gravity": -1e308}, {"friction": 0.5, "gravity": -9.81}]  # fmt: skip
    table = _rows(ensemble.run(failing_world, members, DURATION, DT, tmp_path, executor=ThreadPoolExecutor(2)))
    assert [row["status"] for row in table] == ["done", "failed", "failed", "done"]
    assert table[1]["error"] == "RuntimeError: no such material" and table[1]["path"] is None
    report = (tmp_path / "member_00001.failed.txt").read_text()
    assert report.startswith("member 1, parameters {'friction': 0.7") and "Traceback" in report
    assert 'raise RuntimeError("no such material")' in report
    assert table[2]["error"].startswith("SimulationError: ") and "non-finite" in table[2]["error"]
    assert table[2]["path"] == str(member_path(tmp_path, 2, "failed"))
    failed = Trajectory.load(table[2]["path"])
    assert failed.metadata["status"] == "failed" and failed.metadata["ensemble"]["status"] == "failed"
    assert table[1]["max_displacement"] is None
    assert table[3]["max_displacement"] == pytest.approx(_slid(0.5, 9.81, DURATION), abs=1e-3)
    # A rerun runs the failed ones again (and they fail again), and reuses the rest.
    again = _rows(ensemble.run(failing_world, members, DURATION, DT, tmp_path, executor=ThreadPoolExecutor(2)))
    assert [row["reused"] for row in again] == [True, False, False, True]
    assert [row["status"] for row in again] == ["done", "failed", "failed", "done"]


@runs_members
def test_a_killed_worker_loses_no_finished_member_and_a_rerun_completes(tmp_path):
    marker = str(tmp_path / "killed")
    members = [{"friction": mu, "gravity": -9.81, "marker": marker} for mu in (0.3, 0.4, 0.5, 0.6, 0.7, 0.8)]
    out = tmp_path / "out"
    table = _rows(ensemble.run(killing_world, members, DURATION, DT, out, workers=1))
    assert os.path.exists(marker)
    done = [row["member"] for row in table if row["status"] == "done"]
    assert done == [0, 1, 2]  # one worker: the members before the kill finished
    lost = [row for row in table if row["status"] == "failed"]
    assert lost and all("its worker was lost" in row["error"] for row in lost)
    for k in done:
        assert Trajectory.load(member_path(out, k)).metadata["status"] == "complete"
    assert not member_path(out, 3).exists()  # the killed member left at most its partial file
    again = _rows(ensemble.run(killing_world, members, DURATION, DT, out, workers=2))
    assert [row["status"] for row in again] == ["done"] * 6
    assert [row["reused"] for row in again] == [True, True, True, False, False, False]
    for row, member in zip(again, members, strict=True):
        assert row["max_displacement"] == pytest.approx(_slid(member["friction"], 9.81, DURATION), abs=1e-3)


@runs_members
def test_a_member_that_succeeds_on_a_rerun_leaves_no_failure_behind(tmp_path):
    members = [{"friction": 0.5, "gravity": -9.81, "marker": str(tmp_path / "marker")}]
    first = _rows(ensemble.run(flaky_world, members, DURATION, DT, tmp_path, executor=ThreadPoolExecutor(1)))
    assert first[0]["error"] == "RuntimeError: first try" and (tmp_path / "member_00000.failed.txt").exists()
    again = _rows(ensemble.run(flaky_world, members, DURATION, DT, tmp_path, executor=ThreadPoolExecutor(1)))
    assert again[0]["status"] == "done" and again[0]["error"] is None
    assert sorted(p.name for p in tmp_path.iterdir()) == ["marker", "member_00000.h5", "results.csv"]


@runs_members
def test_nothing_half_written_is_taken_as_finished(tmp_path):
    ensemble.run(BLOCK, MEMBERS[:1], DURATION, DT, tmp_path, executor=ThreadPoolExecutor(1))
    whole = member_path(tmp_path, 0)
    # A partial file under the finished name of member 1 (status "running"), a damaged one for member 2, and a
    # partial file of member 3 as a killed worker leaves it.
    partial = member_path(tmp_path, 1)
    writer = tumble.recording.TrajectoryWriter(partial, block_world(0.5, -9.81))
    writer.flush()
    writer._h5.close()
    member_path(tmp_path, 2).write_bytes(whole.read_bytes()[:2000])
    member_path(tmp_path, 3, "partial").write_bytes(b"")
    table = _rows(ensemble.run(BLOCK, MEMBERS, DURATION, DT, tmp_path, executor=ThreadPoolExecutor(1)))
    assert [row["reused"] for row in table] == [True, False, False, False]
    assert all(row["status"] == "done" for row in table)
    assert all(Trajectory.load(row["path"]).metadata["status"] == "complete" for row in table)


def test_the_progress_bar_shows_members_done_and_failed_and_the_time_left():
    from rich.console import Console

    console = Console(file=io.StringIO(), force_terminal=True, width=120, record=True)
    with ensemble.runner._ProgressBar(4, 1, True, console=console) as bar:
        bar.advance(True)
        time.sleep(0.1)
        bar.advance(False)
        bar._bar.refresh()
        text = console.export_text(clear=False)
    assert "2 done, 1 failed of 4 (1 from an earlier run)" in text
    assert re.search(r"of 4 \(1 from an earlier run\) \d+:\d\d:\d\d", text), text  # the time left, once rates exist
    assert (bar.done, bar.failed) == (2, 1)


# --- bad input ------------------------------------------------------------------------------------------------


def test_unknown_places_are_refused_before_anything_runs(tmp_path):
    with pytest.raises(ValueError, match=r"params\[0\]: sliding_block.toml: materials.surface.frictoin: unknown key"):
        ensemble.run(BLOCK, [{"materials.surface.frictoin": 0.2}], out_dir=tmp_path)
    with pytest.raises(ValueError, match=r"params\[1\]: .*bodies\[3\] is past the end \(bodies has 1 item\)"):
        ensemble.run(BLOCK, [{FRICTION: 0.2}, {"bodies[3].mass": 2.0}], out_dir=tmp_path)
    with pytest.raises(ValueError, match=r"params\[0\]: .*Input should be greater than or equal to 0"):
        ensemble.run(BLOCK, [{FRICTION: -0.2}], out_dir=tmp_path)
    assert list(tmp_path.iterdir()) == []


def test_an_unwritable_out_dir_is_named(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("")
    with pytest.raises(ValueError, match=r"out_dir '.*file/sweep': cannot write there: Not a directory"):
        ensemble.run(BLOCK, MEMBERS, out_dir=blocker / "sweep")
    with pytest.raises(ValueError, match="out_dir: give the folder"):
        ensemble.run(BLOCK, MEMBERS)


def test_an_unreachable_scheduler_is_named(tmp_path, monkeypatch):
    pytest.importorskip("distributed")
    monkeypatch.setattr(executors, "CONNECT_TIMEOUT", 0.5)
    with pytest.raises(ValueError, match=r"executor: cannot reach the Dask scheduler at 'tcp://127.0.0.1:1'"):
        ensemble.run(BLOCK, MEMBERS, out_dir=tmp_path, executor="tcp://127.0.0.1:1")


@runs_members
def test_another_runs_files_are_not_mixed_in(tmp_path):
    ensemble.run(BLOCK, MEMBERS[:1], DURATION, DT, tmp_path, executor=ThreadPoolExecutor(1))
    with pytest.raises(ValueError, match=r"holds member_00000.h5 of another run"):
        ensemble.run(BLOCK, MEMBERS[1:2], DURATION, DT, tmp_path, executor=ThreadPoolExecutor(1))
    with pytest.raises(ValueError, match=r"holds member_00000.h5 of another run"):
        ensemble.run(BLOCK, MEMBERS[:1], DURATION / 2, DT, tmp_path, executor=ThreadPoolExecutor(1))


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"params": {"a": 1}}, TypeError, "params must be a list of dicts"),
        ({"params": []}, ValueError, "no members"),
        ({"params": [3]}, TypeError, r"params\[0\] must be a dict"),
        ({"params": [{"status": 1}]}, ValueError, r"'status' is a column of the results table"),
        ({"params": [{"a": object()}]}, TypeError, r"params\[0\]\['a'\] must be a number"),
        ({"build": 3}, TypeError, "build must be a callable"),
        ({"build": "no_such_scene"}, ValueError, "build: no scene file at 'no_such_scene'"),
        ({"build": block_world, "duration": None}, ValueError, "duration and dt: give both"),
        ({"build": lambda friction, gravity: None}, ValueError, "build: the local process pool .* cannot be pickled"),
        ({"duration": -1.0}, ValueError, "duration"),
        ({"record_every": 0}, ValueError, "record_every"),
        ({"workers": 0}, ValueError, "workers"),
        ({"workers": 2, "executor": ThreadPoolExecutor(1)}, ValueError, "workers=2 sizes the local process pool"),
        ({"executor": 3}, TypeError, "executor must be None"),
        ({"summary": 3}, TypeError, "summary must be a function"),
    ],
)
def test_bad_arguments_are_named(tmp_path, kwargs, error, match):
    arguments = {"build": BLOCK, "params": [{FRICTION: 0.3}], "duration": DURATION, "dt": DT, "out_dir": tmp_path}
    if callable(kwargs.get("build")):
        arguments["params"] = [{"friction": 0.3, "gravity": -9.81}]
    arguments.update(kwargs)
    out = tmp_path / "out"
    arguments["out_dir"] = out
    with pytest.raises(error, match=match):
        ensemble.run(**arguments)
    assert not out.exists()  # refused before anything is made


@runs_members
def test_a_summary_that_fails_fails_its_member_only(tmp_path):
    def bad(world):
        return [1.0]

    members = MEMBERS[:2]
    table = _rows(ensemble.run(BLOCK, members, DURATION, DT, tmp_path, executor=ThreadPoolExecutor(1), summary=bad))
    assert all(row["status"] == "failed" for row in table)
    assert table[0]["error"].startswith("TypeError: summary must return a dict")


@runs_members
def test_without_pandas_the_table_is_a_list_of_dicts(tmp_path, monkeypatch):
    monkeypatch.setitem(__import__("sys").modules, "pandas", None)  # import pandas raises ImportError
    table = ensemble.run(BLOCK, MEMBERS[:2], DURATION, DT, tmp_path, executor=ThreadPoolExecutor(1))
    assert isinstance(table, list) and [row["member"] for row in table] == [0, 1]
    assert table[1][FRICTION] == 0.3 and table[1][GRAVITY] == -3.71 and table[1]["status"] == "done"
