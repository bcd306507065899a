"""Registry pieces without a registry: challenges, scopes, the token cache, retries with backoff,
sizes with shared layers, image names, and the progress lines written when not on a terminal."""

from __future__ import annotations

import io
import random

import pytest

from orchestrator.console import PlainProgress, PullTracker, progress
from orchestrator.engine.images import PullEvent, _transient
from orchestrator.registry import RegistryImage, parse_challenges, plan_enforcement, stored_bytes
from orchestrator.registry.auth import TokenCache, scope_for
from orchestrator.registry.remote import registry_url, split_image
from orchestrator.retry import Backoff, retry


def test_bearer_challenge_with_commas_in_the_scope() -> None:
    (challenge,) = parse_challenges(
        'Bearer realm="https://auth.example/token",service="registry.example",'
        'scope="repository:team/robot:pull,push"'
    )
    assert challenge.scheme == "bearer"
    assert challenge.realm == "https://auth.example/token"
    assert challenge.params["service"] == "registry.example"
    assert challenge.params["scope"] == "repository:team/robot:pull,push"


def test_several_challenges_and_escapes() -> None:
    basic, bearer = parse_challenges('Basic realm="a \\"quoted\\" realm", Bearer realm="t",x=y')
    assert (basic.scheme, basic.realm) == ("basic", 'a "quoted" realm')
    assert (bearer.scheme, bearer.realm, bearer.params["x"]) == ("bearer", "t", "y")
    assert parse_challenges("") == []


@pytest.mark.parametrize(
    ("method", "path", "scope"),
    [
        ("GET", "/v2/_catalog?n=100", "registry:catalog:*"),
        ("GET", "/v2/team/robot/tags/list?n=2", "repository:team/robot:pull"),
        ("HEAD", "/v2/a/b/c/manifests/v1", "repository:a/b/c:pull"),
        ("DELETE", "/v2/team/robot/manifests/sha256:00", "repository:team/robot:delete"),
        ("GET", "/v2/", ""),
    ],
)
def test_scope_for(method: str, path: str, scope: str) -> None:
    assert scope_for(method, path) == scope


def test_token_cache_expiry_and_default_lifetime() -> None:
    now = [100.0]
    cache = TokenCache(clock=lambda: now[0])
    key = ("realm", "service", "repository:a/b:pull")
    cache.put(key, "t1", expires_in_s=300)
    assert cache.get(key) == "t1"
    now[0] += 294.9  # fetched again 5 s before it expires
    assert cache.get(key) == "t1"
    now[0] += 0.2
    assert cache.get(key) is None
    cache.put(key, "t2", expires_in_s=None)  # the specification's default: 60 s
    now[0] += 54.9
    assert cache.get(key) == "t2"
    now[0] += 0.2
    assert cache.get(key) is None
    cache.put(key, "t2", expires_in_s=10)  # short tokens: renewed 10 % before their end
    now[0] += 8.9
    assert cache.get(key) == "t2"
    now[0] += 0.2
    assert cache.get(key) is None
    cache.put(key, "t3", expires_in_s=300)
    cache.drop(key)
    assert cache.get(key) is None


def test_retry_backs_off_with_jitter_and_stops_on_permanent_errors() -> None:
    slept: list[float] = []
    backoff = Backoff(attempts=4, base_s=1.0, cap_s=3.0, sleep=slept.append,
                      rng=random.Random(5))
    calls = iter([OSError("reset"), OSError("reset"), "ok"])

    def call() -> str:
        value = next(calls)
        if isinstance(value, Exception):
            raise value
        return value

    assert retry(call, transient=lambda e: isinstance(e, OSError), backoff=backoff,
                 what="x") == "ok"
    assert len(slept) == 2 and 0 <= slept[0] <= 1.0 and 0 <= slept[1] <= 2.0
    assert len({Backoff(rng=random.Random(s)).delay_s(3) for s in range(10)}) > 1  # jitter
    assert all(Backoff(cap_s=3.0).delay_s(10) <= 3.0 for _ in range(50))  # capped

    def permanent() -> str:
        raise ValueError("no")

    slept.clear()
    with pytest.raises(ValueError):
        retry(permanent, transient=lambda e: isinstance(e, OSError), backoff=backoff, what="x")
    assert slept == []

    def always() -> str:
        raise OSError("down")

    with pytest.raises(OSError):
        retry(always, transient=lambda e: True, backoff=backoff, what="x")
    assert len(slept) == 3  # 4 attempts, 3 waits
    with pytest.raises(ValueError):
        Backoff(attempts=0)


def test_engine_messages_that_are_worth_a_retry() -> None:
    assert _transient("received unexpected HTTP status: 503 Service Unavailable")
    assert _transient("Get https://r/v2/: dial tcp 10.0.0.1:443: i/o timeout")
    assert _transient("read tcp: connection reset by peer")
    assert not _transient("unauthorized: authentication required")
    assert not _transient("manifest unknown")
    assert not _transient("http: server gave HTTP response to HTTPS client")


