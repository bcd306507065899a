"""Physics divergence detection: MuJoCo's instability warnings, counted per step.

MuJoCo resets the whole state itself when it finds a non-finite or huge position, velocity or
acceleration (and records a warning whose ``lastinfo`` is the offending degree of freedom). We
compare the warning counters after every basic step.

MuJoCo's own text for each warning goes to this process's log (:func:`route_mujoco_warnings`),
not to ``MUJOCO_LOG.TXT`` in whatever folder the process runs in (a file nobody collects: inside
the simulator's container it is lost with it, and a researcher's notebook folder fills with it).
"""

from __future__ import annotations

import logging
import re
import threading
import time
from dataclasses import dataclass

import mujoco

log = logging.getLogger("simulator.mujoco")

WATCHED = (
    mujoco.mjtWarning.mjWARN_BADQPOS,
    mujoco.mjtWarning.mjWARN_BADQVEL,
    mujoco.mjtWarning.mjWARN_BADQACC,
    mujoco.mjtWarning.mjWARN_BADCTRL,
)
_TEXT = {
    mujoco.mjtWarning.mjWARN_BADQPOS: "NaN, Inf or huge value in qpos",
    mujoco.mjtWarning.mjWARN_BADQVEL: "NaN, Inf or huge value in qvel",
    mujoco.mjtWarning.mjWARN_BADQACC: "NaN, Inf or huge value in qacc",
    mujoco.mjtWarning.mjWARN_BADCTRL: "NaN, Inf or huge value in ctrl",
}


_UNSTABLE = "Nan, Inf or huge value"  # MuJoCo's text of the warnings WATCHED reports
WARNING_EVERY_S = 10.0  # one line per kind of warning in this time at most
_NUMBERS = re.compile(r"-?\d+(\.\d+)?")
_routing = threading.Lock()
_last_said: dict[str, float] = {}


def route_mujoco_warnings() -> None:
    """Send MuJoCo's warnings to the log "simulator.mujoco" (once per process; a handler
    someone else installed is kept): the instability warnings at debug level (the world's
    :class:`DivergenceWatch` reports them with the robot's joint), the others (a full contact
    or constraint buffer, say) as warnings, one line per kind every :data:`WARNING_EVERY_S`."""
    with _routing:
        if mujoco.get_mju_user_warning() is None:
            mujoco.set_mju_user_warning(_said)


def _said(text: str) -> None:
    if text.startswith(_UNSTABLE):
        log.debug("MuJoCo: %s", text)
        return
    kind = _NUMBERS.sub("#", text)
    now = time.monotonic()
    with _routing:
        if now - _last_said.get(kind, -WARNING_EVERY_S) < WARNING_EVERY_S:
            return
        _last_said[kind] = now
    log.warning("MuJoCo: %s", text)


@dataclass(frozen=True, slots=True)
class Divergence:
    warning: mujoco.mjtWarning
    info: int  # the DOF (or actuator for BADCTRL) MuJoCo reported

    def text(self, name_of_dof: str) -> str:
        return f"{self.warning.name}: {_TEXT[self.warning]} at {name_of_dof}"


class DivergenceWatch:
    """Keeps a view of MuJoCo's warning counters; :meth:`check` costs about a microsecond."""

    def __init__(self, data: mujoco.MjData) -> None:
        self._data = data
        self._numbers = data.warning.number  # a live view into mjData
        lo = min(int(w) for w in WATCHED)
        self._watched = self._numbers[lo : max(int(w) for w in WATCHED) + 1]  # live too
        self._seen = self._watched.tolist()
        self._counts = [int(self._numbers[int(w)]) for w in WATCHED]

    def check(self, data: mujoco.MjData) -> Divergence | None:
        """The first new instability warning since the last call, or None."""
        seen = self._watched.tolist()  # one numpy call in the common case: nothing new
        if seen == self._seen:
            return None
        self._seen = seen
        found: Divergence | None = None
        for i, w in enumerate(WATCHED):
            number = int(self._numbers[int(w)])
            if number != self._counts[i]:
                self._counts[i] = number
                if found is None:
                    found = Divergence(warning=w, info=int(data.warning.lastinfo[int(w)]))
        return found
