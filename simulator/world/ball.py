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


# The league's ball's contacts as ODE makes them (hlvs_webots ``worlds/robocup.wbt:30-45``; the
# defaults of a ``ContactProperties`` field the world leaves out: coulombFriction 1,
# bounceVelocity 0.01, softERP 0.2, softCFM 0.001, cyberbotics/webots
# ``docs/reference/contactproperties.md``). An ODE contact is a constraint on the normal
# velocity, softened by ERP and CFM: ``J v' = c - CFM f`` with ``c = ERP depth / h`` (ODE
# ``joint.cpp``, ``dxJointContact::getInfo2``; ``step.cpp`` scales CFM by 1/h), and with a
# bounce ``c`` is raised to ``bounce`` times the approaching speed (when above
# bounceVelocity). That is a spring and damper per contact, ``kp = ERP / (h CFM)``,
# ``kd = (1 - ERP) / CFM`` (ODE manual, "Soft constraint and constraint force mixing"), plus the
# bounce's kick, which reaches only ``(h/m) / (h/m + CFM)`` of its target in a step:
#
# - ball and grass (``coulombFriction 0.5, bounce 0.76, softCFM 0.05``): kp = 500 N/m,
#   kd = 16 N s/m, for the 0.0791 kg ball 6,320 s^-2 and 202 s^-1, over-damped (the spring
#   alone does not bounce); the kick reaches 67 % of its target, so the ball leaves the grass
#   at 0 to 0.17 of the speed it came at, depending on how deep the 8 ms step found it
#   (dropped from 0.5 m, 1 m and 1.5 m: 0.05, 0.08, 0.09 of it on average over the step's
#   phase): the grass takes a dropped ball dead. Here the pair ball-turf is that spring and
#   damper in MuJoCo's direct form (per kg of ball), which keeps 0.08 to 0.10 of a normal
#   speed of 0.5 to 4 m/s, with sliding friction 0.5 and no rolling friction.
# - ball and anything else, the robots among it (``bounce 0.76``, softCFM 0.001): the kick
#   reaches 99 % of its target, the ball leaves at 0.742 of the relative speed it came at
#   (0.76 x 0.99 - 0.01), with Coulomb friction 1 and no rolling friction; kp = 25,000 N/m,
#   316,000 s^-2 for the ball, and the bounce met in the one 8 ms step that finds the contact:
#   the ball leaves a robot in that step. Here the ball's contact spring is 100,000 s^-2 (the
#   stiffest at which MuJoCo's 2 ms step keeps the restitution steady: at 316,000 it came back
#   at 0.57 to 0.83 of 0.5 to 8 m/s, at 200,000 at 0.69 to 0.77), its damping keeping 0.73 to
#   0.76 of the normal speed at 0.5 to 8 m/s (fitted on a 0.0791 kg sphere thrown at a fixed
#   box at a 2 ms step): the contact lasts 10 ms, 2.7 mm deep per m/s. The match ball's
#   10,000 s^-2 held it 32 ms, 8 mm deep per m/s: pushed into a robot's knees it touched
#   them for four basic steps (the league's referee then saw it touched once it was in play,
#   ``referee.py:2162``, where ODE's ball had left) and sank far enough to meet both legs.
BALL_TURF_PAIR = "ball:turf"
ODE_STEP_S = 0.008  # worlds/robocup.wbt:23, basicTimeStep 8
ODE_SOFT_ERP = 0.2
LEAGUE_GRASS_BALL_SOFT_CFM = 0.05
LEAGUE_GRASS_BALL_FRICTION = 0.5
LEAGUE_BALL_ROBOT_FRICTION = 1.0
LEAGUE_BALL_ROBOT_SOLREF = (-100000.0, -57.0)  # restitution 0.74, 10 ms (see above)


def ode_contact_spring(mass_kg: float, soft_cfm: float) -> tuple[float, float]:
    """(stiffness, damping) per kg of ``mass_kg`` of ODE's soft contact of ``soft_cfm`` at the
    league's ERP and step: ``kp = ERP / (h CFM)``, ``kd = (1 - ERP) / CFM``."""
    kp = ODE_SOFT_ERP / (ODE_STEP_S * soft_cfm)
    kd = (1.0 - ODE_SOFT_ERP) / soft_cfm
    return kp / mass_kg, kd / mass_kg


def use_league_contacts(model: mujoco.MjModel) -> None:
    """Give the compiled world (built with the ball-turf pair, :data:`BALL_TURF_PAIR`) the
    league's ball contacts as ODE makes them (above): with the turf ODE's soft contact spring
    for the ball's present mass, sliding friction 0.5; with the robots and goals restitution
    0.74 within about one basic step, Coulomb friction 1; no rolling or torsional friction on
    either (condim 3). For the league's referee test scenarios; matches keep the match ball's
    contacts."""
    geom = model.geom(BALL_GEOM).id
    mass = float(model.body_mass[model.body(BALL_BODY).id])
    model.geom_condim[geom] = 3
    model.geom_solref[geom] = LEAGUE_BALL_ROBOT_SOLREF
    model.geom_friction[geom] = (LEAGUE_BALL_ROBOT_FRICTION, 0.0, 0.0)
    pair = model.pair(BALL_TURF_PAIR).id
    stiffness, damping = ode_contact_spring(mass, LEAGUE_GRASS_BALL_SOFT_CFM)
    model.pair_dim[pair] = 3
    model.pair_solref[pair] = (-stiffness, -damping)
    model.pair_solimp[pair] = model.geom_solimp[geom]
    model.pair_friction[pair] = (LEAGUE_GRASS_BALL_FRICTION,) * 2 + (0.0,) * 3
