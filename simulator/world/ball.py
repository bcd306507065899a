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
# second; Webots gives ODE 1 - (1 - d) ** dt per step (``WbSolidMerger::setOdeDamping``, the same
# for the world's global damping), so v(t) = v0 * 0.23 ** t. No rolling friction
# (``worlds/robocup.wbt:35-43``: grass and ball, Coulomb friction 0.5).
LEAGUE_BALL_DAMPING_PER_S = 0.77
LEAGUE_BALL_FRICTION = (0.5, 0.0, 0.0)
# Its mass in ODE: the proto scales its Solid by radius x 10.4 and gives ``mass`` the FIFA mass
# (``RobocupTexturedSoccerBall.proto:17-21, 26, 47, 51``: ``scale``, the bounding sphere's
# radius / scale, 0.205 kg for size 1; Webots' own ``RobocupSoccerBall.proto`` of R2022a the
# same), and Webots hands ODE scale^3 x mass for a scaled Solid (cyberbotics/webots
# ``src/webots/nodes/WbSolid.cpp``, ``WbSolid::createOdeMass``: ``actualMass = s * s2 * mass``,
# ``s = absoluteScale().x()``; the league's world is R2022b, ``worlds/robocup.wbt:1``) with the
# inertia of a solid sphere of the scaled radius (``WbSolidUtilities::addMass``:
# ``sphere->scaledRadius()``). Size 1: 0.728^3 x 0.205 = 0.0791 kg, so each ``addForce`` push
# (one 8 ms step: ODE clears a body's forces after every step, ``src/ode/ode/src/step.cpp``
# "zero all force accumulators") moves it 2.6 times as fast as a 0.205 kg ball would go.
LEAGUE_BALL_SCALE_PER_M = 10.4


def league_ball_mass_kg(f: FieldGeometry) -> float:
    """The mass ODE gives the league's ball in Webots (:data:`LEAGUE_BALL_SCALE_PER_M`): the
    field's FIFA ball mass times the proto's scale cubed (0.0791 kg on the kid field)."""
    scale = f.ball_radius_m * LEAGUE_BALL_SCALE_PER_M
    return f.ball_mass_kg * scale**3


def use_league_ball(model: mujoco.MjModel, f: FieldGeometry) -> None:
    """Give the compiled world the league's ball as Webots simulates it: the mass ODE gives it
    (:func:`league_ball_mass_kg`, a solid sphere of the field's radius), its speed and spin
    decaying as Webots damps them (v *= 0.23 ** t: a rate of -ln 0.23 = 1.47 per second, damping
    = rate x mass, rate x inertia on each axis), with sliding friction only. For the league's
    referee test scenarios, whose pushes were tuned to this ball; matches keep the match ball."""
    body = model.body(BALL_BODY).id
    mass = league_ball_mass_kg(f)
    inertia = 0.4 * mass * f.ball_radius_m**2
    model.body_mass[body] = mass
    model.body_inertia[body] = (inertia, inertia, inertia)
    mujoco.mj_setConst(model, mujoco.MjData(model))  # the solver's weights of the new mass
    rate = -math.log(1.0 - LEAGUE_BALL_DAMPING_PER_S)
    adr = int(model.joint(BALL_JOINT).dofadr[0])
    model.dof_damping[adr : adr + 3] = rate * mass
    model.dof_damping[adr + 3 : adr + 6] = rate * inertia
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
