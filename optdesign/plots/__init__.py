"""Plots (matplotlib, Agg back-end: files only, no screen needed)."""

import matplotlib

matplotlib.use("Agg")
