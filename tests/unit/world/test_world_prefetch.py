"""The next step's position stage computed while lockstep waits (``World.prefetch``): the
world it steps is the same to the bit as one stepped whole, a change of state after the
prefetch is honoured, and a single-substep world does not prefetch."""

from __future__ import annotations

import math

import numpy as np

from contracts import RobotId, TeamColor
from referee import PlaceBall
from simulator.world import RobotPlacement, World
from simulator.world.world import _SENSOR_OFF


def _world(physics_dt_s: float = 0.002) -> World:
    robots = [RobotPlacement(id=RobotId(team, n), model="kid-default",
                             x_m=(-1.0 if team is TeamColor.RED else 1.0) * (0.5 + 0.6 * n),
                             y_m=0.5 * n - 0.75, yaw_rad=0.0 if team is TeamColor.RED else math.pi)
              for team in (TeamColor.RED, TeamColor.BLUE) for n in (1, 2)]
    return World.create(field_class="kid", robots=robots, seed=3, physics_dt_s=physics_dt_s)


def _move(world: World, step: int) -> None:
    """Every motor's target swinging, different each step (what clients would send)."""
    world.motors.target[:] = 0.3 * np.sin(0.05 * step + np.arange(world.motors.target.size))


def _state(world: World) -> tuple[np.ndarray, ...]:
    d = world.data
    return d.qpos.copy(), d.qvel.copy(), d.sensordata.copy(), d.qacc_warmstart.copy()


def test_a_prefetched_world_steps_as_a_whole_one_to_the_bit() -> None:
    whole, fetched = _world(), _world()
    for step in range(150):
        _move(whole, step)
        whole.step()
        fetched.prefetch()
        _move(fetched, step)  # targets arrive during the wait, as requests do
        fetched.step()
        if step % 10 == 0:
            assert whole.snapshot() == fetched.snapshot()
    for a, b in zip(_state(whole), _state(fetched), strict=True):
        assert np.array_equal(a, b)
    assert not np.array_equal(whole.data.qpos, _world().data.qpos)  # the robots moved


def test_a_command_after_the_prefetch_is_honoured() -> None:
    whole, fetched = _world(), _world()
    for step in range(40):
        for world in (whole, fetched):
            if world is fetched:
                world.prefetch()
            if step == 20:
                world.apply(PlaceBall(position=(0.7, -0.4, world.field.ball_radius_m)))
            _move(world, step)
            world.step()
    for a, b in zip(_state(whole), _state(fetched), strict=True):
        assert np.array_equal(a, b)


def test_the_stage_is_stale_when_the_state_changes_and_none_with_one_substep() -> None:
    world = _world()
    world.prefetch()
    stage = world._stage
    assert stage is not None
    assert world._settle()  # the state as it began: the stage holds
    assert world._opt.disableflags & _SENSOR_OFF == 0  # sensors on again for anything else
    world.prefetch()
    stage._done.wait()  # the worker is done; the state changes before the step
    world.data.qvel[0] += 0.1
    assert not world._settle()
    single = _world(physics_dt_s=0.008)
    single.prefetch()
    assert single._stage is None
