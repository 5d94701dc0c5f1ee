"""Shared test set-up: matplotlib draws off-screen; hypothesis profiles.

Property-based tests run the "ci" profile by default: 200 examples per property,
a fifth of that for the properties that run a command or write a world folder
per example (``SLOW_PROPERTY``), so the whole suite stays within its time
budget. For a longer search (2,000 and 400), pass ``--hypothesis-profile=long``
or set ``HYPOTHESIS_PROFILE=long``.
"""

import os

import matplotlib
from hypothesis import HealthCheck, settings

matplotlib.use("Agg")

_SLOW_OK = [HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.function_scoped_fixture]
settings.register_profile("ci", max_examples=200, deadline=None, suppress_health_check=_SLOW_OK,
                          derandomize=True, print_blob=True)
settings.register_profile("long", max_examples=2_000, deadline=None, suppress_health_check=_SLOW_OK,
                          print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))


def slow_property() -> settings:
    """Settings for a property whose examples each cost a command run or a world folder: a fifth as many."""
    return settings(max_examples=max(20, settings.default.max_examples // 5))
