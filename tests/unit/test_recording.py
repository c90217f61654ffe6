"""Trajectories on disk: chunked HDF5 and .npz recording, failed and interrupted runs, metadata, CSV (issue 5.3)."""

from __future__ import annotations

import csv
import json
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import tumble
from tumble import recording, runner, scenes
from tumble.trajectory_io import FRAME_ARRAYS, STATIC_ARRAYS

h5py = pytest.importorskip("h5py")

DT = 1 / 60
ALL_ARRAYS = FRAME_ARRAYS + STATIC_ARRAYS


def _pile():
    return scenes.box_pile(8)


def _assert_same_arrays(a: tumble.Trajectory, b: tumble.Trajectory) -> None:
    for name in ALL_ARRAYS:
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert a.body_names == b.body_names


def test_record_writes_chunks_equal_to_one_simulate_call_and_carries_metadata(tmp_path):
    path = tmp_path / "pile.h5"
    scene = {"name": "pile", "bodies": 8}
    chunks = []
    world = _pile()
    traj = recording.record(world, 0.5, DT, path, every=2, chunk_frames=4, scene=scene,
                            callback=lambda w, writer: chunks.append(writer.frame_count))  # fmt: skip
    reference_world = _pile()
    reference = reference_world.simulate(0.5, DT, record_every=2)

    # The same steps as one simulate call, bit for bit; 30 steps, every 2nd recorded, plus the initial state.
    assert world.state.digest() == reference_world.state.digest()
    assert len(traj) == len(reference) == 16
    for name in ("position", "orientation", "velocity", "angular_velocity"):
        np.testing.assert_array_equal(getattr(traj, name), getattr(reference, name), err_msg=name)
    np.testing.assert_allclose(traj.time, reference.time, rtol=0, atol=1e-14)  # clock sums vs t0 + k dt
    # Written chunk by chunk: 1 + 4 frames after the first chunk (8 steps), 4 more after each of the next.
    assert chunks == [5, 9, 13, 16]

    meta = traj.metadata
    assert meta["tumble_version"] == tumble.__version__
    assert meta["dt"] == DT and meta["record_every"] == 2 and meta["status"] == "complete"
    assert meta["integrator"] == "auto" and meta["integrator_used"] == "symplectic"
    assert meta["solver"] == world.solver._asdict()
    assert meta["scene"] == scene
    assert traj.body_names == ["ground"] + [f"box{k}" for k in range(8)]
    np.testing.assert_array_equal(traj.body_mass, world.model.body_mass)
    np.testing.assert_array_equal(traj.body_inertia, world.model.body_inertia_local)

    # The file is plain HDF5: growable datasets, metadata as a JSON attribute, names as strings.
    with h5py.File(path, "r") as f:
        assert f.attrs["format"] == "tumble.trajectory"
        assert json.loads(f.attrs["metadata"])["scene"] == scene
        assert f["position"].shape == (16, 9, 3) and f["position"].maxshape == (None, 9, 3)
        assert [n.decode() for n in f["body_names"][()]][:2] == ["ground", "box0"]


def test_npz_and_hdf5_round_trip_the_same_arrays_and_metadata(tmp_path):
    world = _pile()
    traj = recording.record(world, 0.25, DT, tmp_path / "run.npz", chunk_frames=5, scene='{"name": "pile"}')
    assert traj.metadata["scene"] == {"name": "pile"} and traj.metadata["status"] == "complete"
    for name in ("copy.h5", "copy.hdf5", "copy.npz"):
        traj.save(tmp_path / name)
        loaded = tumble.Trajectory.load(tmp_path / name)
        _assert_same_arrays(loaded, traj)
        assert loaded.metadata == traj.metadata
    # .npz needs numpy alone, without pickles.
    with np.load(tmp_path / "copy.npz", allow_pickle=False) as data:
        assert json.loads(str(data["metadata_json"]))["tumble_version"] == tumble.__version__
    # A name without a suffix gets .npz, as numpy's savez does.
    traj.save(tmp_path / "bare")
    _assert_same_arrays(tumble.Trajectory.load(tmp_path / "bare.npz"), traj)


