"""The robot-side kinematics (robot.motion.models) match the MJCF the simulator compiles.

Both derive from robot.geometry; this compiles each built-in model with MuJoCo and measures the
joint anchors, the sole, the camera and the joint ranges in the zero pose.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from robot.motion import kinematics, known_models
from simulator.world.robots import known_models as world_models
from simulator.world.robots import robot_model


def _compiled(name: str) -> tuple[mujoco.MjModel, mujoco.MjData]:
    mjcf = robot_model(name).mjcf(
        prefix="r", rgba="1 0 0 1", contype=1, conaffinity=1, pose=(0.0, 0.0, 0.0)
    )
    xml = (
        '<mujoco><compiler angle="radian" autolimits="true"/>'
        f"<worldbody>{mjcf.body}</worldbody><actuator>{mjcf.actuators}</actuator>"
        f"<sensor>{mjcf.sensors}</sensor></mujoco>"
    )
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return model, data


def test_robot_side_knows_the_same_models_as_the_world() -> None:
    assert known_models() == world_models()


@pytest.mark.parametrize("name", ["kid-default", "adult-default"])
def test_kinematics_match_the_compiled_model(name: str) -> None:
    kin = kinematics(name)
    model, data = _compiled(name)

    def anchor(motor: str) -> np.ndarray:
        return np.asarray(data.xanchor[model.joint(f"r/{motor}").id])

    torso = np.asarray(data.xpos[model.body("r/torso").id])
    for side, sign in (("L", 1.0), ("R", -1.0)):
        hip = anchor(f"PelvY{side}")
        assert hip[1] - torso[1] == pytest.approx(sign * kin.leg.hip_offset_y_m, abs=1e-9)
        assert torso[2] - hip[2] == pytest.approx(kin.camera.hip_below_pelvis_m, abs=1e-9)
        for motor in (f"Pelv{side}", f"LegUpper{side}"):
            assert anchor(motor) == pytest.approx(hip, abs=1e-9)  # the three hip axes meet
        knee = anchor(f"LegLower{side}")
        ankle = anchor(f"Ankle{side}")
        assert np.linalg.norm(hip - knee) == pytest.approx(kin.leg.thigh_m, abs=1e-9)
        assert np.linalg.norm(knee - ankle) == pytest.approx(kin.leg.shank_m, abs=1e-9)
        assert anchor(f"Foot{side}") == pytest.approx(ankle, abs=1e-9)
        cleats = [model.geom(f"r/foot:cleat_{side}{y}{x}").id for y in "lr" for x in "bf"]
        sole_bottom = min(data.geom_xpos[c][2] - model.geom_size[c][0] for c in cleats)
        assert ankle[2] - sole_bottom == pytest.approx(kin.leg.ankle_height_m, abs=1e-9)
        assert sole_bottom == pytest.approx(0.0, abs=1e-9)  # standing on the ground at zero

    neck = anchor("Neck")
    assert neck[2] - torso[2] == pytest.approx(kin.camera.neck_height_m, abs=1e-9)
    head = np.asarray(data.xpos[model.body("r/head").id])
    assert head[2] - neck[2] == pytest.approx(kin.camera.head_height_m, abs=1e-9)
    camera = model.camera("r/Camera").id
    assert data.cam_xpos[camera][0] - head[0] == pytest.approx(
        kin.camera.camera_forward_m, abs=1e-9
    )
    spec = robot_model(name).camera
    fovy = math.radians(float(model.cam_fovy[camera]))
    horizontal = 2 * math.atan(math.tan(fovy / 2) * spec.width / spec.height)
    assert horizontal == pytest.approx(kin.camera.fov_rad, abs=1e-5)

    actuated = {model.joint(j).name.removeprefix("r/") for j in range(1, model.njnt)}
    assert set(kin.motor_names) == actuated
    for motor in kin.motor_names:
        low, high = model.jnt_range[model.joint(f"r/{motor}").id]
        assert kin.motor_limits[motor] == pytest.approx((low, high), abs=1e-9)
