"""The stub striker finds, reaches and kicks the ball in the looks where it once walked away
(``hlvs bench stub``'s trials, texture_seed = the trial's seed)."""

from __future__ import annotations

import os

import pytest

from simulator.world.look import look_for
from testkit.stub_world import run_reach


@pytest.mark.slow
@pytest.mark.parametrize(
    ("seed", "background"),
    [(1000, 6), (1001, 3)],
    ids=["pink-dawn-worn-patches", "dusk-far-line-crossings"],
)
def test_the_striker_kicks_the_ball_and_not_the_turf(seed: int, background: int) -> None:
    # With the ball's green share allowed up to 0.37, the worn patches of the turf under the
    # pink dawn light (seed 1000) and far crossings of field lines in the dusk (1001) passed
    # for the ball: the striker kicked where no ball lay, or walked to a line for 60 s.
    os.environ.setdefault("MUJOCO_GL", "osmesa")
    os.environ.setdefault("PYOPENGL_PLATFORM", os.environ["MUJOCO_GL"])
    assert look_for(seed).background == background  # the look this trial is about
    result = run_reach(seed=seed, distance_m=2.0, time_limit_s=60.0)
    assert result.success, result
    assert result.kick_distance_m >= 0.5
    assert result.time_to_kick_s is not None and result.time_to_kick_s < 50.0
