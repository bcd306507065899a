"""The servo gains the stub's motions are tuned for.

The simulator's motors behave as the league's Webots motors: ``P`` (1/s) turns the position
error into a target velocity (Webots' default is 10: a 0.1 s lag, too slow for this gait). The
stub sends these gains for every motor as a ``MotorPID`` request when it connects, as a team
tunes its servos; in-process users apply them with ``World.set_motor_pid``.
"""

from __future__ import annotations

SERVO_PID: tuple[float, float, float] = (30.0, 0.0, 0.0)
"""(P, I, D) of Webots' position controller for every motor of the built-in models."""