def test_a_failed_run_leaves_every_frame_before_the_failing_step(tmp_path, monkeypatch):
    """A step that goes non-finite mid-chunk: the frames of the chunks before it and of the good steps of its
    chunk are in the file, which is closed with status "failed"; the error carries the same frames."""
    world, loop = _pile(), runner._plain_contact_loop

    def fail_at_step_23(*args):
        """The runner's compiled loop, up to the world's step 23, which body 3 fails (the world as before it)."""
        *head, first, n_steps, origin_time, origin_count = args
        stop = 23 - world.step_count  # the call's step that is the world's step 23
        if not first <= stop < n_steps:
            return loop(*args)
        done, failing, controller, count, needed = loop(*head, first, stop, origin_time, origin_count)
        return (done, failing, controller, count, needed) if done < stop or needed > 0 else (stop, 3, -1, count, 0)

    monkeypatch.setattr(runner, "_plain_contact_loop", fail_at_step_23)
    path = tmp_path / "failed.h5"
    with pytest.raises(tumble.SimulationError, match="box2") as info:
        recording.record(world, 1.0, DT, path, chunk_frames=10)
    loaded = tumble.Trajectory.load(path)
    assert len(loaded) == 24  # the initial state and steps 1..23
    assert loaded.metadata["status"] == "failed" and "box2" in loaded.metadata["error"]
    _assert_same_arrays(info.value.trajectory, loaded)
    monkeypatch.undo()
    reference = _pile().simulate(23 * DT, DT)
    np.testing.assert_array_equal(loaded.position, reference.position)


def test_a_body_blown_up_by_a_force_leaves_the_chunks_before_it(tmp_path):
    """A real overflow (a finite torque whose spin overflows to inf) in the first step of the third chunk."""

    def blow_up(world, writer):
        if writer.frame_count == 11:  # after the second chunk
            world.body("box3").apply_torque((1e308, 1e308, 1e308))

    path = tmp_path / "blown.npz"
    with np.errstate(over="ignore", invalid="ignore"), pytest.raises(tumble.SimulationError):
        recording.record(_pile(), 1.0, DT, path, chunk_frames=5, callback=blow_up)
    loaded = tumble.Trajectory.load(path)
    assert len(loaded) == 11 and loaded.metadata["status"] == "failed"
    assert all(np.isfinite(getattr(loaded, name)).all() for name in FRAME_ARRAYS)


def test_keyboard_interrupt_from_a_callback_leaves_a_readable_file(tmp_path):
    def interrupt(world, writer):
        if writer.frame_count > 10:
            raise KeyboardInterrupt

    for name in ("interrupted.h5", "interrupted.npz"):
        world = _pile()
        with pytest.raises(KeyboardInterrupt):
            recording.record(world, 2.0, DT, tmp_path / name, every=2, chunk_frames=5, callback=interrupt)
        loaded = tumble.Trajectory.load(tmp_path / name)
        assert len(loaded) == 11 and loaded.metadata["status"] == "interrupted"
        assert world.step_count == 20 and loaded.time[-1] == pytest.approx(20 * DT)


def test_a_killed_process_keeps_every_chunk_flushed_before(tmp_path):
    """No Python clean-up at all (SIGKILL-like ``os._exit`` in the callback): the HDF5 file still reads."""
    path = tmp_path / "killed.h5"
    script = textwrap.dedent(f"""
        import os
        from tumble import recording, scenes

        def die(world, writer):
            if writer.frame_count > 10:
                os._exit(9)

        recording.record(scenes.box_pile(8), 2.0, {DT!r}, {str(path)!r}, chunk_frames=5, callback=die)
    """)
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert result.returncode == 9, result.stderr
    loaded = tumble.Trajectory.load(path)
    assert len(loaded) == 11 and loaded.metadata["status"] == "running"


def test_writer_appends_every_nth_step_and_skips_repeats(tmp_path):
    world = tumble.World()
    world.add_body(tumble.Box((0.1, 0.2, 0.3)), density=100.0, angular_velocity=(1, 2, 3), name="box")
    path = tmp_path / "manual.h5"
    with recording.TrajectoryWriter(path, world, every=3, chunk_frames=2, dt=0.01) as writer:
        assert writer.append(world) and not writer.append(world)  # the same step twice is kept once
        for _ in range(10):
            world.step(0.01)
            writer.append(world)
    assert writer.closed and writer.frame_count == 4  # steps 0, 3, 6, 9
    other = tumble.World()
    other.add_body(tumble.Box((0.1, 0.2, 0.3)), density=100.0, angular_velocity=(1, 2, 3), name="box")
    reference = other.simulate(0.09, 0.01, record_every=3)
    loaded = tumble.Trajectory.load(path)
    for name in ("position", "orientation", "velocity", "angular_velocity", "kinetic_energy"):
        np.testing.assert_array_equal(getattr(loaded, name), getattr(reference, name), err_msg=name)
    assert loaded.metadata["dt"] == 0.01 and loaded.metadata["status"] == "complete"


