"""The pool's nodes: Slurm's host lists and node/job listings parsed, the local pool's host with
the match processes it runs."""

from __future__ import annotations

import json
import os
import socket
import stat
import time
from pathlib import Path

import pytest

from cluster import MatchJob
from cluster.local import LocalDockerPool
from cluster.nodes import (
    ENV_REMOTE_COMMENT,
    expand_hostlist,
    parse_sinfo,
    parse_squeue_nodes,
)
from cluster.slurm import _merged, _parse_entry


@pytest.mark.parametrize(("text", "names"), [
    ("n1", ["n1"]),
    ("n[1-3,5]", ["n1", "n2", "n3", "n5"]),
    ("n[01-03],gpu7", ["n01", "n02", "n03", "gpu7"]),
    ("rack[1-2]-n[1-2]", ["rack1-n1", "rack1-n2", "rack2-n1", "rack2-n2"]),
    ("", []),
])  # fmt: skip
def test_host_lists(text: str, names: list[str]) -> None:
    assert expand_hostlist(text) == names


def test_a_bad_host_list_names_the_part() -> None:
    with pytest.raises(ValueError, match=r"'x-2' is not a number or a range"):
        expand_hostlist("n[x-2]")


SINFO = """n1|allocated|2/0/0/2|4000|12001|1.50|dense,sim,robot|none
n2|drained|0/0/2/2|4000|N/A|N/A|dense|disk | full [root@2026-11-23T10:00:00]
n2|drained|0/0/2/2|4000|N/A|N/A|dense|disk | full [root@2026-11-23T10:00:00]
n3|idle|0/2/0/2|8000|7000|0.02|(null)|none
"""


def test_sinfo_nodes() -> None:
    nodes = parse_sinfo(SINFO)
    assert [n.name for n in nodes] == ["n1", "n2", "n3"]  # n2 in two partitions: once
    n1, n2, n3 = nodes
    assert (n1.state, n1.reason, n1.features, n1.cpus, n1.cpus_allocated, n1.cpu_load,
            n1.memory_mb, n1.memory_free_mb, n1.slots) == \
        ("allocated", "", ("dense", "sim", "robot"), 2, 2, 1.5, 4000, 12001, 1)
    assert (n2.state, n2.reason, n2.cpu_load, n2.memory_free_mb) == \
        ("drained", "disk | full [root@2026-11-23T10:00:00]", None, None)
    assert n3.features == ()


def test_a_bad_sinfo_line_says_what_was_expected() -> None:
    with pytest.raises(ValueError, match=r"expected 8 fields"):
        parse_sinfo("n1|idle|2\n")
    with pytest.raises(ValueError, match=r"CPUs '2', expected A/I/O/T"):
        parse_sinfo("n1|idle|2|4000|1|0.1|x|none\n")


def test_squeue_jobs_per_node() -> None:
    jobs = parse_squeue_nodes(
        "41|hlvs-m-7|RUNNING|n1\n42|other|RUNNING|n[2-3]\n43|hlvs-m-8|PENDING|\n"
        "44|hlvs-m-9|COMPLETING|n3\n"
    )
    assert {node: [(j.job_id, j.match_id, j.state) for j in js] for node, js in jobs.items()} \
        == {"n1": [("41", "m-7", "RUNNING")], "n2": [("42", None, "RUNNING")],
            "n3": [("42", None, "RUNNING"), ("44", "m-9", "COMPLETING")]}


def test_an_environment_remote_job_is_not_a_match() -> None:
    jobs = parse_squeue_nodes(
        f"51|hlvs-env-ab12-0|RUNNING|n4|{ENV_REMOTE_COMMENT}\n52|hlvs-env-x|RUNNING|n5|\n"
    )
    assert [(j.job_id, j.match_id) for j in jobs["n4"]] == [("51", None)]
    assert [(j.job_id, j.match_id) for j in jobs["n5"]] == [("52", "env-x")]  # a match's id


def test_queue_entries_say_their_kind_and_merge_league_components() -> None:
    lines = [f"60|hlvs-env-ab12-0|root|RUNNING|None|2026-11-23T15:00:00|n1|{ENV_REMOTE_COMMENT}",
             "61+0|hlvs-league-1|team_a|RUNNING|None|2026-11-23T15:01:00|n2|",
             "61+1|hlvs-league-1|team_a|RUNNING|None|2026-11-23T15:01:00|n3|"]
    env, league = _merged(_parse_entry(line) for line in lines)
    assert env.to_json() == {
        "job_id": "60", "kind": "environment", "match_id": None, "account": "root",
        "state": "RUNNING", "reason": "None", "expected_start": "2026-11-23T15:00:00",
        "nodes": "n1"}
    assert (league.job_id, league.kind, league.nodes) == ("61", "match", "n2,n3")
    assert league.to_json()["match_id"] == "league-1"


def test_the_local_pool_is_this_host_with_its_match_processes(tmp_path: Path) -> None:
    fake_python = tmp_path / "python"  # stands for 'python -m orchestrator match ...'
    fake_python.write_text("#!/bin/sh\nexec sleep 60\n")
    fake_python.chmod(fake_python.stat().st_mode | stat.S_IXUSR)
    pool = LocalDockerPool(slots=2, python=str(fake_python))
    (node,) = pool.nodes()
    assert (node.name, node.state, node.slots, node.jobs) == (socket.gethostname(), "up", 2, ())
    assert node.cpus == os.cpu_count() and node.memory_mb > 0
    assert node.memory_free_mb is not None and 0 < node.memory_free_mb <= node.memory_mb
    game = tmp_path / "game.json"
    game.write_text("{}")
    handle = pool.submit(MatchJob(match_id="m-local", game_path=game, work_dir=tmp_path / "w"))
    try:
        (node,) = pool.nodes()
        pid = json.loads((tmp_path / "w" / "pool.json").read_text())["pid"]
        assert [(j.job_id, j.match_id, j.state) for j in node.jobs] == \
            [(str(pid), "m-local", "running")]
        # a new service process learns of it from its status query
        later = LocalDockerPool(slots=2)
        assert later.nodes()[0].jobs == ()
        later.status(handle)
        assert [j.match_id for j in later.nodes()[0].jobs] == ["m-local"]
    finally:
        os.kill(pid, 15)
    deadline = time.monotonic() + 10
    while pool.nodes()[0].jobs and time.monotonic() < deadline:
        time.sleep(0.05)
    assert pool.nodes()[0].jobs == ()
