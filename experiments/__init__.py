"""Experiments behind the figures in docs/: benchmarks and studies run as `python -m experiments.NAME` from the
repository root. They use the radar_cli package; nothing in the package imports them."""
