"""The benchmarks run on tiny sizes and return finite rows, so they never rot. Nothing here asserts on timings."""

from __future__ import annotations

import importlib.util
import json
import math
import os
import sys
from pathlib import Path

import numpy as np
import pytest

import tumble

REPO = Path(__file__).resolve().parent.parent
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from benchmarks import build, contact_steps, joints, peers, quadrotor, run, step_breakdown  # noqa: E402

TINY = run.Sizes(
    tumbling_steps=40, record_every=10, bodies=8, body_steps=5, mujoco_seconds=0.002, repeat=1,
    cold_start=False, cold_start_bodies=2, scaling_bodies=(4, 16), scaling_body_steps=64,
)  # fmt: skip


def _assert_finite_numbers(rows: list[dict]) -> None:
    assert rows
    for row in rows:
        for key, value in row.items():
            if isinstance(value, (int, float, np.number)) and not isinstance(value, bool):
                assert math.isfinite(value), f"{key} = {value} in {row}"


def test_tumbling_rows_for_every_tumble_integrator():
    rows = run.bench_tumbling(TINY)
    _assert_finite_numbers(rows)
    tumble_rows = [r for r in rows if r["engine"] == "tumble"]
    assert {(r["integrator"], r["mode"]) for r in tumble_rows} == {
        (name, mode) for name in run.TUMBLE_INTEGRATORS for mode in ("simulate", "step() loop")
    }
    for r in tumble_rows:
        assert r["steps"] == TINY.tumbling_steps
        assert r["steps_per_s"] > 0


def test_tumbling_rows_for_mujoco():
    pytest.importorskip("mujoco")
    rows = run.bench_tumbling(TINY)
    _assert_finite_numbers(rows)
    modes = {(r["integrator"], r["mode"]) for r in rows if r["engine"] == "MuJoCo"}
    assert {("Euler", "mj_step loop"), ("RK4", "mj_step loop")} <= modes
    assert all("x_mujoco_rk4" in r for r in rows)
    # RK4 keeps the energy of a free body to round-off over 40 steps in both engines.
    for r in rows:
        if r["integrator"] in ("auto", "rk4", "RK4"):
            assert r["energy_drift"] < 1e-9


def test_many_bodies_rows():
    rows = run.bench_many_bodies(TINY)
    _assert_finite_numbers(rows)
    tumble_rows = [r for r in rows if r["engine"] == "tumble"]
    assert {r["integrator"] for r in tumble_rows} == {"auto", "symplectic", "rk4"}
    assert 1 in {r["threads"] for r in tumble_rows}
    scaling = [r for r in tumble_rows if r["config"] == "no contacts, scaling"]
    assert sorted((r["bodies"], r["steps"]) for r in scaling) == [(4, 16), (4, 16), (16, 4), (16, 4)]
    assert all(r["bodies"] == TINY.bodies for r in rows if r not in scaling)
    targets = {t["target"] for t in run.check_targets({"many_bodies": rows})}
    assert "symplectic: time per body-step at 16 bodies over 4 (x)" in targets


def test_targets_table_and_csv(tmp_path):
    code = run.main(["--quick", "--only", "tumbling", "--csv", str(tmp_path), "--machine", "smoke"])
    assert code == 0
    folder = tmp_path / "smoke"
    assert (folder / "tumbling.csv").read_text().startswith("engine,integrator,mode")
    assert "commit" in (folder / "machine.csv").read_text()
    rows = [{"name": "a", "value": 1.5e-12}, {"name": "bb", "value": 2_000_000.0}]
    table = run.format_table(rows)
    assert table.splitlines()[0].split() == ["name", "value"]
    targets = run.check_targets({"tumbling": run.bench_tumbling(TINY)})
    assert {t["met"] for t in targets} <= {"yes", "NO"}


def test_cold_start_scripts_run_and_print_their_timings(capsys):
    for order in ("step first", "simulate first"):
        exec(compile(run.cold_start_script(2, order), "<cold start>", "exec"), {})  # here: warm, in-process
        timings = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
        assert set(timings) == {"import_s", "first_step_s", "first_simulate_s"}
        assert all(value >= 0.0 for value in timings.values())


def test_drift_measure_agrees_with_tumble_diagnostics():
    """The benchmark's E and L formulas (used for both engines) match tumble's own Trajectory values."""
    world = tumble.World(gravity=(0.0, 0.0, 0.0))
    world.add_body(None, mass=1.0, inertia=np.diag(run.INERTIA), angular_velocity=run.OMEGA0)
    traj = world.simulate(0.2, 1e-3, record_every=20)
    omega_body = traj.angular_velocity_body()[:, 0]
    energy = peers.rotational_energy(run.INERTIA, omega_body)
    angmom = peers.angular_momentum_world(traj.orientation[:, 0], run.INERTIA, omega_body)
    np.testing.assert_allclose(energy, traj.total_energy, rtol=1e-12)
    np.testing.assert_allclose(angmom, traj.angular_momentum(), rtol=1e-12, atol=1e-12)


