"""Hands the GameController's state to the network and logs its changes.

Every change of state, secondary state, set play, half, kick-off team, score, penalties or
sides is one line in ``gamecontroller.log`` and hands the packet to the sender thread at once.
Every change of another value on the wire hands it too, without a line: ``secsRemaining``,
``secondaryTime`` and a penalty's seconds (computed exactly from simulated time), cards,
goalkeepers and shoot-out kicks. So the packet the thread sends is never more than one step old,
as the league's ``Sender`` computes its times at each send (``Sender.java:164``,
``updateTimes``). The thread sends at its fixed rate and numbers the packets
(:mod:`referee.net`); nothing is sent on a change by itself.
"""

from __future__ import annotations

from collections.abc import Callable

from contracts import TeamColor, encode_game_state
from referee.gamecontroller import GameController, game_control_data
from referee.logs import RefereeLog
from referee.net import GameControllerNetwork


class Publisher:
    def __init__(
        self,
        *,
        gc: GameController,
        team_numbers: dict[TeamColor, int],
        players_per_team: int,
        left_team: Callable[[], TeamColor],
        log: RefereeLog,
    ) -> None:
        """``left_team`` tells which team plays on the left now: its TeamInfo goes first."""
        self._gc = gc
        self._left_team = left_team
        self._team_numbers = dict(team_numbers)
        self._players_per_team = players_per_team
        self._log = log
        self._signature: tuple[object, ...] = ()
        self._values: tuple[int, ...] = ()
        self._state: tuple[object, ...] = ()  # game state and half last handed to the network
        self.network: GameControllerNetwork | None = None

    def packet(self) -> bytes:
        """The current ``RGme`` datagram, ``packetNumber`` 0 (the sender numbers what it sends)."""
        data = game_control_data(
            self._gc,
            team_numbers=self._team_numbers,
            players_per_team=self._players_per_team,
            packet_number=0,
            left_team=self._left_team(),
        )
        return encode_game_state(data)

    def publish(self, sim_time_ms: int, *, force: bool = False) -> None:
        gc = self._gc
        red, blue = gc.score(TeamColor.RED), gc.score(TeamColor.BLUE)
        penalised = gc.penalised()
        left = self._left_team()
        signature = (
            gc.state, gc.secondary_state, gc.set_play, gc.half, gc.kickoff_team, red, blue,
            penalised, left,
        )
        changed = signature != self._signature
        if changed:
            self._signature = signature
            self._log.gamecontroller(
                sim_time_ms,
                f"state {gc.state.name} secondary {gc.secondary_state.name} half {gc.half} "
                f"score red {red} blue {blue} penalised {[str(r) for r in penalised]} "
                f"left {left.value}",
            )
        if self.network is None:
            return
        values = gc.wire_values()
        if changed or force or values != self._values:
            self._values = values
            state = (gc.state, gc.half, gc.phase)
            self.network.publish(self.packet(), state_changed=state != self._state)
            self._state = state

    def log_counts(self, sim_time_ms: int) -> None:
        if self.network is None:
            return
        stats = self.network.stats()
        self._log.gamecontroller(
            sim_time_ms,
            f"packets sent: {stats.packets_sent} ({stats.datagrams_sent} datagrams), "
            f"returns received: {stats.returns_received}, garbage: {stats.garbage}, "
            f"unknown teams: {stats.unknown}, spoofed: {stats.spoofed}",
        )
