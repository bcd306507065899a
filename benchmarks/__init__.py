"""Benchmarks that print JSON, run as ``hlvs bench KIND`` (``python -m simulator bench KIND`` for
the simulator's own). Kept out of the production packages; the tests import nothing from here."""
