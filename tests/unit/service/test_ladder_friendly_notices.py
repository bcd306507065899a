"""A friendly the ladder scheduled, told to both teams by mail through a real SMTP server on
loopback (aiosmtpd), each from its side and saying that the ladder scheduled it and against
whom; each team reads its own robots' logs of it, never the other side's."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from email import message_from_bytes, policy
from email.message import EmailMessage
from typing import Any

import httpx
import pytest

from cluster.fake import FakePool
from tests.integration.service.harness import Served, free_port
from tests.unit.service.conftest import wait_for_status
from tests.unit.service.test_ladder import running_match
from tests.unit.service.test_submissions import setup_team


class Inbox:
    def __init__(self) -> None:
        self.messages: list[EmailMessage] = []

    async def handle_DATA(self, server: Any, session: Any, envelope: Any) -> str:  # noqa: N802
        message = message_from_bytes(envelope.content, policy=policy.default)
        assert isinstance(message, EmailMessage)
        self.messages.append(message)
        return "250 OK"

    def to(self, address: str) -> list[EmailMessage]:
        return [m for m in self.messages if m["To"] == address]


@pytest.fixture
def inbox() -> Iterator[tuple[Inbox, int]]:
    from aiosmtpd.controller import Controller

    handler = Inbox()
    port = free_port()
    controller = Controller(handler, hostname="127.0.0.1", port=port)
    controller.start()
    yield handler, port
    controller.stop()


def _wait_mails(inbox: Inbox, count: int, timeout_s: float = 15.0) -> None:
    import time

    deadline = time.monotonic() + timeout_s
    while len(inbox.messages) < count:
        assert time.monotonic() < deadline, [str(m["Subject"]) for m in inbox.messages]
        time.sleep(0.05)


ADDRESS = {name: f"{name.lower()}@example.org" for name in ("Alpha", "Beta")}


def _played_friendly(served: Served, token: Callable[..., str], pool: FakePool
                     ) -> tuple[dict[str, httpx.Client], str, str, str]:
    """Two teams; the ladder's friendly between them played to its end (red wins 1-0):
    (their clients, the submission id, the submitting team, its opponent)."""
    http = {name: setup_team(served, token(name, accepts_friendlies=True, email=ADDRESS[name]),
                             name) for name in ADDRESS}
    sid, handle, team, opponent = running_match(served)
    pool.finish(handle, {"status": "success"})
    wait_for_status(http[team], sid, lambda b: b["state"] == "done")
    return http, sid, team, opponent


def test_both_teams_of_a_ladder_friendly_are_told_from_their_side_that_the_ladder_set_it(
    start: Callable[..., Served], token: Callable[..., str], pool: FakePool,
    inbox: tuple[Inbox, int],
) -> None:
    """As found: only the submitting team got mail, and it did not say that the ladder
    scheduled the match."""
    mails, port = inbox
    served = start(ladder_every_s=3600.0, smtp_host="127.0.0.1", smtp_port=port)
    _, sid, team, opponent = _played_friendly(served, token, pool)
    _wait_mails(mails, 4)

    for name, other, side, line in ((team, opponent, "red", "you (red) 1 : 0"),
                                    (opponent, team, "blue", "you (blue) 0 : 1")):
        got = mails.to(ADDRESS[name])
        subjects = sorted(str(m["Subject"]) for m in got)
        assert subjects == [f"[hlvs] ladder friendly {sid} against {other} finished",
                            f"[hlvs] ladder friendly {sid} against {other} started"], subjects
        finished = next(str(m.get_content()) for m in got if "finished" in str(m["Subject"]))
        assert f"The ladder scheduled a friendly {sid} of your team ({side}) against {other}" \
            in finished, finished
        assert f"{line} {other}" in finished, finished
        assert ("outcome: won" if side == "red" else "outcome: lost") in finished, finished
        assert f"/v1/submissions/{sid}/logs" in finished


def test_each_team_of_a_ladder_friendly_reads_its_own_robots_logs_never_the_others(
    start: Callable[..., Served], token: Callable[..., str], pool: FakePool,
) -> None:
    """As found: the opponent could not read its own robots' logs of the match."""
    served = start(ladder_every_s=3600.0)
    http, sid, team, opponent = _played_friendly(served, token, pool)
    outsider = served.client(token("Gamma"))
    for name, own, theirs in ((team, "red", "blue"), (opponent, "blue", "red")):
        listing = http[name].get(f"/v1/submissions/{sid}/logs")
        assert listing.status_code == 200, listing.text
        assert listing.json()["team"] == ["1/stdout.log"]
        log = http[name].get(f"/v1/submissions/{sid}/logs/team/1/stdout.log")
        assert log.status_code == 200 and log.text == f"{own} robot log\n"
        assert f"{theirs} robot log" not in log.text
    # the opponent reads nothing else of the submitting team's, nor does a third team
    assert http[opponent].get(f"/v1/submissions/{sid}/results").status_code == 404
    assert outsider.get(f"/v1/submissions/{sid}/logs").status_code == 404
    assert outsider.get(f"/v1/submissions/{sid}/logs/team/1/stdout.log").status_code == 404