def test_mujoco_free_body_angular_velocity_is_set_in_the_body_frame():
    mujoco = pytest.importorskip("mujoco")
    positions = peers.grid_positions(3)
    model, data = peers.load(peers.free_bodies_mjcf(positions))
    quat = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [np.cos(0.4), 0.0, np.sin(0.4), 0.0]])
    data.qpos.reshape(-1, 7)[:, 3:7] = quat
    omega_world = peers.random_angular_velocities(3, seed=1)
    peers.set_free_body_angvel(model, data, omega_world)
    mujoco.mj_forward(model, data)
    for i in range(3):
        velocity = np.zeros(6)
        mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_BODY, i + 1, velocity, 0)
        np.testing.assert_allclose(velocity[:3], omega_world[i], atol=1e-12)


# --- contact benchmarks (benchmarks/contact.py) ----------------------------------------------------------

CONTACT_TINY = run.Sizes(
    repeat=1, pile_boxes=8, pile_seconds=0.05, pyramid_base=3, pyramid_seconds=0.05, cubes_boxes=(4,),
    cubes_seconds=0.05, big_pyramid_base=3, big_pyramid_seconds=0.05,
)  # fmt: skip


def _contact_rows_are_sane(rows: list[dict], bodies: int) -> None:
    _assert_finite_numbers(rows)
    assert {(r["engine"], r["hz"]) for r in rows if r["engine"] == "tumble"} == {("tumble", 60), ("tumble", 240)}
    for r in rows:
        assert r["bodies"] == bodies
        assert r["steps_per_s"] > 0 and r["realtime_x"] > 0
        assert r["below_ground"] == 0
        assert r["notes"] == "", r["notes"]


def test_contact_pile_and_pyramid_rows_for_tumble():
    """Runs with or without the peers; tumble's rows are there either way."""
    rows = run.BENCHMARKS["pile"](CONTACT_TINY)
    _contact_rows_are_sane(rows, 8)
    pyramid = run.BENCHMARKS["pyramid"](CONTACT_TINY)
    _contact_rows_are_sane(pyramid, 6)
    assert all(r["top_drift_mm"] < 10 for r in pyramid)
    big = run.BENCHMARKS["big_pyramid"](CONTACT_TINY)
    assert [(r["engine"], r["hz"]) for r in big] == [("tumble", 60)]
    assert "big_pyramid" in run.OPTIONAL


def test_contact_steps_rows_for_every_scene_and_both_modes():
    """The step() loop and simulate of each scene (the ant's only with Gymnasium's assets), and MuJoCo's mj_step loop
    on the same model where MuJoCo is installed, every tumble row measured against it."""
    rows = run.BENCHMARKS["contact_steps"](run.QUICK)
    tumble_rows = [r for r in rows if r["engine"] == "tumble"]
    scene_names = ["one free body", "box on a plane", "27-box pile"]
    if contact_steps.ant_path() is not None and os.path.exists(contact_steps.ant_path()):
        scene_names.append("ant, ctrl set every step")
    assert [(r["scene"], r["mode"]) for r in tumble_rows] == [
        (scene, mode) for scene in scene_names for mode in ("step() loop", "simulate")
    ]
    assert all(r["us_per_step"] > 0 for r in rows)
    assert [r["x_simulate"] for r in tumble_rows if r["mode"] == "simulate"] == [1.0] * len(scene_names)
    mujoco = [r for r in rows if r["engine"] == "MuJoCo"]
    if importlib.util.find_spec("mujoco") is not None:
        assert [r["scene"] for r in mujoco] == scene_names and all(r["x_mujoco"] == 1.0 for r in mujoco)
        assert all("x_mujoco" in r for r in tumble_rows)


def test_the_step_breakdown_splits_each_call_into_its_parts():
    rows = step_breakdown.breakdown()
    assert [r["scene"] for r in rows] == ["one free body", "box on a plane"]
    for row in rows:
        # No timing compared: under a loaded test run the step and the same step inside simulate can swap.
        assert row["step_us"] > 0 and row["simulate_us"] > 0 and row["entry_us"] > 0
        assert row["python_us"] == pytest.approx(row["step_us"] - row["simulate_us"] - row["entry_us"])
    free, box = rows
    assert free["allocations"] == 0 and box["allocations"] > 0  # counted: the free loop allocates nothing


