"""The command line never leaks a traceback (issue 21): seeded mutants of every shipped scene (``scene_fuzz.py``)
run through ``tumble run`` in-process must exit 0, 1 or 2 with no traceback. A few hundred in ``make test``, a
few thousand in ``make test-slow``; a failure names the seed and index that replay it."""

from __future__ import annotations

import traceback

import pytest

from scene_fuzz import mutant
from tumble.cli import main

ALLOWED = {0, 1, 2}


def _run_mutants(seed: int, count: int, folder, capsys) -> dict[int, int]:
    statuses: dict[int, int] = {}
    for index in range(count):
        case = mutant(seed, index)
        path = folder / f"mutant{case.suffix}"
        path.write_bytes(case.data)
        try:
            # Two steps of 10 ms whatever the file says: the mutant's own dt or duration could run for ever.
            status = main(["run", str(path), "--dt", "0.01", "--duration", "0.02", "-q"])
        except SystemExit as exit_:
            status = exit_.code
        except BaseException:  # noqa: BLE001 - any escape is the failure this test looks for
            pytest.fail(f"{case} raised:\n{traceback.format_exc()}")
        out, err = capsys.readouterr()
        if status not in ALLOWED or "Traceback" in out + err:
            pytest.fail(f"{case} exited {status}:\n{err[-2000:]}")
        statuses[status] = statuses.get(status, 0) + 1
    return statuses


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_hundred_mutants_of_the_shipped_scenes_exit_cleanly(seed, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)  # a mutant's relative recording.path lands here
    statuses = _run_mutants(seed, 100, tmp_path, capsys)
    assert statuses.get(2, 0) > 20  # many mutants are bad input, and are said to be
    assert statuses.get(0, 0) + statuses.get(1, 0) > 10  # others still run (or fail as a simulation may)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(100, 106))
def test_three_thousand_mutants_exit_cleanly(seed, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    _run_mutants(seed, 500, tmp_path, capsys)


def test_the_mutants_are_the_same_for_a_seed_and_differ_across_seeds():
    assert mutant(7, 3) == mutant(7, 3)
    assert len({mutant(7, k).data for k in range(20)}) == 20
    assert mutant(7, 0).data != mutant(8, 0).data
