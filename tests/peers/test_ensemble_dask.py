"""tumble.ensemble on Dask: a LocalCluster of two worker processes, started here, gives the local pool's table (and
a serial loop's: tests/unit/test_ensemble.py ties the pool to one); a worker killed mid-run loses no finished member,
and the run or a rerun completes the rest."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

distributed = pytest.importorskip("distributed")
cloudpickle = pytest.importorskip("cloudpickle")

from tumble import ensemble, scene_file  # noqa: E402
from tumble.ensemble.member import member_path  # noqa: E402
from tumble.trajectory import Trajectory  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "unit"))
import test_ensemble as local  # noqa: E402

pytestmark = pytest.mark.peers

MEMBERS = ensemble.grid({local.FRICTION: [0.2, 0.4, 0.6], local.GRAVITY: [-9.81, -3.71]})


@pytest.fixture(scope="module")
def cluster():
    """Two worker processes of one thread each; the test module's functions travel by value (the workers cannot
    import it)."""
    cloudpickle.register_pickle_by_value(local)
    with (
        distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster,
        distributed.Client(cluster) as client,
    ):
        yield cluster, client
    cloudpickle.unregister_pickle_by_value(local)


def test_a_dask_cluster_gives_the_local_pools_table(tmp_path, cluster):
    _, client = cluster
    pool = local._rows(ensemble.run(local.BLOCK, MEMBERS, local.DURATION, local.DT, tmp_path / "pool", workers=2))
    on_dask = local._rows(ensemble.run(local.BLOCK, MEMBERS, local.DURATION, local.DT, tmp_path / "dask",
                                       executor=client))  # fmt: skip
    by_address = local._rows(ensemble.run(local.BLOCK, MEMBERS, local.DURATION, local.DT, tmp_path / "address",
                                          executor=cluster[0].scheduler_address))  # fmt: skip
    with client.get_executor() as executor:
        by_executor = local._rows(ensemble.run(local.BLOCK, MEMBERS, local.DURATION, local.DT, tmp_path / "executor",
                                               executor=executor))  # fmt: skip
    assert all(row["status"] == "done" for row in pool)
    assert local._without(on_dask, "wall_s", "path") == local._without(pool, "wall_s", "path")
    assert local._without(by_address, "wall_s", "path") == local._without(pool, "wall_s", "path")
    assert local._without(by_executor, "wall_s", "path") == local._without(pool, "wall_s", "path")
    # The workers ran in other processes and wrote the same bits as the pool and as a serial loop here.
    for member, row_pool, row_dask in zip(MEMBERS, pool, on_dask, strict=True):
        one, two = Trajectory.load(row_pool["path"]), Trajectory.load(row_dask["path"])
        assert (one.position == two.position).all() and (one.velocity == two.velocity).all()
        loaded = scene_file.load(local.BLOCK, member)
        start = loaded.world.total_energy()
        serial = loaded.world.simulate(local.DURATION, local.DT)
        assert (serial.position == two.position).all() and (serial.orientation == two.orientation).all()
        assert row_dask["energy_change"] == loaded.world.total_energy() - start


def test_a_function_of_the_users_runs_on_dask(tmp_path, cluster):
    _, client = cluster
    members = [{"friction": m[local.FRICTION], "gravity": m[local.GRAVITY]} for m in MEMBERS]
    table = local._rows(ensemble.run(local.block_world, members, local.DURATION, local.DT, tmp_path, executor=client))
    for row, member in zip(table, members, strict=True):
        expected = local._slid(member["friction"], -member["gravity"], local.DURATION)
        assert row["max_displacement"] == pytest.approx(expected, abs=1e-3)


def test_a_killed_dask_worker_loses_no_finished_member(tmp_path, cluster):
    """The member of friction 0.6 kills its worker process once: Dask gives its task to the other worker (or, past
    its retries, reports it lost, and a rerun completes it); no finished member is run again or lost."""
    _, client = cluster
    marker = str(tmp_path / "killed")
    members = [{"friction": mu, "gravity": -9.81, "marker": marker} for mu in (0.3, 0.4, 0.5, 0.6, 0.7, 0.8)]
    out = tmp_path / "out"
    first = local._rows(ensemble.run(local.killing_world, members, local.DURATION, local.DT, out, executor=client))
    assert os.path.exists(marker)
    finished = [row["member"] for row in first if row["status"] == "done"]
    assert len(finished) >= 5
    client.wait_for_workers(2, timeout=60)  # the nanny restarts the killed worker
    again = local._rows(ensemble.run(local.killing_world, members, local.DURATION, local.DT, out, executor=client))
    assert [row["status"] for row in again] == ["done"] * 6
    assert [row["member"] for row in again if row["reused"]] == finished
    for row, member in zip(again, members, strict=True):
        assert Trajectory.load(member_path(out, row["member"])).metadata["status"] == "complete"
        expected = local._slid(member["friction"], 9.81, local.DURATION)
        assert row["max_displacement"] == pytest.approx(expected, abs=1e-3)
