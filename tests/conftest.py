"""Shared test configuration: hypothesis profiles (``dev`` by default, ``ci`` when CI=true)."""

from __future__ import annotations

import os

from hypothesis import HealthCheck, settings

# deadline=None: the first example of a test may include Numba compilation.
settings.register_profile("dev", max_examples=50, deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("ci", max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci" if os.environ.get("CI") else "dev"))
