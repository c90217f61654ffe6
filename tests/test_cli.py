"""The ``tumble`` command, run as a user runs it: ``python -m tumble ...`` in a subprocess (docs/cli.md).

Each subprocess pays for ``import tumble`` and for loading the compiled kernels from Numba's disk cache (about a
second when warm), so the runs are short and shared between tests through module fixtures.
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import tumble
from tumble import scene_file
from tumble.trajectory import Trajectory
from tumble.viewer.page import read_page_data

REPO = Path(__file__).resolve().parents[1]

SMALL_SCENE = """\
description = "Three shapes on the ground and a hinged pendulum (the CLI tests' scene)."

[world]
dt = 0.016666666666666666
duration = 2.0

[[static]]
name = "ground"
shape = { type = "plane" }

[[bodies]]
name = "ball"
shape = { type = "sphere", radius = 0.1 }
density = 1000.0
position = [0.0, 0.0, 1.0]

[[bodies]]
name = "crate"
shape = { type = "box", extents = [0.2, 0.3, 0.4] }
density = 500.0
position = [0.5, 0.0, 1.0]

[[bodies]]
name = "bob"
shape = { type = "capsule", radius = 0.05, length = 0.2 }
mass = 1.0
position = [2.0, 0.0, 2.0]

[[joints]]
type = "hinge"
a = "bob"
anchor = [1.5, 0.0, 2.0]
axis = [0.0, 1.0, 0.0]
"""

# A box spun at 1e150 rad/s: it falls for 25 steps, and the step in which it lands overflows.
SPINNER_SCENE = """\
[world]
duration = 2.0

[[static]]
name = "ground"
shape = { type = "plane" }

