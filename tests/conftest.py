"""Shared test set-up: matplotlib draws off-screen."""

import matplotlib

matplotlib.use("Agg")
