"""The robot side of hlvs-runner: what a team's robot program uses to play a match.

``robot.client`` (the robot API and GameController client library), ``robot.motion`` (walking,
kicking, getting up for the built-in models), ``robot.stub`` (the stub robot controller) and
``robot.geometry`` (the built-in humanoids' dimensions, from which the simulator builds their
MJCF). Nothing here imports MuJoCo, the simulator server or the referee: the package installs on
its own with numpy and protobuf (see ``robot/pyproject.toml``).
"""

__all__: list[str] = []  # its public modules are listed in ARCHITECTURE.md (Public faces)
