"""Before anything starts: the engine has the OCI runtime that ``limits.robot_runtime`` asks
for the robots (gVisor's ``runsc``, registered in the engine's daemon.json as configs/README.md
says).

Without this check a runtime the engine does not know failed each robot's start with the
engine's message, after the networks and the simulator were up; now the match is refused
before any container starts, with an error naming the setting, the engine and the runtimes it
has. How the engine lists its runtimes is the adapter's business
(:func:`orchestrator.engine.engine_runtimes`); this module only decides.
"""

from __future__ import annotations

from collections.abc import Callable, Collection

from orchestrator.errors import ConfigError, Problem
from orchestrator.match.plan import MatchPlan

POINTER = "/limits/robot_runtime"


def check_robot_runtime(plan: MatchPlan, *, engine: str,
                        runtimes: Callable[[], Collection[str]]) -> None:
    """Refuse ``plan`` when its robots' runtime is not one the engine at ``engine`` has.

    ``runtimes`` lists the engine's runtimes by name; it is not called when the plan asks for
    the engine's default (``""``).

    Raises:
        ConfigError: the engine has no runtime of that name (the problem names the game file,
            ``/limits/robot_runtime``, the engine and the runtimes it has).
    """
    wanted = plan.limits.robot_runtime
    if not wanted:
        return
    known = sorted(runtimes())
    if wanted in known:
        return
    raise ConfigError([Problem(
        file=plan.game_file, pointer=POINTER,
        message=f"{wanted!r}, but the Docker engine at {engine} has no runtime of that name "
                f"(it has: {', '.join(known) or 'none'}); no container was started",
        expected="a runtime registered in that engine's daemon.json (gVisor: runsc, see "
                 "configs/README.md), or \"\" for the engine's default")])


__all__ = ["POINTER", "check_robot_runtime"]
