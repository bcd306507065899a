"""Log sets with a fake uploader: enqueue, manifest last, skip, retry policy, retention."""

from __future__ import annotations

import io
import json
import re
from collections import deque
from pathlib import Path

import pytest

from orchestrator.config.credentials import Credentials
from orchestrator.console import PlainProgress
from orchestrator.delivery import (
    KEEP_UNDELIVERED,
    MANIFEST_NAME,
    FakeUploader,
    RetryPolicy,
    Uploader,
    deliver_pending,
    enqueue_match_logs,
    pending_status,
)
from orchestrator.errors import DeliveryError

FAST = RetryPolicy(attempts=3, initial_delay_s=0.5, factor=2.0, max_delay_s=10.0)


def make_match(root: Path, match_id: str) -> Path:
    match = root / match_id
    for color in ("red", "blue"):
        (match / "teams" / color / "red-1" / "robocup-logs").mkdir(parents=True)
        (match / "teams" / color / "red-1" / "stdout.log").write_text(f"{color} out\n")
        (match / "teams" / color / "red-1" / "robocup-logs" / "a.bin").write_bytes(b"x" * 1000)
    (match / "sim_result.json").write_text("{}")
    (match / "referee.log").write_text("log\n")
    return match


@pytest.fixture
def creds(tmp_path: Path) -> Path:
    path = tmp_path / "creds.json"
    path.write_text(
        json.dumps(
            {
                "type": "s3",
                "credentials": {"access_id": "id", "access_secret": "secret", "bucket": "logs"},
            }
        )
    )
    path.chmod(0o600)
    return path


class Opener:
    def __init__(self, uploader: FakeUploader) -> None:
        self.uploader = uploader
        self.opened = 0

    def __call__(self, credentials: Credentials, team: str) -> Uploader:
        self.opened += 1
        return self.uploader


def error(kind: str) -> DeliveryError:
    return DeliveryError(team="t", target="fake", kind=kind, reason=f"{kind} happened")


def test_enqueue_then_deliver_uploads_files_then_manifest(tmp_path: Path, creds: Path) -> None:
    match = make_match(tmp_path, "m1")
    store = tmp_path / "store"
    sets = enqueue_match_logs(
        match,
        match_id="m1",
        teams={"red": ("Alpha", creds), "blue": ("Beta", creds)},
        public_target=creds,
        store=store,
    )
    assert sorted(s.team for s in sets) == ["Alpha", "Beta", "public"]
    assert not (match / "teams" / "red").exists()  # team logs moved into the store
    assert (match / "sim_result.json").exists()  # public logs stay with the match
    fake = FakeUploader()
    lines = io.StringIO()
    outcomes = deliver_pending(store, opener=Opener(fake), retry=FAST, sleep=lambda s: None,
                               progress=PlainProgress(out=lines))
    assert all(o.delivered for o in outcomes)
    assert pending_status(store) == []
    alpha_bytes = next(o.uploaded_bytes for o in outcomes if o.team == "Alpha")
    assert "upload m1 Alpha: started" in lines.getvalue().splitlines()
    assert re.search(rf"^upload m1 Alpha: done, {alpha_bytes / 1e6:.1f} MB, ", lines.getvalue(),
                     re.M)
    alpha = [c for c in fake.calls if c.startswith("m1/Alpha/")]
    assert alpha[-1] == f"m1/Alpha/{MANIFEST_NAME}"
    manifest = json.loads(fake.files[f"m1/Alpha/{MANIFEST_NAME}"])
    assert {f["path"] for f in manifest["files"]} == {
        "red-1/stdout.log",
        "red-1/robocup-logs/a.bin",
    }
    for entry in manifest["files"]:
        assert fake.sha256(f"m1/Alpha/{entry['path']}") == entry["sha256"]
    assert "m1/public/referee.log" in fake.files
    assert not any(c.startswith("m1/public/teams/") for c in fake.calls)


