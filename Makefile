# tumble: every target sets itself up from a bare Python 3.11.
PYTHON ?= python3.11
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
BROWSER_STAMP := $(VENV)/.browser

.PHONY: install demo test test-slow bench bench-mjbatch lint clean

# The venv, then the kernels compiled two processes at a time (tumble warmup), so that the first run starts at once.
$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e ".[test,mesh,plot]"
	$(PY) -m tumble warmup --jobs 2 --quiet || echo "tumble warmup failed: the first runs will compile instead"
	touch $(STAMP)

install: $(STAMP)

# The flagship scene (a mixed pile poured into a bowl while a wrecking ball swings through it): writes the
# trajectory, out/replay.html (open it in a browser) and out/energy.png.
demo: $(STAMP)
	$(PY) -m tumble run flagship --out out/flagship.h5 --html out/replay.html --plot out/energy.png

# The browser tests drive Debian's Chromium through Playwright (no browser download).
$(BROWSER_STAMP): $(STAMP)
	test -x /usr/bin/chromium || { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium; }
	touch $(BROWSER_STAMP)

# Test processes at once (pytest-xdist): one per core of the 2-core machine CI runs on. The tests are single-threaded
# Python and compiled loops, so two halve the wall time (make test: 556 s -> 274 s, then 178 s -> 115 s).
TEST_JOBS ?= 2
PYTEST := $(PY) -m pytest -q -n $(TEST_JOBS)
# make test gives each process whole files (--dist loadfile): dealt out one by one, both processes compiled the kernels
# a file needs beyond tumble warmup's and built its module fixtures (a fresh clone's first pass: 486 s -> 320 s, some
# 15 s of it from tests changed between the two runs).
# Not make test-slow, whose tests are seven in ten in one file (tests/analytic/test_contact_rates.py).
BY_FILE := --dist loadfile

# What every change passes before it is submitted (under 8 minutes from a fresh clone): everything but the tests
# marked slow, then the unit tests again as plain Python (NUMBA_DISABLE_JIT=1).
test: $(STAMP) $(BROWSER_STAMP)
	$(PYTEST) $(BY_FILE) -m "not slow"
	NUMBA_DISABLE_JIT=1 $(PYTEST) $(BY_FILE) tests/unit -m "not slow" -p no:cacheprovider

# The narrow phase, GJK/EPA and contact tests (the contact grid included), the mixed pile for 12 s at 240 Hz, the
# compiled flights and the sensors, run again with every array access bounds-checked: an index out of range raises
# IndexError instead of reading or writing memory it does not own.
BOUNDSCHECK_TESTS := tests/unit/test_gjk.py tests/unit/test_collide_convex.py tests/unit/test_collide_primitives.py \
	tests/unit/test_broad_phase.py tests/unit/test_contact_api.py tests/unit/test_query_overlap.py \
	tests/properties/test_convex_properties.py tests/properties/test_collide_properties.py \
	tests/analytic/test_contact.py tests/analytic/test_contact_rates.py \
	tests/analytic/test_shipped_scenes.py::test_the_mixed_pile_runs_12_s_at_240_hz_past_its_old_crash \
	tests/analytic/test_native_flight.py tests/analytic/test_sensors.py \
	tests/peers/test_mjcf_joint_physics.py tests/peers/test_mjcf_contacts.py tests/peers/test_locomotion_envs.py \
	tests/analytic/test_articulation_readout.py tests/unit/test_articulation_batch.py tests/unit/test_elementary.py

# The tests marked slow (every shipped scene at every rate, the long scenes), then the bounds-checked pass. Numba's
# cache does not tell a bounds-checked build from a plain one, so that pass compiles into a cache of its own.
test-slow: $(STAMP) $(BROWSER_STAMP)
	$(PYTEST) -m slow
	NUMBA_BOUNDSCHECK=1 NUMBA_CACHE_DIR=$(VENV)/numba-boundscheck $(PY) -m pytest -q -p no:cacheprovider \
		$(BOUNDSCHECK_TESTS)

bench: $(STAMP)
	$(PY) -m pip install --quiet -e ".[bench]"
	$(PY) -m benchmarks.run

# tumble's vector envs beside mjbatch (MuJoCo batched on C++ threads), which pins a MuJoCo of its own: its own venv.
bench-mjbatch:
	test -x .venv-mjbatch/bin/python || $(PYTHON) -m venv .venv-mjbatch
	.venv-mjbatch/bin/python -m pip install --quiet mjbatch gymnasium -e .
	.venv-mjbatch/bin/python -m benchmarks.beside_mjbatch

lint: $(STAMP)
	$(VENV)/bin/ruff check src tests benchmarks examples
	$(VENV)/bin/ruff format --check src tests benchmarks examples

clean:
	rm -rf $(VENV) .venv-mjbatch out .pytest_cache .ruff_cache
	find . -name __pycache__ -prune -exec rm -rf {} +