def image(repo: str, blobs: dict[str, int]) -> RegistryImage:
    return RegistryImage(repository=repo, digest=f"sha256:{repo}", tags=("v1",),
                         size_bytes=sum(blobs.values()), team=repo.split("/")[0], blobs=blobs)


def test_shared_layers_count_once_per_team() -> None:
    base = {"sha256:base": 800}
    images = [image("a/x", {**base, "sha256:x": 100}), image("a/y", {**base, "sha256:y": 100}),
              image("b/z", {**base, "sha256:z": 100})]
    assert stored_bytes(images[:2]) == 1000  # not 1800
    assert plan_enforcement(images, image_limit_bytes=900, team_limit_bytes=1000, seed=0) == []
    plan = plan_enforcement(images, image_limit_bytes=900, team_limit_bytes=999, seed=0)
    assert [d.image.team for d in plan] == ["a"] and plan[0].reason == "team_over_limit"


@pytest.mark.parametrize(
    ("reference", "parts"),
    [
        ("127.0.0.1:5000/alpha/robot:v1", ("127.0.0.1:5000", "alpha/robot", "v1")),
        ("ghcr.io/team/robot", ("ghcr.io", "team/robot", "latest")),
        ("localhost/robot:2", ("localhost", "robot", "2")),
        ("team/robot:v2", ("registry-1.docker.io", "team/robot", "v2")),
        ("ubuntu", ("registry-1.docker.io", "library/ubuntu", "latest")),
        ("reg.example:5000/a/b@sha256:00ff", ("reg.example:5000", "a/b", "sha256:00ff")),
    ],
)
def test_split_image(reference: str, parts: tuple[str, str, str]) -> None:
    assert split_image(reference) == parts


def test_registry_url_plain_http_only_on_loopback_or_when_asked() -> None:
    assert registry_url("127.0.0.1:5000", {}) == "http://127.0.0.1:5000"
    assert registry_url("localhost:5000", {}) == "http://localhost:5000"
    assert registry_url("ghcr.io", {}) == "https://ghcr.io"
    assert registry_url("reg.lan:5000", {"HLVS_INSECURE_REGISTRIES": "reg.lan:5000"}) == (
        "http://reg.lan:5000"
    )


def test_plain_progress_prints_periodic_lines_and_the_end() -> None:
    out = io.StringIO()
    now = [0.0]
    bars = PlainProgress(out=out, interval_s=10.0, clock=lambda: now[0])
    task = bars.add("pull team/robot:v1")
    tracker = PullTracker(task)
    tracker(PullEvent(layer="a", status="Downloading", current=1_000_000, total=4_000_000))
    now[0] = 11.0
    tracker(PullEvent(layer="b", status="Downloading", current=1_000_000, total=4_000_000))
    now[0] = 12.0
    tracker(PullEvent(layer="a", status="Download complete"))  # within 10 s: no line
    tracker(PullEvent(layer="b", status="Pull complete"))
    task.finish()
    lines = out.getvalue().splitlines()
    assert lines == [
        "pull team/robot:v1: started",
        "pull team/robot:v1: 2.0 MB of 8.0 MB (25 %)",
        "pull team/robot:v1: done, 8.0 MB, 12.0 s",
    ]


def test_progress_is_plain_when_not_a_terminal(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("HLVS_PROGRESS", raising=False)
    out = io.StringIO()
    with progress(stream=out) as bars:
        assert isinstance(bars, PlainProgress)
    monkeypatch.setenv("HLVS_PROGRESS", "off")
    with progress(stream=out) as bars:
        bars.add("quiet").finish()
    assert "quiet" not in out.getvalue()


def test_rich_progress_draws_bars(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("HLVS_PROGRESS", "rich")
    out = io.StringIO()
    with progress(stream=out) as bars:
        pull = bars.add("pull team/robot:v1")
        PullTracker(pull)(PullEvent(layer="a", status="Downloading", current=5_000_000,
                                    total=10_000_000))
        pull.finish()
        build = bars.add("build simulator", unit="steps")
        build.update(completed=3, total=9)
        build.finish()
    drawn = out.getvalue()
    assert "pull team/robot:v1 (done)" in drawn and "10.0/10.0 MB" in drawn
    assert "build simulator (done)" in drawn and "9/9 steps" in drawn


def test_retry_waits_at_least_what_the_server_asks_up_to_the_cap() -> None:
    slept: list[float] = []
    backoff = Backoff(attempts=3, base_s=0.1, cap_s=5.0, sleep=slept.append)
    errors = iter([RuntimeError("429"), RuntimeError("429")])

    def call() -> str:
        error = next(errors, None)
        if error is not None:
            raise error
        return "ok"

    hints = iter([2.0, 60.0])
    assert retry(call, transient=lambda e: True, backoff=backoff, what="x",
                 wait_hint=lambda e: next(hints)) == "ok"
    assert slept == [2.0, 5.0]
