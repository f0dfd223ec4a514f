"""Drake's contact and solver settings: ``DrakeSettings``, the engine field's
(``plant.params.engine: {type: drake, ...}``, plants/arm_rig/engine.py). The rig's own params
(robot, hand, object, limits, catch criterion, friction) are the arm rig's; PyBullet's contact
settings (``PybulletSettings``) are not Drake's: Drake's point contact has no restitution
coefficient; the bounce is set by its Hunt-Crossley dissipation (docs/drake.md)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from replay.params import param


@dataclass
class DrakeSettings:
    """``plant.params.engine`` of type drake: its settings and adapters."""

    type: str = param(
        "drake", choices=("drake",), doc="the engine: Drake (pydrake's MultibodyPlant)"
    )
    dk_contact_approximation: str = param(
        "lagged",
        choices=("sap", "similar", "lagged"),
        doc="Drake's discrete contact approximation, each solved by its SAP solver (convex: joint "
        "limits and the hand's PD servos are constraints solved with the contacts, implicitly, "
        "as PyBullet's). lagged (Drake's default) and similar use the Hunt-Crossley "
        "dissipation below; sap its own linear model",
    )
    dk_contact_model: str = param(
        "point",
        choices=("point", "hydroelastic"),
        doc="point: one contact point per geometry pair (Drake's point contact, the stiffness "
        "and dissipation below); hydroelastic: pressure-field contact patches between "
        "compliant geometries (every robot geometry and the object, the modulus below; "
        "~2.3x the grasp's CPU). Point chosen; hydroelastic holds the box where point contact "
        "lets it walk along the hand at 0.3 m/s (docs/drake.md)",
    )
    dk_hydroelastic_modulus: float = param(
        5.0e6,
        unit="Pa",
        gt=0.0,
        le=1e12,
        doc="hydroelastic modulus of every geometry (dk_contact_model: hydroelastic only). "
        "Assumed: hard rubber (a few MPa), meshes refined to 1 cm",
    )
    dk_point_stiffness: float = param(
        1.0e5,
        unit="N/m",
        gt=0.0,
        le=1e9,
        doc="point contact stiffness of every object-robot contact (the pair's, after Drake's "
        "series combination). Assumed: a 25 g ball at 9.5 m/s would sink 4.8 mm, its contact "
        "lasting 1.6 ms (two steps); x0.5 and x2 catch and grasp alike (docs/drake.md)",
    )
    dk_dissipation: float = param(
        10.0,
        unit="s/m",
        ge=0.0,
        le=1e4,
        doc="Hunt-Crossley dissipation of every object-robot contact (Drake's documentation: "
        "1-50 s/m are physical). Assumed 10: a ball driven at the held arm's palm at 1.3 m/s "
        "comes back at 0.08 of its speed, as in the MuJoCo plant (0.08); at 6 m/s at 0.02 "
        "(MuJoCo 0.11): Hunt-Crossley's bounce falls with the speed (0 s/m: 0.22 at both)",
    )
    dk_hand_servo_gain: float = param(
        100.0,
        unit="N*m*s/rad",
        gt=0.0,
        le=1e6,
        doc="velocity gain (Kd) of each hand joint's PD servo (Kp = 0), implicit in SAP and "
        "capped at hand_max_torque in the same solve as the contacts: PyBullet's velocity motor "
        "(a capped constraint); the MuJoCo plant's gain",
    )

    arm: ClassVar[str] = "plants.drake_arm.plant:DrakeEngine"
    grasp: ClassVar[str] = "plants.drake_arm.grasp_plant:DrakeGraspEngine"
