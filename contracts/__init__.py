"""The typed vocabulary shared by the orchestrator, the simulator, the referee and robot code.

Standard library and protobuf only, so every process (including a team's robot image) can import
it. ``contracts.robot_api`` holds the robot API's protobuf messages (the league's
``messages.proto``). Installs on its own from ``contracts/pyproject.toml``.
"""
