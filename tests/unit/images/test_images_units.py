"""Pure parts of the image and registry code: deletion planning, team rules, error wording,
content hashing, and the ECR login against an in-process AWS mock."""

from __future__ import annotations

from pathlib import Path

import pytest

from orchestrator.engine.images import RegistryLogin, _classify, registry_of
from orchestrator.errors import ImagePullError
from orchestrator.project_images import content_hash
from orchestrator.pull import split_reference
from orchestrator.registry import RegistryImage, TeamRule, plan_enforcement
from orchestrator.registry.client import _next_link


def image(repo: str, size: int) -> RegistryImage:
    return RegistryImage(
        repository=repo, digest=f"sha256:{repo}", tags=("v1",), size_bytes=size,
        team=repo.split("/")[0],
    )  # fmt: skip


IMAGES = [image("a/big", 500), image("a/x", 100), image("a/y", 100), image("a/z", 100),
          image("b/w", 300)]  # fmt: skip


def test_plan_deletes_oversize_images_first_then_until_team_under() -> None:
    plan = plan_enforcement(IMAGES, image_limit_bytes=400, team_limit_bytes=150, seed=1)
    assert plan[0].image.repository == "a/big" and plan[0].reason == "image_over_limit"
    team_a = [d.image.repository for d in plan[1:] if d.image.team == "a"]
    team_b = [d for d in plan if d.image.team == "b"]
    assert len(team_a) == 2 and set(team_a) < {"a/x", "a/y", "a/z"}
    assert len(team_b) == 1 and team_b[0].reason == "team_over_limit"


def test_plan_is_seeded_and_varies_with_the_seed() -> None:
    def run(seed: int) -> list[str]:
        plan = plan_enforcement(IMAGES, image_limit_bytes=400, team_limit_bytes=150, seed=seed)
        return [d.image.repository for d in plan]

    assert run(3) == run(3)
    assert len({tuple(run(seed)) for seed in range(20)}) > 1


def test_plan_within_limits_deletes_nothing() -> None:
    assert plan_enforcement(IMAGES, image_limit_bytes=500, team_limit_bytes=800, seed=0) == []


def test_team_rule() -> None:
    rule = TeamRule.parse(["cbr2021-bit-bots=bitbots"])
    assert rule.team("cbr2021-bit-bots") == "bitbots"
    assert rule.team("alpha/robot") == "alpha"
    with pytest.raises(ValueError, match="PREFIX=TEAM"):
        TeamRule.parse(["nonsense"])


def test_next_link() -> None:
    assert _next_link('</v2/_catalog?last=b&n=100>; rel="next"') == "/v2/_catalog?last=b&n=100"
    assert _next_link("") is None


@pytest.mark.parametrize(
    ("reference", "expected"),
    [
        ("127.0.0.1:5000/alpha/robot", "127.0.0.1:5000"),
        ("123.dkr.ecr.us-east-1.amazonaws.com/bots", "123.dkr.ecr.us-east-1.amazonaws.com"),
        ("localhost/x", "localhost"),
        ("alpha/robot", ""),
        ("robot", ""),
    ],
)
def test_registry_of(reference: str, expected: str) -> None:
    assert registry_of(reference) == expected


def test_split_reference() -> None:
    assert split_reference("127.0.0.1:5000/a/r:v1") == ("127.0.0.1:5000/a/r", "v1")
    assert split_reference("127.0.0.1:5000/a/r") == ("127.0.0.1:5000/a/r", "latest")


def test_classify_engine_messages() -> None:
    auth = RegistryLogin(username="alpha", password="x")
    ref = "127.0.0.1:5000/alpha/robot:v9"
    assert _classify(ref, "Head ...: no basic auth credentials", auth).startswith(
        "authentication failed for 127.0.0.1:5000 (user alpha)"
    )
    assert _classify(ref, "manifest unknown: manifest unknown", auth) == (
        "tag v9 not found in 127.0.0.1:5000/alpha/robot"
    )
    assert _classify(ref, "dial tcp 127.0.0.1:5000: connect: connection refused", None).startswith(
        "registry 127.0.0.1:5000 unreachable: "
    )