def test_files_already_there_are_skipped(tmp_path: Path, creds: Path) -> None:
    match = make_match(tmp_path, "m1")
    store = tmp_path / "store"
    enqueue_match_logs(
        match, match_id="m1", teams={"red": ("Alpha", creds)}, public_target=None, store=store
    )
    fake = FakeUploader(files={"m1/Alpha/red-1/stdout.log": b"red out\n"})
    [outcome] = deliver_pending(store, opener=Opener(fake), retry=FAST)
    assert (outcome.uploaded_files, outcome.skipped_files) == (1, 1)
    assert "m1/Alpha/red-1/stdout.log" not in fake.calls


def test_transient_errors_are_retried_with_backoff(tmp_path: Path, creds: Path) -> None:
    store = tmp_path / "store"
    enqueue_match_logs(
        make_match(tmp_path, "m1"),
        match_id="m1",
        teams={"red": ("Alpha", creds)},
        public_target=None,
        store=store,
    )
    fake = FakeUploader(failures=deque([error("transient"), error("unreachable")]))
    opener = Opener(fake)
    sleeps: list[float] = []
    [outcome] = deliver_pending(store, opener=opener, retry=FAST, sleep=sleeps.append)
    assert outcome.delivered and sleeps == [0.5, 1.0] and opener.opened == 3


def test_transient_errors_exhausting_retries_leave_the_set_pending(
    tmp_path: Path, creds: Path
) -> None:
    store = tmp_path / "store"
    enqueue_match_logs(
        make_match(tmp_path, "m1"),
        match_id="m1",
        teams={"red": ("Alpha", creds)},
        public_target=None,
        store=store,
    )
    fake = FakeUploader(failures=deque([error("transient")] * 3))
    [outcome] = deliver_pending(store, opener=Opener(fake), retry=FAST, sleep=lambda s: None)
    assert not outcome.delivered and outcome.error is not None
    assert outcome.error.kind == "transient" and outcome.error.team == "Alpha"
    [pending] = pending_status(store)
    assert pending.attempts == 1 and pending.last_error is not None
    assert pending.last_error.kind == "transient"
    [outcome] = deliver_pending(store, opener=Opener(fake), retry=FAST, sleep=lambda s: None)
    assert outcome.delivered and pending_status(store) == []


@pytest.mark.parametrize("kind", ["auth", "host_key", "bucket", "access_denied", "path"])
def test_permanent_errors_are_not_retried(tmp_path: Path, creds: Path, kind: str) -> None:
    store = tmp_path / "store"
    enqueue_match_logs(
        make_match(tmp_path, "m1"),
        match_id="m1",
        teams={"red": ("Alpha", creds)},
        public_target=None,
        store=store,
    )
    fake = FakeUploader(failures=deque([error(kind)]))
    sleeps: list[float] = []
    [outcome] = deliver_pending(store, opener=Opener(fake), retry=FAST, sleep=sleeps.append)
    assert outcome.error is not None and outcome.error.kind == kind and sleeps == []
    assert len(fake.calls) == 1
    assert pending_status(store)[0].last_error.kind == kind  # type: ignore[union-attr]


def test_team_without_credentials_stays_pending(tmp_path: Path) -> None:
    store = tmp_path / "store"
    enqueue_match_logs(
        make_match(tmp_path, "m1"),
        match_id="m1",
        teams={"red": ("Alpha", None)},
        public_target=None,
        store=store,
    )
    [outcome] = deliver_pending(store, opener=Opener(FakeUploader()), retry=FAST)
    assert outcome.error is not None and outcome.error.kind == "config"
    assert len(pending_status(store)) == 1


def test_only_the_three_newest_undelivered_sets_of_a_team_are_kept(
    tmp_path: Path, creds: Path, caplog: pytest.LogCaptureFixture
) -> None:
    store = tmp_path / "store"
    for i in range(5):
        enqueue_match_logs(
            make_match(tmp_path, f"m{i}"),
            match_id=f"m{i}",
            teams={"red": ("Alpha", None), "blue": ("Beta", creds)},
            public_target=None,
            store=store,
        )
    alpha = [s.match_id for s in pending_status(store) if s.team == "Alpha"]
    beta = [s.match_id for s in pending_status(store) if s.team == "Beta"]
    assert alpha == beta == ["m2", "m3", "m4"] and KEEP_UNDELIVERED == 3
    assert "deleted the undelivered logs of Alpha" in caplog.text
    outcomes = deliver_pending(store, team="Beta", opener=Opener(FakeUploader()), retry=FAST)
    assert [o.match_id for o in outcomes] == ["m2", "m3", "m4"]
    assert {s.team for s in pending_status(store)} == {"Alpha"}


