"""Exit codes of every ``hlvs`` command: one code per kind of outcome, the same everywhere.

=====  ==================  ===============================================================
code   name                meaning
=====  ==================  ===============================================================
0      OK                  the command did what it was asked (a match played to its end)
1      FAILED              the operation ran and failed: a match failed, a log set was not
                           delivered, a player has no usable image, cleanup was incomplete
2      INVALID             invalid input: command line, configuration file, a missing or
                           unreadable file named on the command line
3      INFRASTRUCTURE      the Docker engine, a registry, the network or the host failed us
4      FORFEIT             the match was played but decided by forfeit (a team had no valid
                           image or no robot connected)
130    INTERRUPTED         stopped by SIGINT / SIGTERM (after stopping and collecting)
=====  ==================  ===============================================================

Commands return these (``return ExitCode.FAILED``) or raise an :class:`OrchestratorError`
subclass, whose ``exit_code`` is one of them; the command line maps errors to codes in one place.
"""

from __future__ import annotations

from enum import IntEnum


class ExitCode(IntEnum):
    OK = 0
    FAILED = 1
    INVALID = 2
    INFRASTRUCTURE = 3
    FORFEIT = 4
    INTERRUPTED = 130


__all__ = ["ExitCode"]
