# tumble: every target sets itself up from a bare Python 3.11.
PYTHON ?= python3.11
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
BROWSER_STAMP := $(VENV)/.browser

.PHONY: install demo test test-nojit bench lint clean

$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e ".[test,mesh,plot]"
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

test: $(STAMP) $(BROWSER_STAMP)
	$(PY) -m pytest -q
	NUMBA_DISABLE_JIT=1 $(PY) -m pytest -q tests/unit -m "not slow" -p no:cacheprovider

bench: $(STAMP)
	$(PY) -m pip install --quiet -e ".[bench]"
	$(PY) -m benchmarks.run

lint: $(STAMP)
	$(VENV)/bin/ruff check src tests benchmarks examples
	$(VENV)/bin/ruff format --check src tests benchmarks examples

clean:
	rm -rf $(VENV) out .pytest_cache .ruff_cache
	find . -name __pycache__ -prune -exec rm -rf {} +