def test_a_set_being_delivered_elsewhere_is_skipped_and_not_pruned(
    tmp_path: Path, creds: Path
) -> None:
    from orchestrator.delivery.store import claimed

    store = tmp_path / "store"
    enqueue_match_logs(
        make_match(tmp_path, "m0"),
        match_id="m0",
        teams={"red": ("Alpha", creds)},
        public_target=None,
        store=store,
    )
    [busy] = pending_status(store)
    with claimed(busy) as mine:
        assert mine
        assert deliver_pending(store, opener=Opener(FakeUploader()), retry=FAST) == []
        for i in range(1, KEEP_UNDELIVERED + 2):
            enqueue_match_logs(
                make_match(tmp_path, f"m{i}"),
                match_id=f"m{i}",
                teams={"red": ("Alpha", creds)},
                public_target=None,
                store=store,
            )
        assert "m0" in [s.match_id for s in pending_status(store)]
    outcomes = deliver_pending(store, opener=Opener(FakeUploader()), retry=FAST)
    assert "m0" in [o.match_id for o in outcomes if o.delivered]


def test_a_file_lost_from_the_local_store_is_a_typed_failure(tmp_path: Path, creds: Path) -> None:
    store = tmp_path / "store"
    [pending] = enqueue_match_logs(
        make_match(tmp_path, "m1"),
        match_id="m1",
        teams={"red": ("Alpha", creds)},
        public_target=None,
        store=store,
    )
    (pending.files_dir / "red-1" / "stdout.log").unlink()
    fake = FakeUploader()
    [outcome] = deliver_pending(store, opener=Opener(fake), retry=FAST)
    assert outcome.error is not None and outcome.error.kind == "store"
    assert f"m1/Alpha/{MANIFEST_NAME}" not in fake.files


def test_reenqueueing_a_match_makes_no_empty_set_and_keeps_the_real_ones(
    tmp_path: Path, creds: Path
) -> None:
    store = tmp_path / "store"
    for i in range(KEEP_UNDELIVERED):
        enqueue_match_logs(make_match(tmp_path, f"m{i}"), match_id=f"m{i}",
                           teams={"red": ("Alpha", creds)}, public_target=None, store=store)
    for _ in range(4):  # the team folder has moved into the store: nothing left to queue
        again = enqueue_match_logs(tmp_path / "m0", match_id="m0",
                                   teams={"red": ("Alpha", creds)}, public_target=creds,
                                   store=store)
        assert [s.kind for s in again] == ["public"]
    team_sets = [s for s in pending_status(store) if s.kind == "team"]
    assert [s.match_id for s in team_sets] == [f"m{i}" for i in range(KEEP_UNDELIVERED)]
    assert all(s.files for s in pending_status(store))
    empty = tmp_path / "empty"
    empty.mkdir()
    assert enqueue_match_logs(empty, match_id="e", teams={"red": ("Alpha", creds)},
                              public_target=creds, store=store) == []


def test_the_matchs_public_folder_is_the_public_sets_top(tmp_path: Path, creds: Path) -> None:
    """``hlvs match`` leaves the public files in ``<match>/public/``: they are delivered to
    ``<match id>/public/<file>``, not ``<match id>/public/public/<file>``."""
    match = make_match(tmp_path, "m1")
    (match / "public").mkdir()
    (match / "public" / "replay.jsonl").write_text("{}\n")
    (match / "public" / "referee.log").write_text("the same name as one beside it\n")
    enqueue_match_logs(match, match_id="m1", teams={}, public_target=creds,
                       store=tmp_path / "store")
    fake = FakeUploader()
    assert all(o.delivered for o in deliver_pending(tmp_path / "store", opener=Opener(fake),
                                                    retry=FAST, sleep=lambda s: None))
    assert "m1/public/replay.jsonl" in fake.files
    assert "m1/public/referee.log" in fake.files and "m1/public/public/referee.log" in fake.files
    assert not any(c.startswith("m1/public/public/replay") for c in fake.calls)
