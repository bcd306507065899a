"""Lockstep waiting: each step waits for one request from every connected, non-slow client.

A client's answer within ``deadline_s`` of the start of the wait (or of the moment its
measurement was queued, when a camera image delayed it) is free; time beyond it is
taken from the client's time bank (a chess clock with a per-move allowance). A client whose bank
runs out is marked slow (logged, counted) and the step goes on without it; it is waited for
again, with a full bank, once it has answered the latest measurement and its send queue is empty.
A client that sends more than its budget (:mod:`simulator.api.bounds`) is marked slow the same
way and is not waited for while it is not read.

The lockstep and pipelined stepping policies (:mod:`simulator.api.stepping`) wait with it.
"""

from __future__ import annotations

import logging
import time

from simulator.api.server import ApiServer, LockstepSettings

log = logging.getLogger(__name__)


def wait_lockstep(server: ApiServer, settings: LockstepSettings) -> float:
    """Block until every awaited client has answered (or ran out of time); returns seconds.

    The usual wait is one look at the server's :class:`~simulator.api.connection.AnswerBook`
    per wake-up, whatever the number of robots: until the deadline nobody can be late, so the
    clients are looked at one by one (:func:`_wait`: deadlines, time banks, slow clients
    catching up) only once it has passed or while some client is slow."""
    book = server.answers
    assert book is not None, "lockstep without the server's lockstep settings"
    start = time.monotonic()
    if server.settle_exchange(settings.deadline_s):  # the exchange thread took every answer
        return time.monotonic() - start
    owing = book.owing
    if not owing and not book.slow:  # every client answered before the wait (pipelined)
        return 0.0
    deadline = settings.deadline_s
    due = start + deadline  # the earliest any client's free time ends
    server.awaiting_answers = True  # before the book is read: an answer after wakes the poll
    try:
        while owing and not book.slow and not server.stop_requested:
            remaining = due - time.monotonic()
            if remaining <= 0:
                break
            server.poll(min(remaining, 0.05))
        if owing or book.slow:  # past the deadline, or slow clients: client by client
            _wait(server, settings, start, deadline, set())
            book.reconcile()
    finally:
        server.awaiting_answers = False
    end = time.monotonic()
    if end >= due:  # before ``due`` every answer was within its free time: nothing to charge
        for slot in server.slots.values():
            conn = slot.conn
            if conn is not None and not conn.slow and conn.answered:
                late = conn.answered_at - max(start, conn.enqueued_at) - deadline
                if late > 0:
                    conn.bank_s = max(0.0, conn.bank_s - late)
    return end - start


def _wait(
    server: ApiServer, settings: LockstepSettings, start: float, deadline: float, missed: set[str]
) -> None:
    while not server.stop_requested:
        now = time.monotonic()
        waiting = []
        next_event = float("inf")
        for slot in server.slots.values():
            conn = slot.conn
            if conn is None:
                continue
            if conn.slow:
                if conn.answered and conn.idle and not conn.paused:
                    conn.mark_slow(False)
                    conn.bank_s = settings.time_bank_s
                    log.info("%s: caught up, lockstep waits for it again", slot.session.key)
                continue
            if conn.answered:
                continue
            if slot.pending:  # its measurement still waits for a camera image: not its fault
                waiting.append(conn)  # the render worker's wake-up ends the poll
                continue
            over = now - max(start, conn.enqueued_at) - deadline
            if over > 0:
                if slot.session.key not in missed:
                    missed.add(slot.session.key)
                    slot.stats.missed_deadlines += 1
                if over >= conn.bank_s:
                    conn.bank_s = 0.0
                    conn.mark_slow(True)
                    slot.stats.slow_periods += 1
                    log.warning(
                        "%s: too slow for lockstep (time bank of %.1f s used up), "
                        "the simulation goes on without it",
                        slot.session.key, settings.time_bank_s,
                    )  # fmt: skip
                    continue
                next_event = min(next_event, conn.bank_s - over)
            else:
                next_event = min(next_event, -over)
            waiting.append(conn)
        if not waiting:
            break
        server.poll(max(0.0, min(next_event, 0.05)))