def test_writer_refuses_bad_input(tmp_path):
    world = _pile()
    with pytest.raises(ValueError, match="every must be an integer from 1 to"):
        recording.TrajectoryWriter(tmp_path / "a.h5", world, every=0)
    with pytest.raises(ValueError, match="scene must be a dict or a JSON string"):
        recording.TrajectoryWriter(tmp_path / "a.h5", world, scene="{not json")
    with pytest.raises(TypeError, match="scene must be a dict"):
        recording.TrajectoryWriter(tmp_path / "a.h5", world, scene=[1, 2])
    with pytest.raises(ValueError, match="compression applies to HDF5 files only"):
        recording.TrajectoryWriter(tmp_path / "a.npz", world, compression="gzip")
    writer = recording.TrajectoryWriter(tmp_path / "a.h5", world)
    world.add_body(tumble.Sphere(0.1), density=100.0)
    with pytest.raises(ValueError, match="the world has 10 bodies but this recording was opened with 9"):
        writer.append(world)
    writer.close()
    with pytest.raises(ValueError, match="is closed"):
        writer.append(world)
    with pytest.raises(ValueError, match="not a tumble trajectory"):
        np.savez(tmp_path / "other.npz", x=np.zeros(3))
        tumble.Trajectory.load(tmp_path / "other.npz")
    with pytest.raises(FileNotFoundError, match="no trajectory file"):
        tumble.Trajectory.load(tmp_path / "missing.h5")


def test_csv_has_one_row_per_frame_and_body_with_the_named_columns(tmp_path):
    world = _pile()
    traj = world.simulate(0.1, DT, record_every=2)
    path = tmp_path / "boxes.csv"
    traj.to_csv(path, bodies=["box1", 4])
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    assert rows[0] == ["time", "body", "x", "y", "z", "qw", "qx", "qy", "qz", "vx", "vy", "vz", "wx", "wy", "wz"]
    assert len(rows) == 1 + 2 * len(traj)
    assert [r[1] for r in rows[1:5]] == ["box1", "box3", "box1", "box3"]
    values = np.array([[float(v) for v in r[2:]] for r in rows[1:]]).reshape(len(traj), 2, 13)
    expected = np.concatenate([traj.position, traj.orientation, traj.velocity, traj.angular_velocity], axis=-1)
    np.testing.assert_array_equal(values, expected[:, [2, 4]])  # written in full precision
    np.testing.assert_array_equal([float(r[0]) for r in rows[1::2]], traj.time)
    traj.to_csv(tmp_path / "all.csv")
    with open(tmp_path / "all.csv", newline="") as f:
        assert sum(1 for _ in f) == 1 + len(traj) * traj.body_count


def test_trajectory_slices_and_body_selection():
    traj = _pile().simulate(0.1, DT)
    part = traj[2:5]
    assert len(part) == 3 and part.body_names == traj.body_names
    np.testing.assert_array_equal(part.velocity, traj.velocity[2:5])
    with pytest.raises(TypeError, match="indexed by a slice"):
        traj[0]
    world = _pile()
    assert traj.select_bodies([world.body("box0"), "box1", -1]) == [1, 2, 8]
    assert traj.select_bodies(None, dynamic_only=True) == list(range(1, 9))
    with pytest.raises(KeyError, match="no body named 'nope'"):
        traj.select_bodies("nope")
    with pytest.raises(IndexError, match="out of range"):
        traj.select_bodies(9)


def test_energy_parts_add_up_to_the_kinetic_energy():
    world = tumble.World(gravity=(0, 0, 0))
    world.add_body(tumble.Box((0.1, 0.2, 0.3)), density=100.0, velocity=(1, 2, 0), angular_velocity=(1, 2, 3))
    traj = world.simulate(0.1, 0.01)
    np.testing.assert_allclose(traj.translational_energy + traj.rotational_energy, traj.kinetic_energy, rtol=1e-14)
    np.testing.assert_allclose(traj.translational_energy, 0.5 * traj.body_mass[0] * 5.0, rtol=1e-14)


def test_default_chunk_is_about_four_mebibytes():
    assert recording.default_chunk_frames(1000) == 40
    assert recording.default_chunk_frames(1) == 1024 and recording.default_chunk_frames(10**6) == 16


@pytest.mark.skipif(os.name != "posix", reason="file modes")
def test_npz_rewrites_are_atomic(tmp_path):
    """The .npz is replaced by a rename, never left half-written: no partial file remains after a run."""
    recording.record(_pile(), 0.2, DT, tmp_path / "run.npz", chunk_frames=3)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.npz"]
