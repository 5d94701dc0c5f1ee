"""Shared test set-up: matplotlib draws off-screen; hypothesis profiles.

Property-based tests run the "ci" profile by default (a bounded number of
examples per property, so the whole suite stays within its time budget). For a
longer search, run ``python -m pytest -q --hypothesis-profile=long tests/core/test_properties.py
tests/sim/world/test_world_properties.py`` (or set ``HYPOTHESIS_PROFILE=long``).
"""

import os

import matplotlib
from hypothesis import HealthCheck, settings

matplotlib.use("Agg")

_SLOW_OK = [HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.function_scoped_fixture]
settings.register_profile("ci", max_examples=40, deadline=None, suppress_health_check=_SLOW_OK,
                          derandomize=True, print_blob=True)
settings.register_profile("long", max_examples=2_000, deadline=None, suppress_health_check=_SLOW_OK,
                          print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))
