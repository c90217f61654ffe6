"""Every shipped scene at every rate: 3 s of simulated time at 30, 60, 120, 240 and 1000 Hz with no error, and the
same final state (``State.digest()``) from two runs in separate processes; the mixed pile also for 12 s at 240 Hz,
past the step (2638) where an EPA that read a face it had never written once crashed it or blew a hull up.

Each scene runs in two fresh interpreters side by side (``tests/scene_runs.py``): a crash there (a segfault) fails
the test with its exit status instead of taking pytest down, and two processes share no memory, so a result that
leans on uninitialised memory or on state left in the process shows up as two digests.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from tumble import scenes

RUNNER = Path(__file__).resolve().parent.parent / "scene_runs.py"
RATES = (30, 60, 120, 240, 1000)
SCENES = [path.stem for path in scenes.files()]


def run_twice(name: str, duration: float, rates) -> tuple[dict, dict]:
    """The runner's ``{rate: digest or error}`` from two processes started together."""
    command = [sys.executable, str(RUNNER), name, f"{duration!r}", *(str(rate) for rate in rates)]
    runs = [subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) for _ in range(2)]
    results = []
    for run in runs:
        out, err = run.communicate(timeout=280)
        assert run.returncode == 0, f"{name}: the runner exited with {run.returncode}\n{err[-3000:]}"
        results.append(json.loads(out))
    return results[0], results[1]


def errors_in(result: dict) -> dict:
    return {rate: outcome for rate, outcome in result.items() if outcome.startswith("error")}


@pytest.mark.slow
@pytest.mark.parametrize("name", SCENES)
def test_every_shipped_scene_runs_at_every_rate_and_repeats_bit_for_bit(name):
    first, second = run_twice(name, 3.0, RATES)
    assert not errors_in(first) and not errors_in(second)
    assert sorted(first) == sorted(f"{rate:g}" for rate in RATES)
    assert first == second


@pytest.mark.slow
def test_the_mixed_pile_runs_12_s_at_240_hz_past_its_old_crash():
    first, second = run_twice("mixed_pile", 12.0, [240])
    assert not errors_in(first) and not errors_in(second)
    assert first == second