def test_content_hash_follows_every_input(tmp_path: Path) -> None:
    context = tmp_path / "context"
    (context / "wheels").mkdir(parents=True)
    (context / "src" / "simulator").mkdir(parents=True)
    (context / "Dockerfile").write_text("FROM x\n")
    (context / "src" / "simulator" / "a.py").write_text("A = 1\n")
    (context / "wheels" / "numpy-2.0-cp311.whl").write_bytes(b"zip")

    def current(base: str = "sha256:base", arg: str = "b") -> str:
        return content_hash("stub", context, base, {"BASE_IMAGE": arg})

    first = current()
    assert first == current() and len(first) == 12
    assert first != content_hash("team-base", context, "sha256:base", {"BASE_IMAGE": "b"})
    assert first != current(base="sha256:other")
    assert first != current(arg="c")
    (context / "wheels" / "numpy-2.0-cp311.whl").write_bytes(b"same name, other bytes")
    assert current() == first, "wheels count by name (their versions are pinned)"
    (context / "wheels" / "numpy-2.0-cp311.whl").rename(context / "wheels" / "numpy-2.1-cp311.whl")
    second = current()
    assert second != first
    (context / "src" / "simulator" / "a.py").write_text("A = 2\n")
    third = current()
    assert third != second
    (context / "Dockerfile").write_text("FROM y\n")
    assert current() != third


def test_ecr_login_decodes_the_token(monkeypatch: pytest.MonkeyPatch) -> None:
    moto = pytest.importorskip("moto")
    from orchestrator.ecr import ecr_login

    monkeypatch.setenv("AWS_ACCESS_KEY_ID", "testing")
    monkeypatch.setenv("AWS_SECRET_ACCESS_KEY", "testing")
    with moto.mock_aws():
        login = ecr_login(registry="123456789012.dkr.ecr.us-east-1.amazonaws.com",
                          region="us-east-1")  # fmt: skip
    assert login.username == "AWS"
    assert login.password


def test_ecr_login_failure_is_an_auth_error(monkeypatch: pytest.MonkeyPatch) -> None:
    from orchestrator.ecr import ecr_login

    monkeypatch.setenv("AWS_ENDPOINT_URL", "http://127.0.0.1:9")
    monkeypatch.setenv("AWS_MAX_ATTEMPTS", "1")
    with pytest.raises(ImagePullError) as caught:
        ecr_login(registry="123456789012.dkr.ecr.us-east-1.amazonaws.com", region="us-east-1",
                  access_id="a", access_secret="b")  # fmt: skip
    assert caught.value.reason.startswith(
        "authentication failed for 123456789012.dkr.ecr.us-east-1.amazonaws.com (user AWS)"
    )


def test_the_stub_is_built_on_team_base_and_downloads_nothing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from orchestrator import image_inputs
    from orchestrator.project_images import RECIPES

    assert RECIPES["stub"].parent == "team-base" and RECIPES["stub"].requirements == ()
    assert RECIPES["stub"].packages == ()
    assert RECIPES["team-base"].parent is None
    assert "FROM ${BASE_IMAGE}" in RECIPES["stub"].dockerfile.read_text()

    def no_download(*args: object, **kwargs: object) -> None:
        raise AssertionError("pip download ran for an empty requirement list")

    monkeypatch.setattr(image_inputs, "_run_logged", no_download)
    wheels = image_inputs.ensure_wheels((), cache_dir=tmp_path)
    assert (wheels / "requirements.txt").read_text() == ""
    assert not list(wheels.glob("*.whl"))
    assert image_inputs.ensure_wheels((), cache_dir=tmp_path) == wheels


def test_a_missing_mmdebstrap_is_a_clear_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from orchestrator import image_inputs
    from orchestrator.errors import ImageError

    monkeypatch.setattr(image_inputs.shutil, "which", lambda name: None)
    recipe = image_inputs.BaseRecipe(flavour="robot")
    with pytest.raises(ImageError) as raised:
        image_inputs.make_rootfs(recipe, work_dir=tmp_path, log_path=tmp_path / "log")
    assert "apt-get install mmdebstrap" in str(raised.value)
    assert recipe.reference in str(raised.value)
    assert recipe.key() != image_inputs.BaseRecipe(flavour="robot", suite="trixie").key()
