"""The groups ``make test`` hands to its pytest-xdist workers (tests/conftest.py)."""

from __future__ import annotations

from pathlib import Path

from tests.conftest import LONG_GROUPS_FIRST, ONE_OF_A_KIND, worker_group

TESTS = Path(__file__).resolve().parents[1]


def test_an_integration_folder_is_one_group_and_a_unit_module_its_own() -> None:
    assert worker_group("tests/integration/pool/test_node_failure.py::test_a") == (
        "integration/pool")
    assert worker_group("tests/integration/pool/test_pool_slurm.py::test_b[x-1]") == (
        "integration/pool")
    assert worker_group("tests/integration/test_readme_commands.py::test_c[README.md:20]") == (
        "integration/test_readme_commands.py")
    assert worker_group("tests/unit/stub/test_stub_ready.py::test_d") == (
        "unit/stub/test_stub_ready.py")


def test_the_pool_page_on_the_slurm_cluster_runs_with_the_pool_folder() -> None:
    assert worker_group(
        "tests/integration/viewer/test_viewer_pool_nodes.py::test_the_pool_page[x]"
    ) == "integration/pool"
    assert worker_group("tests/integration/viewer/test_viewer_live.py::test_e") == (
        "integration/viewer")


def test_every_test_file_on_the_slurm_cluster_outside_its_folder_is_in_its_group() -> None:
    uses = "from tests.integration.pool.conftest import " + "cluster"  # (not this file)
    users = {
        path.relative_to(TESTS).as_posix()
        for path in TESTS.rglob("test_*.py")
        if uses in path.read_text()
        and path.parent != TESTS / "integration" / "pool"
    }
    assert users, "no test outside tests/integration/pool uses the cluster: is the import gone?"
    assert {path: ONE_OF_A_KIND.get(path) for path in users} == dict.fromkeys(
        users, "integration/pool")


def test_the_groups_handed_out_first_are_groups_that_exist() -> None:
    """A renamed folder would silently fall back to collection order."""
    for group in LONG_GROUPS_FIRST:
        assert (TESTS / group).exists(), group
        assert worker_group(f"tests/{group}" + ("" if group.endswith(".py") else "/test_x.py")
                            + "::test") == group
