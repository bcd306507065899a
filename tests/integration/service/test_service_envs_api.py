"""The HTTP environment API mounted in the real service (uvicorn on loopback, httpx client)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from envs.http_client import EnvApiError, EnvClient
from tests.integration.service.conftest import TokenMaker
from tests.integration.service.harness import Served


def test_an_episode_with_a_token_monitor_files_and_limits(
    served: Served, make_token: TokenMaker, tmp_path: Path
) -> None:
    token = make_token(team="Kickers")
    with EnvClient(served.url, token=token) as client:
        instance = client.env_create("hlvs/Kick-v0", max_episode_s=0.4, perception=True)
        assert client.env_list_all() == {instance: "hlvs/Kick-v0"}
        assert client.env_action_space_info(instance)["shape"] == [20]
        # gym-http-api's client signature: (instance_id, directory, force, resume, video_callable)
        client.env_monitor_start(instance, str(tmp_path / "monitor"), False, False, True)
        obs = client.env_reset(instance, seed=3)
        assert len(obs["joints"]) == 20 and len(obs["perception"]["lines"]) == 33
        done, steps, info = False, 0, {}
        while not done:
            obs, reward, done, info = client.env_step(instance, [0.0] * 20)
            steps += 1
        assert steps == 50 and info["sim_time_ms"] == 400
        stats = client.env_monitor_close(instance)
        assert stats["episodes"] == 1 and stats["steps"] == 50
        assert stats["video"], stats["video_error"]
        names = {f["name"]: f["bytes"] for f in client.monitor_files(instance)}
        assert {"episodes.jsonl", "stats.json", "video.mp4"} <= set(names)
        assert {p.name for p in (tmp_path / "monitor").iterdir()} == set(names)
        episodes = client.download(instance, "episodes.jsonl", tmp_path / "episodes.jsonl")
        line = json.loads(episodes.read_text().splitlines()[0])
        assert line["steps"] == 50 and line["truncated"] is True
        video = client.download(instance, "video.mp4", tmp_path / "video.mp4")
        assert video.stat().st_size == names["video.mp4"] > 1000
        second = client.env_create("hlvs/Match-v0", half_duration_s=5.0,
                                   minimum_play_s=0.0)
        with pytest.raises(EnvApiError) as limit:
            client.env_create("hlvs/Kick-v0")
        assert limit.value.status == 409 and "limit" in limit.value.message
        with EnvClient(served.url, token=make_token(team="Kickers")) as other_token:
            third = other_token.env_create("hlvs/Kick-v0")  # the limit is per token
            other_token.env_close(third)
        client.env_close(second)
        client.env_close(instance)
        assert client.env_list_all() == {}
        assert client.monitor_files(instance)  # still downloadable after close
        with pytest.raises(EnvApiError) as gone:
            client.env_step(instance, [0.0] * 20)
        assert gone.value.status == 404


def test_without_a_token_or_with_another_teams_token_nothing_runs(
    served: Served, make_token: TokenMaker
) -> None:
    with EnvClient(served.url, token=None) as anonymous:
        with pytest.raises(EnvApiError) as refused:
            anonymous.env_create("hlvs/Kick-v0")
        assert refused.value.status == 401
    with (
        EnvClient(served.url, token=make_token(team="A")) as a,
        EnvClient(served.url, token=make_token(team="B")) as b,
    ):
        instance = a.env_create("hlvs/Kick-v0")
        with pytest.raises(EnvApiError) as hidden:
            b.env_reset(instance, seed=1)
        assert hidden.value.status == 404
        with pytest.raises(EnvApiError) as bad:
            a.env_create("hlvs/Kik-v0")
        assert bad.value.status == 422 and "hlvs/Kick-v0" in bad.value.message
        with pytest.raises(EnvApiError) as option:
            a.env_create("hlvs/Kick-v0", remotes=4)
        assert option.value.status == 422 and "remotes" in option.value.message
        a.env_reset(instance, seed=1)
        with pytest.raises(EnvApiError) as shape:
            a.env_step(instance, [0.0] * 3)
        assert shape.value.status == 422 and "action" in shape.value.message
        a.env_close(instance)


def test_idle_environments_are_closed_for_new_ones(
    settings: object, make_token: TokenMaker, monkeypatch: pytest.MonkeyPatch
) -> None:
    import time

    from tests.integration.service.harness import serve

    monkeypatch.setenv("HLVS_ENVS_PER_TOKEN", "1")
    monkeypatch.setenv("HLVS_ENVS_IDLE_S", "0.5")
    served = serve(settings)  # type: ignore[arg-type]
    try:
        with EnvClient(served.url, token=make_token(team="Idle")) as client:
            first = client.env_create("hlvs/Kick-v0")
            time.sleep(1.0)
            second = client.env_create("hlvs/Kick-v0")  # the idle one made room
            with pytest.raises(EnvApiError) as gone:
                client.env_reset(first)
            assert gone.value.status == 404
            client.env_close(second)
    finally:
        served.stop()
