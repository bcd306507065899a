"""The referee's messaging with the robots: the GameController's packets sent (``RGme``), the
robots' returns received (``RGrt``: goalkeeper claims), the team mirror, and the spoofing
attempts seen on them.

:class:`GameControllerLink` owns the :class:`~referee.publisher.Publisher`, the
:class:`~referee.net.GameControllerNetwork` and the :class:`~referee.mirror.TeamMirror` (the
last two only once :meth:`GameControllerLink.start` ran: a referee without a network, as in the
learning environments, publishes to its log only), and the :class:`~referee.spoofing.SpoofingLog`
they share with the robot API ports.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from contracts import RobotId, TeamColor
from referee.clock import Clock
from referee.config import RefereeConfig
from referee.gamecontroller import LEAGUE_PLAYERS_PER_TEAM, GameController
from referee.logs import RefereeLog
from referee.mirror import TeamMirror
from referee.net import GameControllerNetwork
from referee.publisher import Publisher
from referee.snapshot import RefereeEvent
from referee.spoofing import Senders, SpoofingLog, robot_key

COLORS = (TeamColor.RED, TeamColor.BLUE)


class GameControllerLink:
    def __init__(
        self,
        *,
        config: RefereeConfig,
        gc: GameController,
        clock: Clock,
        log: RefereeLog,
        log_dir: Path | None,
        left_team: Callable[[], TeamColor],
    ) -> None:
        """``left_team`` tells which team plays on the left now (its TeamInfo goes first)."""
        self._config = config
        self._gc = gc
        self._clock = clock
        self._log = log
        self._log_dir = log_dir
        self.spoofing = SpoofingLog()
        self.senders = Senders({
            RobotId(color, n): address
            for color in COLORS
            for n, address in enumerate(config.team(color).robot_addresses, start=1)
        })
        self._publisher = Publisher(
            gc=gc,
            team_numbers={c: config.team(c).team_id for c in COLORS},
            players_per_team=LEAGUE_PLAYERS_PER_TEAM[config.field_class],
            left_team=left_team,
            log=log,
        )
        self.network: GameControllerNetwork | None = None
        self.mirror: TeamMirror | None = None

    def start(self, sim_time_ms: int) -> None:
        """Start the GameController sender / receiver and the team mirror (UDP), and send the
        first packet."""
        config = self._config
        net = config.network
        addresses = {color: tuple(config.team(color).robot_addresses) for color in COLORS}
        self.network = GameControllerNetwork(
            bind_host=net.bind_host,
            data_port=net.gc_data_port,
            return_port=net.gc_return_port,
            targets=addresses[TeamColor.RED] + addresses[TeamColor.BLUE],
            team_numbers={config.team(c).team_id: c for c in addresses},
            send_rate_hz=net.send_rate_hz,
            clock=self._clock,
            senders=self.senders,
            spoofing=self.spoofing,
        )
        self.mirror = TeamMirror(
            bind_host=net.bind_host,
            port=net.mirror_port,
            teams=addresses,
            max_bytes=net.mirror_max_bytes,
            log_dir=self._log_dir,
            spoofing=self.spoofing,
        )
        self._publisher.network = self.network
        self.network.start()
        self.mirror.start()
        self.publish(sim_time_ms, force=True)

    def close(self, sim_time_ms: int) -> None:
        """Stop the network (its packet counts logged first) and the mirror."""
        if self.network is not None:
            self._publisher.log_counts(sim_time_ms)
            self.network.close()
            self.network = None
            self._publisher.network = None
        if self.mirror is not None:
            self.mirror.close()
            self.mirror = None

    def publish(self, sim_time_ms: int, *, force: bool = False) -> None:
        self._publisher.publish(sim_time_ms, force=force)

    def log_counts(self, sim_time_ms: int) -> None:
        self._publisher.log_counts(sim_time_ms)

    def packet(self) -> bytes:
        """The current ``RGme`` datagram (``packetNumber`` 0: the sender numbers its packets)."""
        return self._publisher.packet()

    def take_goalkeeper_claims(self, sim_time_ms: int) -> None:
        """The robots that declared themselves goalkeeper since the last step (their returns'
        flag) become their team's goalkeeper in the GameController."""
        if self.network is None:
            return
        for robot in self.network.take_goalkeeper_claims():
            if robot.number in self._gc.teams[robot.team].robots:
                self._gc.set_goalkeeper(robot)
                self._log.info(sim_time_ms, f"{robot} declared itself goalkeeper.")

    def report_spoofing(self, sim_time_ms: int, emit: Callable[[RefereeEvent], None]) -> None:
        """Each new kind of spoofing attempt: one warning and one ``spoofing`` event."""
        for attempt in self.spoofing.take_new():
            self._log.warning(sim_time_ms, attempt.describe() + ".")
            sender = self.senders.robots_at(attempt.sender)
            robot = min(sender, key=robot_key) if len(sender) == 1 else None
            emit(RefereeEvent(
                sim_time_ms=sim_time_ms, type="spoofing",
                team=robot.team if robot is not None else None,
                player=robot.number if robot is not None else None,
                reason=attempt.describe(), details=attempt.to_json(),
            ))
