"""``remotes="slurm:N?..."``: parsing, the options, the batch script of a remote's job and the
node side's lease (no cluster needed; tests/integration/pool/test_env_remotes_slurm.py runs them
on the real one)."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from envs.errors import EnvConfigError
from envs.remote import parse_remotes, parse_slurm
from envs.remote_pool import RemotePool
from envs.slurm_node import Lease
from envs.slurm_pool import LEASE_S, SlurmLauncher, SlurmOptions


def test_count_and_options() -> None:
    assert parse_slurm("slurm:2") == (2, {})
    count, options = parse_slurm(
        "slurm:3?conf=/etc/slurm/slurm.conf&partition=sim&account=team_a&lease=30&cpus=2"
    )
    assert count == 3
    assert options == {"conf": "/etc/slurm/slurm.conf", "partition": "sim",
                       "account": "team_a", "lease": 30.0, "cpus": 2}  # fmt: skip
    made = SlurmOptions.from_query(options)
    assert (made.conf, made.partition, made.account, made.lease_s, made.cpus) == (
        "/etc/slurm/slurm.conf", "sim", "team_a", 30.0, 2)  # fmt: skip
    assert SlurmOptions.from_query({}).lease_s == LEASE_S


@pytest.mark.parametrize(
    ("text", "field", "expected"),
    [
        ("slurm:0", "remotes", "slurm:N"),
        ("slurm:two", "remotes", "slurm:N"),
        ("slurm:", "remotes", "slurm:N"),
        ("slurm:2?leas=5", "remotes 'slurm:2?leas=5': option", "keys: conf"),
        ("slurm:2?lease", "remotes 'slurm:2?lease': option", "keys: conf"),
        ("slurm:2?lease=soon", "remotes 'slurm:2?lease=soon': lease", "a float"),
        ("slurm:2?cpus=0", "remotes 'slurm:2?cpus=0': cpus", "> 0"),
    ],
)
def test_bad_slurm_remotes_name_the_option(text: str, field: str, expected: str) -> None:
    with pytest.raises(EnvConfigError) as error:
        parse_slurm(text)
    assert error.value.field == field and expected in error.value.expected


def test_a_misspelt_key_gets_a_suggestion() -> None:
    with pytest.raises(EnvConfigError) as error:
        parse_slurm("slurm:1?partiton=sim")
    assert error.value.suggestion == "partition"
    assert "did you mean 'partition'?" in str(error.value)


def test_the_pool_refuses_before_asking_slurm() -> None:
    with pytest.raises(EnvConfigError):
        RemotePool.open("slurm:0")
    # addresses keep their meaning: a host called "slurm" is not the cluster
    assert parse_remotes("hlvs://slurm:7700")[0].host == "slurm"


def test_the_job_script_runs_the_node_side(tmp_path: Path) -> None:
    options = SlurmOptions(dir=str(tmp_path), lease_s=12)
    local = SlurmLauncher(options, image="hlvs-runner/simulator:abc", python="/opt/py",
                          host_network=True)  # fmt: skip
    cluster = SlurmLauncher(options, image="hlvs-runner/simulator:abc", python="/opt/py",
                            host_network=False)  # fmt: skip
    try:
        folder = tmp_path / "job folder"
        script = local._script(folder)
        assert script.startswith("#!/bin/sh\nexec nsenter --net=/run/netns/hlvs-host /opt/py -m "
                                 "envs.slurm_node --image hlvs-runner/simulator:abc")  # fmt: skip
        assert f"--job-dir '{folder}'" in script and "--advertise bridge" in script
        assert "--lease-s 12" in script
        remote = cluster._script(folder)
        assert "nsenter" not in remote and "--advertise node" in remote
        assert local.root.parent == tmp_path and local.root.is_dir()
    finally:
        local.close()  # no job submitted: nothing to cancel
        cluster.close()
    assert local.root.is_dir()  # a folder the user named is kept (the logs are there)


def test_the_lease_expires_only_when_the_file_stops_changing(tmp_path: Path) -> None:
    path = tmp_path / "lease"
    path.write_text("0")
    lease = Lease(path, 0.3)
    for stamp in range(4):
        time.sleep(0.15)
        path.write_text(str(stamp + 1))  # renewed
        assert not lease.expired()
    time.sleep(0.4)
    assert lease.expired()



def test_a_missing_slurm_conf_is_named_at_once(tmp_path: Path) -> None:
    conf = tmp_path / "missing" / "slurm.conf"
    with pytest.raises(EnvConfigError) as error:
        SlurmLauncher(SlurmOptions(conf=str(conf)), image="x:1", host_network=False)
    assert error.value.field == "remotes conf" and error.value.value == str(conf)


def test_slurm_refusing_a_job_is_a_remote_start_failure(tmp_path: Path) -> None:
    from cluster.errors import PoolError
    from envs.errors import RemoteStartFailed

    launcher = SlurmLauncher(SlurmOptions(dir=str(tmp_path)), image="x:1", host_network=False)

    def refuse(*_args: object, **_kwargs: object) -> str:  # sbatch at the boundary
        raise PoolError(handle=str(tmp_path), reason="sbatch --parsable: exit 1: Invalid account")

    launcher.slurm.submit_script = refuse  # type: ignore[method-assign]
    try:
        with pytest.raises(RemoteStartFailed) as failed:
            launcher.start(1)
        assert failed.value.reason.endswith("Invalid account")
        assert failed.value.address == f"Slurm ({tmp_path})"
    finally:
        launcher.close()
