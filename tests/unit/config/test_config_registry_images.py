"""``registry_images`` (default: ``official``): ``hlvs check`` refuses team images named
without a registry, in the team file, with the field and how to push the image."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import pytest

from orchestrator.config.loader import check_game, load_game
from orchestrator.match import scrimmage


def _game(tmp_path: Path, *, red: str, game: dict[str, object]) -> Path:
    args = argparse.Namespace(
        red_image=red, blue_image="hlvs-runner/stub:0123456789ab", players=2,
        half_duration=10.0, minimum_play=0.0, wait_before_ready=1.0, grace=1.0, robot_command=None,
        match_id="m-registry", seed=1)
    path = scrimmage.write_files(scrimmage.ScrimmageRequest.from_options(args), tmp_path / "config")
    data = json.loads(path.read_text())
    data.update(game)
    path.write_text(json.dumps(data))
    return path


def test_a_bare_team_image_is_refused_where_the_game_wants_registry_images(
    tmp_path: Path,
) -> None:
    for setting in ({"registry_images": True}, {"official": True}):
        path = _game(tmp_path / str(len(setting)) / next(iter(setting)),
                     red="other-team/robot:v1", game=setting)
        errors = [p for p in check_game(path, images_required=True) if p.severity == "error"]
        assert [(Path(p.file).name, p.pointer) for p in errors] == [("team_red.json", "/image")]
        assert "other-team/robot:v1 names no registry" in errors[0].message
        assert "docker push REGISTRY/TEAM/robot" in errors[0].message


def test_registry_names_and_local_matches_pass(tmp_path: Path) -> None:
    registry = _game(tmp_path / "a", red="127.0.0.1:5000/red/robot:v1",
                     game={"registry_images": True})
    assert load_game(registry, images_required=True).game.registry_images
    local = _game(tmp_path / "b", red="my-robot:dev", game={})
    loaded = load_game(local, images_required=True)
    assert not loaded.game.registry_images  # a local match: the operator's own image plays
    opted_out = _game(tmp_path / "c", red="my-robot:dev",
                      game={"official": True, "registry_images": False})
    assert not load_game(opted_out, images_required=True).game.registry_images


def test_the_plan_carries_the_registries_hlvs_match_pulls_from(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import orchestrator
    from hlvs.commands.play import _pull_resolver
    from orchestrator.match import plan_from_game

    path = _game(tmp_path, red="127.0.0.1:5000/red/robot:v1", game={"registry_images": True})
    loaded = load_game(path, images_required=True)
    plan = plan_from_game(loaded)
    assert plan.registry is not None
    asked: list[tuple[object, ...]] = []

    def resolve(client: object, team: object, *, limits: object, progress: object,
                registry_only: bool) -> dict[int, object]:
        asked.append((client, team, limits, registry_only))
        return {}

    monkeypatch.setattr(orchestrator, "resolve_team_images", resolve)
    client = object()
    found = _pull_resolver(client, plan.registry)(plan)
    assert asked == [(client, loaded.red, loaded.game.limits, True),
                     (client, loaded.blue, loaded.game.limits, True)]
    assert found == {robot.key: (None, "no image named for this player") for robot in plan.robots}