def test_contact_rows_for_the_peers():
    pytest.importorskip("mujoco")
    pytest.importorskip("pybullet")
    rows = run.BENCHMARKS["cubes"](CONTACT_TINY)
    _contact_rows_are_sane(rows, 4)
    assert {r["engine"] for r in rows} == {"tumble", "MuJoCo", "PyBullet"}
    assert all("x_mujoco" in r and "x_pybullet" in r for r in rows)
    assert max(r["x_pybullet"] for r in rows if r["engine"] == "PyBullet") == pytest.approx(1.0)


def test_contact_targets_in_quick_mode(tmp_path):
    code = run.main(["--quick", "--only", "pile", "--only", "pyramid", "--csv", str(tmp_path), "--machine", "smoke"])
    assert code == 0
    assert (tmp_path / "smoke" / "pile.csv").read_text().startswith("scene,bodies,engine,hz")
    targets = (tmp_path / "smoke" / "targets.csv").read_text()
    assert "pile 27, tumble 60 Hz: max penetration (mm)" in targets
    assert "pyramid 10, tumble 60 Hz: top drift (mm)" in targets


def test_box_corners_and_mujoco_penetration_helpers():
    quat = np.array([[1.0, 0.0, 0.0, 0.0], [np.cos(np.pi / 8), np.sin(np.pi / 8), 0.0, 0.0]])
    low = peers.box_vertices_min_z([[0.0, 0.0, 0.1], [0.0, 0.0, 0.1]], quat, [0.1, 0.1, 0.1])
    np.testing.assert_allclose(low, [0.0, 0.1 - 0.1 * np.sqrt(2.0)], atol=1e-12)
    assert "type='plane'" in peers.boxes_on_plane_mjcf([[0.0, 0.0, 0.1]], [[1.0, 0.0, 0.0, 0.0]], 0.1, 1.0)


# --- world-joint chain (benchmarks/joints.py) -------------------------------------------------------------

CHAIN_TINY = run.Sizes(repeat=1, chain_links=3, chain_seconds=0.05)


def test_world_chain_rows():
    """Runs with or without the peers; tumble's rows are there either way, each peer's when installed."""
    rows = run.BENCHMARKS["world_chain"](CHAIN_TINY)
    _assert_finite_numbers(rows)
    assert {r["hz"] for r in rows if r["engine"] == "tumble"} == {60, 240}
    engines = {r["engine"] for r in rows}
    assert ("PyBullet" in engines) == peers.have_pybullet()
    assert ("MuJoCo" in engines) == peers.have_mujoco()
    for r in rows:
        assert r["links"] == 3 and r["steps_per_s"] > 0 and r["notes"] == "", r
        assert r["max_gap_mm"] < 5 and abs(r["energy_change"]) < 0.1
        if r["engine"] == "MuJoCo" or "multibody" in r["config"]:  # generalised coordinates: exact joints
            assert r["max_gap_mm"] < 1e-6 and r["max_axis_rad"] < 1e-9
    if peers.have_pybullet():
        reference = [r for r in rows if r["engine"] == "PyBullet" and r["hz"] == 240 and "maximal" in r["config"]]
        assert [r["x_pybullet"] for r in reference] == [1.0]


