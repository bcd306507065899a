"""The ball entity: the HLVS ball (size and mass per field class), bouncy on grass, rolling to rest.

Contacts of the ball use the ball's parameters (higher geom priority): restitution about 0.84
on a rigid contact (``solref`` in MuJoCo's direct form, -stiffness and -damping: a 1 m drop
bounces back to about 0.53 m with the drag; the time-constant form gains energy at these damping
ratios; the league's world bounces it at 0.76, :func:`use_league_bounce`), sliding
friction 0.5 and rolling friction that brings a rolling ball to rest. Linear damping on the free
joint plays the part of HLVS's grass drag: a ball kicked at 4 m/s rolls about 7 m and stops
within 6 s.
"""

from __future__ import annotations

import math

import mujoco

from contracts import FieldGeometry
from simulator.world.look import BALL_TEXTURE

BALL_BODY = "ball"
BALL_JOINT = "ball/root"
BALL_GEOM = "ball:geom"
BALL_SOLREF = (-10000.0, -11.0)  # direct form: -stiffness, -damping -> restitution ~0.84
BALL_FRICTION = (0.5, 0.005, 0.0025)  # sliding, torsional, rolling (m)
BALL_LINEAR_DAMPING_PER_KG = 0.6  # N s/m per kg of ball: v decays ~ exp(-0.6 t / 1.4) rolling
BALL_ANGULAR_DAMPING = 0.0


def ball_body(f: FieldGeometry, *, bits: tuple[int, int]) -> str:
    contype, conaffinity = bits
    r = f.ball_radius_m
    return (
        f'<body name="{BALL_BODY}" pos="0 0 {r:.6g}">'
        f'<freejoint name="{BALL_JOINT}"/>'
        f'<geom name="{BALL_GEOM}" type="sphere" size="{r:.6g}" mass="{f.ball_mass_kg:.6g}" '
        f'material="{BALL_TEXTURE}" condim="6" priority="2" '
        f'friction="{" ".join(str(v) for v in BALL_FRICTION)}" '
        f'solref="{BALL_SOLREF[0]} {BALL_SOLREF[1]}" contype="{contype}" '
        f'conaffinity="{conaffinity}"/>'
        f"</body>"
    )


def ball_damping(f: FieldGeometry) -> tuple[float, float]:
    """(linear, angular) damping of the ball's free joint, set on the compiled model."""
    return BALL_LINEAR_DAMPING_PER_KG * f.ball_mass_kg, BALL_ANGULAR_DAMPING


# The league's ball (hlvs_webots ``protos/RobocupTexturedSoccerBall.proto:54-57``):
# ``Damping { linear 0.77 angular 0.77 }``, the fraction of its speed a body loses every
# second; Webots gives ODE 1 - (1 - d) ** dt per step (``WbWorldInfo::applyToOdeGlobalDamping``,
# the same for a body's own damping), so v(t) = v0 * 0.23 ** t. No rolling friction
# (``worlds/robocup.wbt:35-43``: grass and ball, Coulomb friction 0.5).
LEAGUE_BALL_DAMPING_PER_S = 0.77
LEAGUE_BALL_FRICTION = (0.5, 0.0, 0.0)


def use_league_ball(model: mujoco.MjModel) -> None:
    """Give the compiled world the league's ball: its speed and spin decay as Webots damps them
    (v *= 0.23 ** t: a rate of -ln 0.23 = 1.47 per second, damping = rate x mass, rate x
    inertia on each axis), with sliding friction only. For the league's referee test scenarios,
    whose pushes were tuned to this ball; matches keep the match ball."""
    rate = -math.log(1.0 - LEAGUE_BALL_DAMPING_PER_S)
    body = model.body(BALL_BODY).id
    adr = int(model.joint(BALL_JOINT).dofadr[0])
    model.dof_damping[adr : adr + 3] = rate * float(model.body_mass[body])
    model.dof_damping[adr + 3 : adr + 6] = rate * model.body_inertia[body]
    model.geom_friction[model.geom(BALL_GEOM).id] = LEAGUE_BALL_FRICTION


# The league's world bounces the ball at 0.76 off the grass and off everything else, robots
# included (hlvs_webots ``worlds/robocup.wbt:35-43``: ``ContactProperties`` ``bounce 0.76`` for
# grass and ball, and for the ball with any other material): ODE's bounce sets the normal speed
# after a contact to 0.76 times the speed before it.
LEAGUE_BALL_BOUNCE = 0.76


def bounce_damping(stiffness: float, restitution: float) -> float:
    """The damping of a direct-form contact spring of ``stiffness`` whose bounce keeps
    ``restitution`` of the normal speed (a damped spring's: e = exp(-pi zeta / sqrt(1 - zeta^2)),
    damping = 2 zeta sqrt(stiffness))."""
    log_e = math.log(restitution)
    zeta = -log_e / math.sqrt(math.pi**2 + log_e**2)
    return 2.0 * zeta * math.sqrt(stiffness)


def use_league_bounce(model: mujoco.MjModel) -> None:
    """Give the compiled world the league's bounce (:data:`LEAGUE_BALL_BOUNCE`) on every contact
    of the ball: its contact spring keeps its stiffness, its damping is raised so that 0.76 of the
    normal speed comes back (the match ball's 11 keeps 0.84). For the league's referee test
    scenarios, which push the ball into the league's robot to make it touch it and count on where
    it comes back to (kick_off/scenario_3); matches keep the match ball."""
    geom = model.geom(BALL_GEOM).id
    stiffness = -float(model.geom_solref[geom][0])
    model.geom_solref[geom][1] = -bounce_damping(stiffness, LEAGUE_BALL_BOUNCE)
