"""The groups ``make test`` hands to its pytest-xdist workers (tests/conftest.py)."""

from __future__ import annotations

from pathlib import Path

from tests.conftest import worker_group

TESTS = Path(__file__).resolve().parents[1]


def test_an_integration_folder_is_one_group_and_a_unit_module_its_own() -> None:
    pool = TESTS / "integration" / "pool"
    assert worker_group(pool / "test_node_failure.py") == "integration/pool"
    assert worker_group(pool / "test_pool_slurm.py") == "integration/pool"
    assert worker_group(TESTS / "integration" / "test_readme_commands.py") == (
        "integration/test_readme_commands.py")
    assert worker_group(TESTS / "unit" / "stub" / "test_stub_ready.py") == (
        "unit/stub/test_stub_ready.py")


def test_a_test_on_the_slurm_cluster_runs_with_the_pool_folder_wherever_it_lies() -> None:
    viewer = TESTS / "integration" / "viewer" / "test_viewer_pool_nodes.py"
    assert worker_group(viewer, ["tmp_path", "cluster", "page"]) == "integration/pool"
    assert worker_group(viewer, ["tmp_path", "page"]) == "integration/viewer"