def test_world_chain_measures_agree_with_tumble_joint_handles():
    """The benchmark's gap and axis angle (from body poses, the same for every engine) are tumble's own errors."""
    world = joints.world_chain(4)
    chain = joints.chain_from_world(world, 4)
    assert chain.potential_drop == pytest.approx(0.1 * 9.81 * (0.05 + 0.15 + 0.25 + 0.35))
    for _ in range(20):
        world.step(1 / 60)
    s = world.state
    omega = world.angular_velocities()
    frame = joints._Frame(s.body_pos.copy(), tumble.rotation.quat_to_matrix(s.body_quat), s.body_linvel.copy(), omega)
    gap, angle = joints.joint_errors(chain, frame)
    np.testing.assert_allclose(gap, [j.position_error for j in world.joints], rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(angle, [j.angular_error for j in world.joints], atol=1e-9)
    # tumble's potential energy is zero at the origin, the benchmark's at the pivot.
    offset = chain.mass.sum() * (chain.gravity @ chain.pivot)
    assert joints.energy(chain, frame) == pytest.approx(world.total_energy() + offset, rel=1e-12, abs=1e-12)


def test_world_chain_is_the_pendulum_chain_scene_without_collisions():
    chain = joints.world_chain(5)
    assert [b.name for b in chain.bodies] == [f"link{k}" for k in range(5)]
    assert len(chain.joints) == 5 and all(j.kind == "hinge" for j in chain.joints)
    assert not chain.model.shape_mask.any()  # the benchmark's links collide with nothing


def test_quadrotor_rows_for_every_controller_and_rate():
    sizes = run.Sizes(**{**run.QUICK.__dict__, "quadrotor_seconds": 0.05, "rotorpy_seconds": 0.05})
    rows = quadrotor.bench_quadrotor(sizes)
    _assert_finite_numbers([{k: v for k, v in r.items() if k not in ("rms_error_cm", "x_rotorpy")} for r in rows])
    tumble_rows = {(r["controller"], r["rate_hz"]) for r in rows if r["engine"] == "tumble"}
    assert len(tumble_rows) == 3 * len(quadrotor.RATES)


def test_build_rows_for_every_world_and_way_and_the_same_world_each_way(tmp_path):
    sizes = run.Sizes(**{**run.QUICK.__dict__, "build_bodies": (30, 120), "build_joints": (30,)})
    rows = build.bench_build(sizes)
    _assert_finite_numbers([{k: v for k, v in r.items() if k != "x_mujoco"} for r in rows])
    assert {(r["case"], r["how"]) for r in rows} == {
        (case, how) for case in ("free bodies", "chain", "grid") for how in ("API", "scene file", "MuJoCo MJCF")
    }
    assert {r["bodies"] for r in rows if r["case"] == "free bodies"} == {31, 121}  # and the ground
    assert {r["joints"] for r in rows if r["case"] == "grid"} == {2 * 4 * 3}  # the side-4 grid is closest to 30
    # The scene file describes the world the API builds.
    for case in ("free bodies", "chain", "grid"):
        api = build.api_world(case, 30)
        path = tmp_path / f"{case}.toml"
        path.write_text(build.scene_toml(case, 30))
        scene = tumble.scene_file.load(path).world
        np.testing.assert_allclose(scene.state.body_pos, api.state.body_pos, atol=1e-12)
        assert scene.model.joint_count == api.model.joint_count
    targets = run._build_targets(rows)
    assert any("scene file vs API" in t["target"] for t in targets)
    mujoco = pytest.importorskip("mujoco")
    for case in ("free bodies", "chain", "grid"):
        model = mujoco.MjModel.from_xml_string(build.mjcf(case, 30))
        assert model.nbody - 1 == build.api_world(case, 30).model.body_count - (case == "free bodies")


def test_model_files_rows_for_every_loader():
    from benchmarks import model_files

    rows = model_files.bench_model_files(chain_links=3, repeat=1)
    _assert_finite_numbers(rows)
    assert {r["model"] for r in rows} >= {"chain of 3"}
    assert {r["loader"] for r in rows if r["model"] == "chain of 3"} >= {"tumble read_mjcf", "tumble from_mjcf"}


def test_mjcf_contacts_rows_for_both_engines():
    from benchmarks import model_files

    rows = model_files.bench_mjcf_contacts(seconds=0.05, repeat=1)
    _assert_finite_numbers(rows)
    assert {r["engine"] for r in rows} >= {"tumble World"}
    assert {r["model"] for r in rows} == {"ant", "humanoid"}


def test_robots_rows_for_both_engines_and_modes():
    pytest.importorskip("mujoco")
    pytest.importorskip("gymnasium")
    from benchmarks import robots

    rows = robots.bench_robots(seconds=0.02, repeat=1, models=("hopper",), chains=(3,))
    _assert_finite_numbers(rows)
    assert {(r["model"], r["engine"], r["mode"]) for r in rows} == {
        *((m, e, mode) for m in ("hopper",) for e in ("tumble", "MuJoCo") for mode in ("simulate", "step loop")),
        *(("chain of 3", e, "simulate") for e in ("tumble", "MuJoCo")),
    }


def test_broad_phase_rows_for_both_worlds_and_pairs_in_the_pile():
    from benchmarks import broad_phase

    rows = broad_phase.bench_broad_phase(run.Sizes(**{**run.QUICK.__dict__, "broad_phase_shapes": (50,)}))
    _assert_finite_numbers(rows)
    assert [(r["world"], r["shapes"]) for r in rows] == [("pile", 50), ("scatter", 50)]
    # 50 boxes 1 cm apart with a 2 cm margin (5 rows of 10): the bounds of every neighbour overlap, along the rows
    # (5 * 9), across them (4 * 10) and on both diagonals (2 * 4 * 9).
    assert rows[0]["pairs"] == 5 * 9 + 4 * 10 + 2 * 4 * 9


def test_first_run_rows_with_warm_caches():
    from benchmarks import first_run

    rows = first_run.bench_first_run(run.Sizes(**{**run.QUICK.__dict__, "cold_start": False}))
    _assert_finite_numbers(rows)
    assert [r["case"] for r in rows] == ["sphere on a plane"] and rows[0]["run_s"] > 0


def test_batch_rows_for_both_scenes_with_ratios_to_mujoco():
    from benchmarks import batch

    rows = batch.bench_batch(batch.QUICK)
    _assert_finite_numbers(rows)
    tumble_rows = [r for r in rows if r["engine"] == "tumble"]
    assert {r["scene"] for r in tumble_rows} == {"tumbling", "isotropic", "pile"}
    assert {r["config"] for r in tumble_rows if r["scene"] == "tumbling"} == {"rk4", "symplectic", "auto"}
    assert all(r["body_steps_per_s"] > 0 and r["copies"] == (4 if r["scene"] == "pile" else 8) for r in tumble_rows)
    if any(r["engine"] == "MuJoCo" for r in rows):
        assert all("x_mujoco_Euler_steps" in r for r in tumble_rows if r["scene"] != "pile")
        like = {r["config"]: "x_like_for_like" in r for r in tumble_rows if r["scene"] == "tumbling"}
        assert like == {"rk4": True, "symplectic": True, "auto": False}
        assert all("x_mujoco_240hz_sim_time" in r for r in tumble_rows if r["scene"] == "pile")


def test_envs_rows_for_every_env_with_ratios_to_mujoco():
    from benchmarks import envs

    rows = envs.bench_envs(envs.QUICK)
    _assert_finite_numbers(rows)
    ours = [r for r in rows if r["engine"] == "tumble"]
    assert {r["env"] for r in ours} == {"tumble/CartPole", "tumble/DoublePendulum", "tumble/Pendulum",
                                         "tumble/QuadrotorHover", "tumble/Hopper", "tumble/Walker2d",
                                         "tumble/HalfCheetah", "tumble/Ant", "tumble/Humanoid"}  # fmt: skip
    assert all(r["env_steps_per_s"] > 0 for r in rows)
    assert {r["copies"] for r in ours if r["kind"] == "vector"} == {1, 4}
    if any(r["engine"] == "MuJoCo" for r in rows):
        assert all("x_mujoco_single" in r for r in ours if r["env"] == "tumble/CartPole" and r["kind"] == "single")
        assert all("x_mujoco_vec4" in r for r in ours if r["env"] == "tumble/DoublePendulum" and r["kind"] == "vector")
        assert all("x_mujoco_vec4" in r for r in ours if r["env"] == "tumble/Ant" and r["kind"] == "vector")


@pytest.mark.slow  # 20 s: four process pools and two Dask clusters start
def test_ensemble_rows_for_the_pool_and_dask_with_their_efficiency():
    from benchmarks import ensembles

    rows = ensembles.bench_ensemble(ensembles.QUICK)
    _assert_finite_numbers(rows)
    executors = {(r["executor"], r["workers"]) for r in rows}
    assert {("serial loop", 1), ("local pool", 1), ("local pool", 2)} <= executors
    assert all(r["members"] == 4 and r["members_per_s"] > 0 for r in rows if "scaling" not in r["executor"])
    assert all("efficiency" in r for r in rows if r["workers"] == 2 and "scaling" not in r["executor"])
    assert [r["members"] for r in rows if "scaling" in r["executor"]] == [2, 4]


@pytest.mark.slow  # 10 s on a fresh clone: the profile compiles its own copy of each stage, which the warmup does not
def test_the_contact_profile_replays_the_batch_step_to_its_bits_stage_by_stage():
    from benchmarks import contact_profile

    whole = contact_profile.profile(contact_profile.ProfileSizes(copies=2, boxes=4, steps=6))
    split = contact_profile.profile(contact_profile.QUICK)
    for result in (whole, split):
        assert result["same_bits"]  # the replay is pipeline.contact_stages, stage for stage
        assert all(seconds >= 0.0 for seconds in result["stages"].values())
        lines = contact_profile.table(result)
        assert lines[-1].startswith("| all stages |") and len(lines) == len(result["stages"]) + 3
    assert "run_substeps" in whole["stages"] and "solve_contacts" not in whole["stages"]
    assert {"solve_contacts", "relax_contacts", "warm_start_contacts"} <= set(split["stages"])
    assert "run_substeps" not in split["stages"]
    assert split["per_step"]["found_again"] > 0 and "rebase_contacts" in split["stages"]
