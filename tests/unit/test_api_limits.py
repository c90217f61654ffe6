"""Issue 22: the public API refuses overflowing and degenerate values with a ValueError naming the argument, and
a refused call or a failed step never leaves the world stuck; damaged files and environments give one clear error.
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from tumble.dynamics.integrate import thread_count

# --- environment -----------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("setting", "cores", "threads"),
    [(None, 2, 2), ("", 4, 4), ("auto", 2, 2), (" AUTO ", 3, 3), ("1", 2, 1), ("2", 2, 2), ("8", 2, 2), ("1", None, 1)],
)
def test_tumble_threads_is_a_count_or_auto(setting, cores, threads):
    assert thread_count(setting, cores) == threads


@pytest.mark.parametrize("setting", ["0", "-3", "two", "1.5", "4 threads"])
def test_a_bad_tumble_threads_warns_and_uses_every_core(setting):
    with pytest.warns(RuntimeWarning, match=rf"TUMBLE_THREADS={setting!r}.*one per core \(2\)"):
        assert thread_count(setting, 2) == 2


def test_tumble_imports_and_steps_whatever_the_environment_says():
    env = dict(os.environ, PROJECT="myproject", TUMBLE_THREADS="auto")
    code = "import tumble; w = tumble.World(); w.add_body(tumble.Sphere(1.0), mass=1.0); w.step(0.01); print('ok')"
    result = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "ok"
    assert "Warning" not in result.stderr
    env["TUMBLE_THREADS"] = "lots"
    result = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    assert "TUMBLE_THREADS='lots'" in result.stderr
