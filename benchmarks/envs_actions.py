"""The actions the environment benchmarks send (:mod:`benchmarks.envs`,
:mod:`benchmarks.envs_remote`): small motor targets around the standing posture."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np

ACTION_AMPLITUDE_RAD = 0.05


def actions(count: int, seed: int) -> np.ndarray:
    """Small motor targets around the standing posture (the robot stays up)."""
    import numpy as np

    rng = np.random.default_rng(seed)
    return rng.uniform(-ACTION_AMPLITUDE_RAD, ACTION_AMPLITUDE_RAD, (count, 20)).astype(np.float32)


__all__ = ["ACTION_AMPLITUDE_RAD", "actions"]
