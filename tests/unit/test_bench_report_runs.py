"""``hlvs bench report``: how many runs each kind gets, without running any (the runners are
replaced by recorders; ``tests/integration/api/test_bench_report.py`` runs real ones)."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from typing import Any

import pytest

from benchmarks import report


def _run(monkeypatch: pytest.MonkeyPatch, *argv: str) -> tuple[list[str], dict[str, Any]]:
    order: list[str] = []

    def runners(args: argparse.Namespace) -> dict[str, Callable[[], dict[str, Any]]]:
        def runner(kind: str) -> Callable[[], dict[str, Any]]:
            def run() -> dict[str, Any]:
                order.append(kind)
                return {"ratio": 1.0, "real_time_factor": 1.0, "total_s": 1.0}

            return run

        return {kind: runner(kind) for kind in report.KINDS}

    monkeypatch.setattr(report, "_runners", runners)
    args = report._parser().parse_args(list(argv))
    return order, report.run(args, lambda text: None)


def test_match_and_bringup_repeats_above_repeats_are_all_run(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    order, document = _run(monkeypatch, "--only", "sim,bringup,match", "--repeats", "1",
                           "--bringup-repeats", "2", "--match-repeats", "3")  # fmt: skip
    assert order == ["sim", "bringup", "match", "bringup", "match", "match"]
    assert len(document["match"]["runs"]) == 3 and document["match_repeats"] == 3
    assert len(document["bringup"]["runs"]) == 2 and len(document["sim"]["runs"]) == 1


def test_defaults_one_match_and_as_many_bringups_as_repeats(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    order, document = _run(monkeypatch, "--only", "sim,bringup,match", "--repeats", "2")
    assert order == ["sim", "bringup", "match", "sim", "bringup"]
    assert document["bringup_repeats"] == 2 and len(document["match"]["runs"]) == 1
