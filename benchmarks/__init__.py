"""Benchmarks that print JSON, run as ``hlvs bench KIND`` (``python -m benchmarks KIND`` for
the simulator's own). Kept out of the production packages; the tests import nothing from here."""

__all__: list[str] = []  # its public modules are listed in ARCHITECTURE.md (Public faces)
