"""Physics divergence detection: MuJoCo's instability warnings, counted per step.

MuJoCo resets the whole state itself when it finds a non-finite or huge position, velocity or
acceleration (and records a warning whose ``lastinfo`` is the offending degree of freedom). We
compare the warning counters after every basic step.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco

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
