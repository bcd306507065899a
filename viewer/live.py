"""Live telemetry for the web view (the only viewer module importing zenoh).

:class:`ZenohFeed` subscribes to one match's ``hlvs/<id>/{state,events,poses,scene}`` keys at
the simulator's telemetry endpoint and hands every message to a callback as ``(kind, payload)``
with ``kind`` one of ``state events poses scene`` and ``payload`` the message bytes.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Any, Protocol

from contracts import telemetry as topics

log = logging.getLogger(__name__)

KINDS = ("state", "events", "poses", "scene")
Callback = Callable[[str, bytes], None]


class LiveFeed(Protocol):
    def close(self) -> None: ...


FeedFactory = Callable[[str, str, Callback], LiveFeed]  # (endpoint, match id, callback)


class LiveUnavailable(Exception):
    def __init__(self, *, endpoint: str, reason: str) -> None:
        self.endpoint = endpoint
        self.reason = reason
        super().__init__(f"telemetry at {endpoint}: {reason}")


class ZenohFeed:
    def __init__(self, endpoint: str, match_id: str, callback: Callback) -> None:
        import zenoh

        from orchestrator import subscriber_config

        try:
            self._session: Any = zenoh.open(subscriber_config(endpoint))
            self._subs = [
                self._session.declare_subscriber(
                    topics.topic(match_id, kind), _forward(kind, callback)
                )
                for kind in KINDS
            ]
        except zenoh.ZError as exc:
            raise LiveUnavailable(endpoint=endpoint, reason=str(exc)) from exc
        log.info("live view: subscribed to hlvs/%s/* at %s", match_id, endpoint)

    def close(self) -> None:
        for sub in self._subs:
            sub.undeclare()  # type: ignore[no-untyped-call]
        self._session.close()


def _forward(kind: str, callback: Callback) -> Callable[[Any], None]:
    def on_sample(sample: Any) -> None:
        callback(kind, bytes(sample.payload.to_bytes()))

    return on_sample