[[bodies]]
name = "spinner"
shape = { type = "box", extents = [0.2, 0.2, 0.2] }
density = 1000.0
position = [0.0, 0.0, 1.0]
angular_velocity = [1e150, 0.0, 0.0]
"""


def tumble_cli(*args, cwd=None, timeout=300, env=None) -> subprocess.CompletedProcess:
    """``python -m tumble ARGS`` in a fresh process; stdout and stderr as text."""
    environment = {k: v for k, v in os.environ.items() if k not in ("FORCE_COLOR", "COLUMNS")}
    environment.update(env or {})
    return subprocess.run(
        [sys.executable, "-m", "tumble", *map(str, args)],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=timeout,
        env=environment,
    )


@pytest.fixture
def tumble_here(capsys):
    """``tumble ARGS`` called in this process (``cli.main``, argparse's exit caught), for the refusals: the status
    and what it prints, as :func:`tumble_cli` gives them, without the 1.5 s start of a fresh process (an uncaught
    error fails the test). Every command also runs in a fresh process in a test of its own."""
    from tumble import cli

    def call(*args) -> subprocess.CompletedProcess:
        capsys.readouterr()
        try:
            status = cli.main([str(arg) for arg in args])
        except SystemExit as exit:
            status = exit.code
        out, err = capsys.readouterr()
        return subprocess.CompletedProcess(args, status, out, err)

    return call


def assert_clean_failure(result, status: int, *fragments: str) -> None:
    """Exit status ``status``, each fragment in stderr, and no traceback."""
    assert result.returncode == status, (result.returncode, result.stdout, result.stderr)
    assert "Traceback" not in result.stderr, result.stderr
    for fragment in fragments:
        assert fragment in result.stderr, (fragment, result.stderr)


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("cli")
    (path / "small.toml").write_text(SMALL_SCENE)
    (path / "spinner.toml").write_text(SPINNER_SCENE)
    return path


@pytest.fixture(scope="module")
def flagship_run(folder) -> dict:
    """The shipped flagship scene run for 0.5 s with every output."""
    out = {"h5": folder / "run" / "flagship.h5", "html": folder / "run" / "replay.html", "png": folder / "energy.png"}
    result = tumble_cli("run", "flagship", "--duration", "0.5", "--out", out["h5"], "--html", out["html"],
                        "--plot", out["png"], "--quiet")  # fmt: skip
    return {"result": result, **out}


def test_version():
    result = tumble_cli("--version")
    assert result.returncode == 0
    assert result.stdout.startswith(f"tumble {tumble.__version__} ")


def test_run_writes_trajectory_replay_and_plot(flagship_run):
    result = flagship_run["result"]
    assert result.returncode == 0, result.stderr
    assert "Traceback" not in result.stderr
    for row in ("simulated time", "steps", "steps/s", "real-time factor", "energy drift", "contacts", "sleeping"):
        assert row in result.stdout, result.stdout
    assert "30 " in result.stdout  # 0.5 s at dt = 1/60
    # The digest row is the run's final state, as the same steps give it in this process.
    loaded = scene_file.load(scene_file.shipped_scene("flagship"))
    loaded.world.simulate(0.5, loaded.run.dt)
    assert re.search(rf"state digest\W+{loaded.world.state.digest()[:16]}\W", result.stdout), result.stdout

    trajectory = Trajectory.load(flagship_run["h5"])
    assert len(trajectory) == 31 and trajectory.time[-1] == pytest.approx(0.5)
    assert trajectory.metadata["status"] == "complete"
    scene = trajectory.metadata["scene"]
    assert scene["file"] == "flagship.toml" and "wrecking_ball" in json.dumps(scene["source"])
    assert "wrecking_ball" in trajectory.body_names

    data = read_page_data(flagship_run["html"].read_text(encoding="utf-8"))
    assert data["bodyCount"] == trajectory.body_count and data["frameCount"] == 31
    assert {"mesh", "hull", "sphere", "box", "capsule", "cylinder"} <= {s["kind"] for s in data["shapes"]}
    assert flagship_run["png"].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_view_rebuilds_the_shapes_from_the_recorded_scene(flagship_run, folder):
    page = folder / "view" / "replay.html"
    result = tumble_cli("view", flagship_run["h5"], "-o", page, "--max-frames", "10")
    assert result.returncode == 0, result.stderr
    assert "balls" not in result.stderr  # the shapes came from the scene stored in the file
    data = read_page_data(page.read_text(encoding="utf-8"))
    assert data["frameCount"] == 10 and "mesh" in {s["kind"] for s in data["shapes"]}

    # Another scene's shapes do not fit: bad input, said in one line.
    result = tumble_cli("view", flagship_run["h5"], "-o", page, "--scene", folder / "small.toml")
    assert_clean_failure(result, 2, "small.toml has 4 bodies but the trajectory has 103")


def test_view_without_a_scene_draws_balls(folder):
    world = scene_file.load(folder / "small.toml").world
    world.simulate(0.1, 1 / 60).save(folder / "plain.npz")  # no scene in its metadata
    page = folder / "plain.html"
    result = tumble_cli("view", folder / "plain.npz", "-o", page)
    assert result.returncode == 0, result.stderr
    assert "drawn as balls" in result.stderr and "--scene" in result.stderr
    assert {s["kind"] for s in read_page_data(page.read_text(encoding="utf-8"))["shapes"]} == {"sphere"}
    result = tumble_cli("view", folder / "plain.npz", "-o", page, "--scene", folder / "small.toml")
    assert result.returncode == 0, result.stderr
    data = read_page_data(page.read_text(encoding="utf-8"))
    assert {s["kind"] for s in data["shapes"]} == {"sphere", "box", "capsule"} and len(data["planes"]) == 1


def test_plot(flagship_run, folder, tumble_here):
    out = folder / "plots"
    result = tumble_cli("plot", flagship_run["h5"], "--what", "energy,momentum,omega,paths", "-o", out,
                        "--bodies", "wrecking_ball,link9")  # fmt: skip
    assert result.returncode == 0, result.stderr
    for what in ("energy", "momentum", "omega", "paths"):
        assert (out / f"flagship_{what}.png").read_bytes()[:4] == b"\x89PNG"
    single = folder / "one.svg"
    assert tumble_cli("plot", flagship_run["h5"], "-o", single).returncode == 0
    assert single.read_text().lstrip().startswith("<?xml")

    assert_clean_failure(tumble_here("plot", flagship_run["h5"], "--what", "energy,spin"), 2, "--what")
    assert_clean_failure(tumble_here("plot", flagship_run["h5"], "--what", "omega", "--bodies", "nobody", "-o", out),
                         2, "nobody")  # fmt: skip


def test_info_lists_bodies_joints_and_settings(folder):
    result = tumble_cli("info", folder / "small.toml")
    assert result.returncode == 0, result.stderr
    out = result.stdout
    for text in ("Three shapes on the ground", "ground", "static", "ball", "crate", "bob", "dynamic", "hinge",
                 "world", "integrator", "substeps", "0.0166667"):  # fmt: skip
        assert text in out, (text, out)
    # The crate: 0.2 x 0.3 x 0.4 m of 500 kg/m³ = 12 kg; principal moments m (b² + c²) / 12 ascending.
    crate = next(line for line in out.splitlines() if " crate " in line)
    assert " 12 " in crate and "(0.13, 0.2, 0.25)" in crate
    assert re.search(r"[+-]z, [+-]y, [+-]x", crate), crate  # the principal axes of those moments: z, y, x


def test_examples_lists_and_copies(tmp_path, tumble_here):
    result = tumble_cli("examples")
    assert result.returncode == 0, result.stderr
    shipped = scene_file.shipped()
    assert any(p.name == "flagship.toml" for p in shipped)
    for path in shipped:
        assert path.name in result.stdout
    words = " ".join(re.sub(r"[│┃]", " ", result.stdout).split())  # the table wraps long descriptions
    assert "wrecking ball" in words

    result = tumble_here("examples", "--copy", tmp_path / "scenes")
    assert result.returncode == 0, result.stderr
    assert sorted(p.name for p in (tmp_path / "scenes").glob("*.toml")) == sorted(p.name for p in shipped)
    assert len(scene_file.load(tmp_path / "scenes" / "flagship.toml").world.bodies) == 103
    again = tumble_here("examples", "--copy", tmp_path / "scenes")  # existing files are kept unless --force
    assert again.returncode == 0 and "kept existing" in again.stderr


BAD_SCENES = {
    # name: (file text, what stderr must name besides the file)
    "syntax": ('[world]\ndt = 0.01\n[[bodies]\nname = "x"\n', "line 3"),
    "wrong_type": (
        '[[bodies]]\nname = "x"\nshape = { type = "sphere", radius = "big" }\nmass = 1.0\n',
        "bodies[0].shape.radius",
    ),  # fmt: skip
    "unknown_key": (
        '[[bodies]]\nname = "x"\nshape = { type = "sphere", radius = 0.1 }\nmass = 1.0\ncolour = "red"\n',
        "bodies[0].colour",
    ),  # fmt: skip
    "negative_mass": (
        '[[bodies]]\nname = "x"\nshape = { type = "sphere", radius = 0.1 }\nmass = -1.0\n',
        "bodies[0].mass",
    ),  # fmt: skip
    "missing_mesh": (
        '[[static]]\nname = "rock"\nshape = { type = "mesh", path = "meshes/rock.stl" }\n',
        "static[0].shape.path",
    ),  # fmt: skip
}


@pytest.mark.parametrize("case", sorted(BAD_SCENES))
def test_bad_scene_is_exit_2_with_file_and_place(case, tmp_path, tumble_here):
    text, place = BAD_SCENES[case]
    path = tmp_path / f"{case}.toml"
    path.write_text(text)
    command = "info" if case in ("syntax", "unknown_key") else "run"
    assert_clean_failure(tumble_here(command, path, "--quiet") if command == "run" else tumble_here(command, path),
                         2, f"{case}.toml", place)  # fmt: skip


def test_bad_arguments_are_exit_2(folder, tmp_path, tumble_here):
    # Two in fresh processes: argparse's refusal and one of tumble's own, as a user's shell sees them.
    assert_clean_failure(tumble_cli("run", tmp_path / "nowhere.toml"), 2, "nowhere.toml", "no such scene file")
    assert_clean_failure(tumble_cli("frobnicate"), 2, "invalid choice")
    assert_clean_failure(tumble_here("frobnicate"), 2, "invalid choice")
    assert_clean_failure(tumble_here("run", folder / "small.toml", "--dt", "-1"), 2, "--dt", "-1")
    assert_clean_failure(tumble_here("run", folder / "small.toml", "--out", tmp_path / "x.csv"), 2, ".h5", ".npz")
    assert_clean_failure(tumble_here("run", folder / "small.toml", "--plot", tmp_path / "e.xyz"), 2, "--plot")
    assert_clean_failure(tumble_here("view", tmp_path / "none.h5", "-o", tmp_path / "r.html"), 2, "none.h5")
    assert not list(tmp_path.iterdir())  # nothing was written
    (folder / "garbage.npz").write_bytes(b"PK\x03\x04 not a zip")
    assert_clean_failure(tumble_here("plot", folder / "garbage.npz"), 2, "garbage.npz", "cannot read")


def test_simulation_error_is_exit_1_and_keeps_what_was_recorded(folder):
    out, page, png = folder / "fail" / "spin.h5", folder / "fail" / "spin.html", folder / "fail" / "spin.png"
    result = tumble_cli("run", folder / "spinner.toml", "--out", out, "--html", page, "--plot", png, "--quiet")
    assert_clean_failure(result, 1, "simulation failed", "'spinner'", "step 25")
    assert "FAILED" in result.stdout
    trajectory = Trajectory.load(out)  # the steps before the failing one, in a readable file
    assert len(trajectory) == 26 and trajectory.metadata["status"] == "failed"
    assert "spinner" in trajectory.metadata["error"]
    assert read_page_data(page.read_text(encoding="utf-8"))["frameCount"] == 26
    assert png.stat().st_size > 1000


def test_progress_bar_through_the_recorder_callback(folder, tmp_path):
    result = tumble_cli("run", folder / "small.toml", "--duration", "1.0", "--out", tmp_path / "s.npz",
                        env={"FORCE_COLOR": "1", "COLUMNS": "120"})  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert "simulating" in result.stderr  # the bar was drawn
    trajectory = Trajectory.load(tmp_path / "s.npz")
    assert len(trajectory) == 61 and trajectory.metadata["status"] == "complete"


def signal_when(command: list[str], ready, stop: str) -> tuple[int, str, str]:
    """Start ``command``, send it the signal ``stop`` once ``ready()`` (or it ended, or 300 s passed: a cold Numba
    cache compiles first), and give its exit status, stdout and stderr."""
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 300
        while not ready() and time.monotonic() < deadline and process.poll() is None:
            time.sleep(0.05)
        process.send_signal(getattr(signal, stop))
        stdout, stderr = process.communicate(timeout=60)
    finally:
        if process.poll() is None:
            process.kill()
    return process.returncode, stdout, stderr


def out_size(path: Path) -> int:
    return path.stat().st_size if path.exists() else 0


@pytest.mark.skipif(not hasattr(signal, "SIGTERM") or sys.platform == "win32", reason="needs POSIX signals")
@pytest.mark.parametrize(("stop", "status", "said"), [("SIGINT", 130, "interrupted at t"),
                                                      ("SIGTERM", 143, "terminated (SIGTERM) at t")])  # fmt: skip
def test_a_signal_stops_the_run_and_keeps_the_file_readable(folder, stop, status, said):
    out = folder / f"interrupted_{stop}.h5"  # a file of its own: the other case's would exist from the start
    command = [sys.executable, "-m", "tumble", "run", str(folder / "small.toml"), "--out", str(out),
               "--dt", "1e-4", "--duration", "1000", "--quiet"]  # fmt: skip
    # HDF5's own structures are about 12 kB; the first chunk (2048 frames of three bodies) brings it to about
    # 900 kB. Waiting for a growth and a second after it found 1 frame where starting up took over a second;
    # waiting for 100 kB found none, once in a few runs (the file grows before the chunk's frames count).
    returncode, stdout, stderr = signal_when(command, lambda: out_size(out) >= 600_000, stop)
    assert returncode == status, (stdout, stderr)
    assert said in stderr and "status 'interrupted'" in stderr and "Traceback" not in stderr
    trajectory = Trajectory.load(out)
    assert trajectory.metadata["status"] == "interrupted"
    assert 1 < len(trajectory) and trajectory.time[-1] < 1000


def test_bench_reaches_the_repository_benchmarks():
    # An unknown benchmark name is refused by benchmarks/run.py itself: proof that it was found and imported.
    result = tumble_cli("bench", "--only", "no_such_benchmark", cwd=REPO)
    assert result.returncode == 2
    assert "no_such_benchmark" in result.stderr and "Traceback" not in result.stderr


def test_main_in_process_and_bench_outside_a_checkout(monkeypatch, capsys):
    from tumble import cli

    monkeypatch.setattr(cli, "_find_benchmarks", lambda: None)
    assert cli.main(["bench", "--quick"]) == 2
    assert "benchmarks live in the repository" in capsys.readouterr().err
    assert cli.main([]) == 2  # no command: the help, and the status of bad input
    assert "COMMAND" in capsys.readouterr().out


def test_a_ctrl_c_that_python_drops_is_raised_again_at_the_next_chunk():
    """Python drops a KeyboardInterrupt raised inside a weakref callback or __del__ ("Exception ignored in ..."):
    a run went on for its whole duration when Ctrl-C landed in one; inside Numba's ``_numba_unpickle`` it ended the
    run with a SystemError and status 1. The latch raises it after the chunk."""
    from tumble.cli import _InterruptLatch

    with _InterruptLatch() as latch:
        latch.check()  # nothing asked yet
        with pytest.raises(KeyboardInterrupt):  # at once where Python can raise it
            latch._handle(signal.SIGINT, sys._getframe())
        with pytest.raises(KeyboardInterrupt):
            latch.check()
    with _InterruptLatch() as latch:

        class Finalised:
            def __del__(self):
                latch._handle(signal.SIGINT, sys._getframe())  # in a finaliser: latched, not raised

        Finalised()
        with pytest.raises(KeyboardInterrupt):
            latch.check()
    with _InterruptLatch() as latch:

        def _numba_unpickle():  # Numba's, called from compiled code: raised there, it ends the run as a SystemError
            def rebuild():
                latch._handle(signal.SIGTERM, sys._getframe())  # latched, not raised

            rebuild()

        try:
            _numba_unpickle()
        except KeyboardInterrupt:  # (not left to escape: pytest would stop the whole session)
            pytest.fail("the latch raised inside _numba_unpickle")
        with pytest.raises(KeyboardInterrupt) as caught:
            latch.check()
        assert type(caught.value).__name__ == "_Terminated"
    with _InterruptLatch() as latch:
        with pytest.raises(KeyboardInterrupt) as caught:
            latch._handle(signal.SIGTERM, sys._getframe())
        assert type(caught.value).__name__ == "_Terminated"
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL


def test_info_lists_the_first_rows_of_a_big_scene_and_all_with_all(tmp_path, tumble_here):
    parts = ["[world]\n"]
    parts += [f'[[bodies]]\nname = "b{i}"\nshape = {{ type = "sphere", radius = 0.1 }}\nmass = 1.0\n'
              f"position = [{0.5 * i}, 0, 1]\n" for i in range(130)]  # fmt: skip
    parts += [
        f'[[joints]]\ntype = "ball"\na = "b{i}"\nb = "b{i + 1}"\nanchor = [{0.5 * i + 0.25}, 0, 1]\n'
        for i in range(120)
    ]
    scene = tmp_path / "many.toml"
    scene.write_text("\n".join(parts))
    short = tumble_here("info", scene)
    assert short.returncode == 0, short.stderr
    bodies_table = short.stdout.split("joints (")[0]
    assert " b99 " in bodies_table and " b100 " not in bodies_table
    assert "... and 30 more bodies (tumble info --all" in short.stdout
    assert "... and 20 more joints" in short.stdout
    full = tumble_here("info", scene, "--all")
    assert full.returncode == 0, full.stderr
    assert " b129 " in full.stdout and "more bodies" not in full.stdout and "more joints" not in full.stdout


def test_the_bar_says_that_kernels_compile_until_the_first_chunk():
    from io import StringIO

    from numba.core import event
    from rich.console import Console

    from tumble import cli

    world = tumble.World()
    world.add_body(tumble.Sphere(0.1), mass=1.0)
    world.step(0.01)  # its kernels loaded (or compiled, where this process has no cache) before the bar counts
    progress = cli._Progress(Console(file=StringIO(), force_terminal=True, width=160), 100, 0, 1.0, enabled=True)
    stage = lambda: progress._bar.tasks[0].fields["stage"]  # noqa: E731
    with progress:
        assert stage() == "simulating"
        for _ in range(3):
            with event.trigger_event("numba:compile", data={"dispatcher": None, "args": (), "return_type": None}):
                pass
        assert stage() == "compiling kernels (first run only)… 3 functions"
        world.step(0.01)
        progress(world, None)  # the first chunk is done: simulating
        assert stage() == "simulating" and progress.compiled == 3
    with event.trigger_event("numba:compile", data={"dispatcher": None, "args": (), "return_type": None}):
        pass
    assert progress.compiled == 3  # the listener went with the bar


def test_warmup_steps_every_scene_and_reports_failures(tmp_path, monkeypatch, capsys):
    from tumble import cli, scene_file, warmup

    shipped = {p.stem: p for p in scene_file.shipped()}
    broken = tmp_path / "broken.toml"
    broken.write_text("[world]\ngravity = [0, 0]\n")
    results = warmup.warmup(2, scenes=[shipped["pendulum"], broken, shipped["flagship"]])
    assert sorted(r.name for r in results if r.error is None) == ["flagship", "pendulum"]
    (failed,) = [r for r in results if r.error is not None]
    assert failed.name == "broken" and "gravity" in failed.error
    # One process steps the broken scene and then the pendulum: a scene's failure does not stop the next.
    results = warmup.warmup(1, scenes=[shipped["pendulum"], broken, shipped["dzhanibekov"]])
    assert [(r.name, r.error is None) for r in results] == [("dzhanibekov", 1), ("broken", 0), ("pendulum", 1)]
    monkeypatch.setattr(scene_file, "shipped", lambda: [shipped["pendulum"], shipped["dzhanibekov"]])
    assert cli.main(["warmup", "--jobs", "1"]) == cli.EXIT_OK
    err = capsys.readouterr().err
    assert "3 of 3 warmed (the scenes and the articulation kernels)" in err and "1 process at a time" in err
    assert "warmed articulation kernels (1/3" in err  # first, in a process of its own
    with pytest.raises(ValueError, match="jobs must be an integer >= 1, got 0"):
        warmup.warmup(0)
    with pytest.raises(SystemExit) as exit_info:  # argparse refuses it, with the status of bad input
        cli.main(["warmup", "--jobs", "0"])
    assert exit_info.value.code == cli.EXIT_BAD_INPUT


def test_warmup_runs_the_scenes_with_kernels_of_their_own_alone_first_and_deals_out_the_rest():
    from tumble import scene_file, warmup

    scenes = list(scene_file.shipped())
    batches = warmup._batches(scenes, 2)
    assert [b[0].stem for b in batches[: len(warmup.FIRST)]] == list(warmup.FIRST)
    assert all(len(b) == 1 for b in batches[: len(warmup.FIRST)])
    rest = batches[len(warmup.FIRST) :]
    assert len(rest) == 2 and abs(len(rest[0]) - len(rest[1])) <= 1
    assert sorted(p for b in batches for p in b) == sorted(scenes)
    assert warmup._batches(scenes[:1], 4) == [scenes[:1]]


# --- tumble batch ---------------------------------------------------------------------------------------------


def test_batch_steps_copies_of_a_scene_and_reports_body_steps_per_second(folder):
    result = tumble_cli("batch", folder / "small.toml", "-n", "16", "--duration", "0.5", "--quiet")
    assert result.returncode == 0, result.stderr
    assert "16 copies, done" in result.stdout and "body-steps/s" in result.stdout
    assert re.search(r"steps\s+.\s+30\s", result.stdout), result.stdout  # 0.5 s at the scene's 60 Hz
    assert re.search(r"3 dynamic bodies each", result.stdout), result.stdout


BLOCK = scene_file.shipped_scene("sliding_block")


def test_sweep_runs_a_grid_writes_the_table_and_resumes(tmp_path):
    out = tmp_path / "sweep"
    args = ("sweep", BLOCK, "--param", "materials.surface.friction=0.3:0.6:2", "-p", "world.gravity[2]=-9.81,-3.71",
            "--duration", "0.5", "--workers", "2", "--out", out, "--quiet")  # fmt: skip
    result = tumble_cli(*args)
    assert result.returncode == 0, result.stderr
    assert "4 members, 4 done, 0 failed" in result.stdout and "every row in" in result.stdout
    rows = (out / "results.csv").read_text().splitlines()
    assert rows[0].startswith("member,materials.surface.friction,world.gravity[2],status,error,time,")
    assert [row.split(",")[:4] for row in rows[1:]] == [
        ["0", "0.3", "-9.81", "done"], ["1", "0.3", "-3.71", "done"], ["2", "0.6", "-9.81", "done"],
        ["3", "0.6", "-3.71", "done"],
    ]  # fmt: skip
    trajectory = Trajectory.load(out / "member_00002.h5")
    assert trajectory.metadata["scene"]["materials"]["surface"]["friction"] == 0.6  # the member's scene, stored
    # Coulomb: after 0.5 s at mu = 0.6 and g = 9.81 the block has stopped, 2^2 / (2 mu g) from its start.
    assert trajectory.position[-1, 0, 0] == pytest.approx(4.0 / (2 * 0.6 * 9.81), abs=1e-3)
    (out / "member_00001.h5").unlink()
    again = tumble_cli(*args)
    assert again.returncode == 0, again.stderr
    assert "4 members, 4 done, 0 failed (3 from an earlier run)" in again.stdout


def test_sweep_draws_samples_from_a_seed(tmp_path):
    from tumble import ensemble

    result = tumble_cli("sweep", BLOCK, "-p", "materials.surface.friction=0.2:0.8", "-p", "world.dt=0.01,0.005",
                        "--samples", "3", "--seed", "7", "--duration", "0.2", "-j", "1", "--out", tmp_path,
                        "-q")  # fmt: skip
    assert result.returncode == 0, result.stderr
    expected = ensemble.sample(3, seed=7, uniform={"materials.surface.friction": (0.2, 0.8)},
                               choice={"world.dt": [0.01, 0.005]})  # fmt: skip
    rows = [row.split(",") for row in (tmp_path / "results.csv").read_text().splitlines()[1:]]
    assert [(float(r[1]), float(r[2])) for r in rows] == [
        (m["materials.surface.friction"], m["world.dt"]) for m in expected
    ]


@pytest.mark.skipif(not hasattr(signal, "SIGTERM") or sys.platform == "win32", reason="needs POSIX signals")
@pytest.mark.parametrize(("stop", "status", "said"), [
    pytest.param("SIGINT", 130, "interrupted", marks=pytest.mark.slow),  # the same path as SIGTERM's
    ("SIGTERM", 143, "terminated (SIGTERM)"),
])  # fmt: skip
def test_a_signal_stops_a_sweep_keeping_the_finished_members(tmp_path, stop, status, said):
    out = tmp_path / "sweep"
    args = [sys.executable, "-m", "tumble", "sweep", str(BLOCK), "-p", "materials.surface.friction=0.1:0.9:40",
            "--duration", "0.5", "-j", "1", "--out", str(out), "--quiet"]  # fmt: skip
    returncode, stdout, stderr = signal_when(args, (out / "member_00002.h5").exists, stop)
    assert returncode == status, (stdout, stderr)
    assert f"tumble: {said}: the members finished so far are kept in" in stderr and "Traceback" not in stderr
    finished = sorted(p.name for p in out.glob("member_*.h5") if ".partial" not in p.name)
    assert 3 <= len(finished) < 40
    assert all(Trajectory.load(out / name).metadata["status"] == "complete" for name in finished)
    again = tumble_cli(*args[3:])
    assert again.returncode == 0, again.stderr
    assert f"40 members, 40 done, 0 failed ({len(finished)} from an earlier run)" in again.stdout


def test_sweep_refuses_bad_input_and_reports_failed_members(tmp_path, tumble_here):
    blocker = tmp_path / "file"
    blocker.write_text("")
    base = ("sweep", BLOCK, "--duration", "0.2", "-j", "1", "-q")
    assert_clean_failure(tumble_here(*base, "-p", "materials.surface.frictoin=0.1,0.2", "--out", tmp_path / "a"), 2,
                         "--param: sliding_block.toml: materials.surface.frictoin: unknown key")  # fmt: skip
    assert_clean_failure(tumble_here(*base, "-p", "materials.surface.friction=0.1:0.2", "--out", tmp_path / "a"), 2,
                         "a range is LOW:HIGH:N")  # fmt: skip
    assert_clean_failure(tumble_here(*base, "-p", "world.dt=0.01", "--out", blocker / "x"), 2,
                         "--out", "cannot write there: Not a directory")  # fmt: skip
    assert_clean_failure(tumble_here(*base, "-p", "world.dt=0.01", "--out", tmp_path / "b", "--workers", "2",
                                    "--scheduler", "tcp://127.0.0.1:1"), 2, "not allowed with argument")  # fmt: skip
    result = tumble_cli(*base, "-p", "world.gravity[2]=-9.81,-1e308", "--out", tmp_path / "c")
    assert result.returncode == 1 and "Traceback" not in result.stderr, result.stderr
    assert "2 members, 1 done, 1 failed" in result.stdout and "SimulationError" in result.stdout


def test_batch_refuses_what_it_cannot_step_and_names_it(folder, tumble_here):
    assert_clean_failure(tumble_here("batch", folder / "small.toml", "-n", "0"), 2, "-n", "0")
    assert_clean_failure(tumble_here("batch", folder / "small.toml"), 2, "-n")
    assert_clean_failure(tumble_here("batch", "quadrotor_landing", "-n", "2"), 2, "quadrotor_landing",
                         "a Batch steps bodies, shapes and joints")  # fmt: skip
    result = tumble_cli("batch", folder / "spinner.toml", "-n", "3", "--quiet")
    assert_clean_failure(result, 1, "simulation failed", "copy 0: body 'spinner'", "step 25")
    assert "FAILED" in result.stdout
