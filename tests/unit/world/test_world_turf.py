"""The soft grass and the cleats: sinkage, contact points, friction, creep, and the ball's roll
(simulator.world.field, simulator.world.robots)."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from contracts.field import KID_FIELD
from referee.snapshot import PlaceBall
from simulator.world import RobotPlacement, World
from simulator.world.field import GRASS_SINKAGE_M, TURF_FRICTION
from simulator.world.scene import STATIC_BIT, scene_xml

from .conftest import RED_1, run_steps

WOLFGANG = Path(__file__).resolve().parents[3] / "configs" / "examples" / "robots" / "wolfgang"
G = 9.81


def _standing(model: str, field_class: str = "kid") -> World:
    placement = RobotPlacement(id=RED_1, model=model, x_m=-1.0, y_m=0.5, yaw_rad=0.0)
    world = World.create(field_class=field_class, robots=[placement], seed=1)  # type: ignore[arg-type]
    run_steps(world, 250)  # 2 s
    return world


def _turf_contacts(world: World) -> list[tuple[str, float]]:
    """(robot geom name, depth m) of every contact of the turf with a robot."""
    turf = world.model.geom("turf").id
    out = []
    for contact in world.data.contact[: world.data.ncon]:
        if turf in (contact.geom1, contact.geom2):
            other = world.model.geom(contact.geom1 + contact.geom2 - turf).name
            if other.startswith("red_1/"):
                out.append((other, -float(contact.dist)))
    return out


@pytest.mark.parametrize(("model", "field_class"), [("kid-default", "kid"),
                                                     ("adult-default", "adult")])  # fmt: skip
def test_a_standing_robot_sinks_as_deep_as_in_the_leagues_grass(
    model: str, field_class: str
) -> None:
    """The league's world sinks a 4.9 kg robot on eight contact points 7.2 mm; MuJoCo's soft
    contact sinks every robot alike (it does not depend on mass)."""
    world = _standing(model, field_class)
    depths = [depth for _, depth in _turf_contacts(world)]
    assert len(depths) == 8
    assert GRASS_SINKAGE_M - 0.002 < float(np.mean(depths)) < GRASS_SINKAGE_M + 0.002
    run_steps(world, 250)
    later = [depth for _, depth in _turf_contacts(world)]
    assert float(np.mean(later)) == pytest.approx(float(np.mean(depths)), abs=5e-4)  # settled


def test_each_built_in_foot_stands_on_its_four_cleats() -> None:
    world = _standing("kid-default")
    names = sorted(name for name, _ in _turf_contacts(world))
    assert names == sorted(f"red_1/foot:cleat_{s}{y}{x}" for s in "LR" for y in "lr" for x in "bf")
    forces = [world.read_force(RED_1, name) for name in ("llb", "llf", "lrf", "lrb")]
    assert all(force > 1.0 for force in forces)  # each corner sensor feels its cleat


def test_a_team_model_keeps_its_own_cleats() -> None:
    """The Wolfgang's cleat links carry a sphere each: four per foot, kept as shapes."""
    world = _standing(str(WOLFGANG))
    cleats = [name for name, _ in _turf_contacts(world) if "_cleat_" in name]
    for foot in ("l_foot", "r_foot"):
        assert len({name for name in cleats if f":{foot}_cleat_" in name}) == 4
    assert not world.snapshot().robots[0].fallen


def _block_world(speed_m_s: float) -> tuple[mujoco.MjModel, mujoco.MjData, int]:
    """The world's turf with a 2 kg block (a foot's size) sliding along x, and the address of
    the block's x velocity."""
    spec = mujoco.MjSpec.from_string(scene_xml(KID_FIELD, [], physics_dt_s=0.002))
    block = spec.worldbody.add_body()
    block.name = "block"
    block.pos = (0.0, 0.0, 0.02)
    block.add_freejoint().name = "block/root"
    geom = block.add_geom()
    geom.type = mujoco.mjtGeom.mjGEOM_BOX
    geom.size = (0.085, 0.045, 0.02)
    geom.mass = 2.0
    geom.contype, geom.conaffinity = 0, STATIC_BIT
    model = spec.compile()
    data = mujoco.MjData(model)
    for _ in range(250):  # settle into the grass
        mujoco.mj_step(model, data)
    adr = int(model.joint("block/root").dofadr[0])
    data.qvel[adr] = speed_m_s
    return model, data, adr


def test_a_block_sliding_on_the_turf_feels_the_configured_friction() -> None:
    """While it slides, the turf's friction on the block is mu times the normal force."""
    model, data, adr = _block_world(2.0)
    turf = model.geom("turf").id
    block = model.geom(model.body("block").geomadr[0]).id
    force = np.zeros(6)
    normal = tangential = 0.0
    for _ in range(150):  # 0.3 s, sliding all along
        mujoco.mj_step(model, data)
        assert data.qvel[adr] > 0.2
        for i, contact in enumerate(data.contact[: data.ncon]):
            if {int(contact.geom1), int(contact.geom2)} == {turf, block}:
                mujoco.mj_contactForce(model, data, i, force)
                normal += force[0]
                tangential += float(np.hypot(force[1], force[2]))
    assert normal > 0.0
    assert tangential / normal == pytest.approx(TURF_FRICTION, abs=0.02)


def test_a_pushed_standing_robot_does_not_creep_on_the_soft_grass() -> None:
    """A 0.1 g push for 1 s: the feet hold (rigid turf: 1.8 mm; a linear soft contact of the
    same sinkage: 10 to 20 cm)."""
    world = _standing("kid-default")
    torso = world.model.body("red_1/torso").id
    foot = world.model.body("red_1/foot_L").id
    start = world.data.xpos[foot][:2].copy()
    world.data.xfrc_applied[torso, 0] = 0.1 * G * float(world.model.body_subtreemass[torso])
    run_steps(world, 125)
    world.data.xfrc_applied[:] = 0.0
    assert float(np.linalg.norm(world.data.xpos[foot][:2] - start)) < 0.006


@pytest.mark.parametrize(("field_class", "rolled_m"), [("kid", 4.9999), ("adult", 5.5841)])
def test_the_ball_rolls_as_on_the_rigid_turf(field_class: str, rolled_m: float) -> None:
    """The ball keeps its own contact (higher priority): kicked at 4 m/s it rolls as far as
    before the soft grass (figures measured with the rigid turf), within 1 %."""
    world = World.create(field_class=field_class, robots=[], seed=1)  # type: ignore[arg-type]
    r = world.field.ball_radius_m
    world.apply(PlaceBall(position=(-2.0, 0.0, r), velocity=(4.0, 0.0, 0.0)))
    run_steps(world, 750)  # 6 s
    assert world.snapshot().ball.position[0] + 2.0 == pytest.approx(rolled_m, rel=0.01)
