"""The stub robot's view of the GameController: a listener thread on UDP 3838 that keeps the
latest ``RGme`` packet and answers ``RGrt`` ALIVE every second (C's client library underneath)."""

from __future__ import annotations

import logging
import threading
import time

from robot.client import (
    GameControlData,
    GameControllerListener,
    GameControllerReplier,
    GameState,
)
from robot.stub.behaviour import GameInfo

logger = logging.getLogger(__name__)

ALIVE_PERIOD_S = 1.0
COLOUR_BY_TEAM = {"blue": 0, "red": 1}

class GameControllerLink:
    """Runs in its own thread until :meth:`close`; :meth:`info` is safe from any thread."""

    def __init__(
        self,
        *,
        team_color: str,
        player: int,
        gamecontroller_ip: str | None,
        data_port: int,
        return_port: int,
    ) -> None:
        self._color = team_color
        self._player = player
        self._gc_ip = gamecontroller_ip
        self._return_port = return_port
        self._listener = GameControllerListener(port=data_port, gamecontroller=gamecontroller_ip)
        self._replier: GameControllerReplier | None = None
        self._latest: GameControlData | None = None
        # the team number of the last set play seen since the last kick-off: the protection
        # after it is taken (secondaryTime counts on, secondaryState is NORMAL again) is theirs
        self._set_play_team: int | None = None
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="gamecontroller", daemon=True)
        self.alive_sent = 0

    def start(self) -> GameControllerLink:
        self._thread.start()
        return self

    def close(self) -> None:
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join(timeout=2.0)
        self._listener.close()
        if self._replier is not None:
            self._replier.close()

    def team_number(self, data: GameControlData) -> int | None:
        wanted = COLOUR_BY_TEAM[self._color]
        for team in data.teams:
            if team.colour == wanted:
                return team.team_number
        return None

    def info(self) -> GameInfo | None:
        """The game as the GameController last described it; None before the first packet."""
        with self._lock:
            data, set_play_team = self._latest, self._set_play_team
        if data is None:
            return None
        team = self.team_number(data)
        penalty = data.own_penalty(team, self._player) if team is not None else None
        playing = data.state is GameState.PLAYING
        set_play = playing and data.secondary_state.is_set_play
        return GameInfo(
            phase=data.state,
            penalised=bool(penalty),
            our_kick_off=team is not None and data.kick_off_team == team,
            first_half=data.first_half,
            on_left=None if team is None else data.teams[0].team_number == team,
            ball_free_in_s=float(max(data.secondary_time, 0)) if playing else 0.0,
            restart_ours=None if set_play_team is None else set_play_team == team,
            set_play_ours=data.secondary_state_info[0] == team if set_play else None,
            set_play_phase=data.secondary_state_info[1] if set_play else 0,
        )

    def _run(self) -> None:
        next_alive = time.monotonic()
        previous_state: GameState | None = None
        while not self._stop.is_set():
            data = self._listener.receive(timeout=0.25)
            if data is not None:
                with self._lock:
                    self._latest = data
                    if data.state is not GameState.PLAYING:
                        self._set_play_team = None  # a kick-off comes next
                    elif data.secondary_state.is_set_play:
                        self._set_play_team = data.secondary_state_info[0]
                if data.state != previous_state:
                    logger.info(
                        "GameController %s: state %s", self._listener.sender, data.state.name
                    )
                    previous_state = data.state
            if time.monotonic() >= next_alive:
                next_alive += ALIVE_PERIOD_S
                self._send_alive()

    def _send_alive(self) -> None:
        with self._lock:
            data = self._latest
        host = self._gc_ip or self._listener.sender
        team = self.team_number(data) if data is not None else None
        if host is None or team is None:
            return
        if self._replier is None or self._replier.team != team:
            self._replier = GameControllerReplier(
                host=host, team=team, player=self._player, port=self._return_port
            )
            logger.info("sending ALIVE to %s:%d as team %d", host, self._return_port, team)
        try:
            self._replier.send()
            self.alive_sent += 1
        except OSError as exc:
            logger.warning("ALIVE to %s failed: %s", host, exc)
