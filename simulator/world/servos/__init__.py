"""The league servo catalogue (:mod:`.catalogue`)."""

from simulator.world.servos.catalogue import Servo, catalogue, find_servo, servo, servo_ids

__all__ = ["Servo", "catalogue", "find_servo", "servo", "servo_ids"]
