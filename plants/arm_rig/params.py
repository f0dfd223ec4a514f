"""The arm rig's scenario parameters (checked by the loader before a run starts): what every
engine reads; each engine's own settings are in ``engine`` (plants/arm_rig/engine.py)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

from replay.params import ParamError, param
from replay.robot.hand import CATCH_CLOSING_SPEED  # Namiki & Ishikawa IV-A: 90 deg in 20 ms
from replay.robot.hand import HANDS
from replay.robot.wam import TORQUE_LIMIT_SETS

_DOF = {"wam4": 4, "wam7": 7}
_JOINTS = tuple(f"J{i}" for i in range(1, 8))  # the WAM table's joint names (data/robots)


@dataclass
class Params:
    arm: str = param(
        "wam4",
        choices=("wam4", "wam7"),
        doc="Barrett WAM with 4 axes (J1-J4 + tool plate) or 7 axes (with wrist)",
    )
    tool_d: float = param(
        -1.0,
        unit="m",
        ge=-10.0,
        le=2.0,
        doc="tool frame offset along the last DH z axis; negative = the table's "
        "(wam4: 0.35 m, the manual; libbarrett wam4.conf uses 0.36 m; "
        "wam7: 0, the J7 flange)",
    )
    base_position: list[float] = param(
        [0.0, 0.0, 0.0],
        unit="m",
        length=3,
        ge=-100,
        le=100,
        doc="world position of the base plate (J1 axis foot)",
    )
    base_rpy: list[float] = param(
        [0.0, 0.0, 0.0],
        unit="rad",
        length=3,
        ge=-10,
        le=10,
        doc="base plate orientation, URDF roll-pitch-yaw",
    )
    initial_q: list[float] = param(
        [],
        unit="rad",
        ge=-10,
        le=10,
        max_length=7,
        doc="initial arm joint angles, one per axis; [] = all zero. "
        "Catching (Namiki & Ishikawa IV-A): [0, pi/4, 0, 0]",
    )
    initial_qd: list[float] = param(
        [],
        unit="rad/s",
        ge=-100,
        le=100,
        max_length=7,
        doc="initial arm joint velocities; [] = zero",
    )
    locked_joints: list[str] = param(
        [],
        choices=_JOINTS,
        max_length=7,
        doc="arm joints held rigidly at their initial angle "
        "(built as fixed joints), e.g. ['J3'] for catching",
    )
    torque_limit_set: str = param(
        "public_urdf",
        choices=tuple(TORQUE_LIMIT_SETS),
        doc="named torque limits (wam.yaml notes: sources disagree): 'libbarrett' control-signal "
        "limits (25, 20, 15, 15, 5, 5, 5) N*m, or 'public_urdf' effort limits "
        "(60, 60, 45, 30, 10, 10, 10) N*m. Default public_urdf: libbarrett's numbers clamp "
        "the output of its PID joint controllers (a software setting), while a model's "
        "effort limit stands for what the actuators give; the paper's arm was driven harder "
        "than a stock WAM (5 m/s, 30 m/s^2). A scenario states which it uses",
    )
    torque_limits: list[float] = param(
        [],
        unit="N*m",
        ge=0.0,
        le=1e4,
        max_length=7,
        doc="explicit |tau| limits per axis; [] = torque_limit_set",
    )
    velocity_limits: list[float] = param(
        [],
        unit="rad/s",
        gt=0.0,
        le=1000,
        max_length=7,
        doc="|qd| limits per axis; [] = 3.0 rad/s each (assumed, no table source)",
    )
    enforce_velocity_limits: bool = param(
        False,
        doc="if true, a joint at its speed limit gets no torque further in its direction "
        "of motion; if false, exceeding it is only reported (velocity_limit event)",
    )
    hand: str = param(
        "catch3",
        choices=("catch3", "grasp4", "none"),
        doc="hand table: catch3 (3 fingers, 3 axes), grasp4 (4 fingers, 14 joints, "
        "provisional sizes), none",
    )
    hand_closing_speed: float = param(
        CATCH_CLOSING_SPEED,
        unit="rad/s",
        gt=0.0,
        le=1e4,
        doc="hand joints' speed limit; 90 deg in 20 ms = 78.54",
    )
    hand_max_torque: float = param(
        2.0, unit="N*m", gt=0.0, le=1e3, doc="each hand joint's actuator torque limit (assumed)"
    )
    hand_initial: list[float] = param(
        [], unit="rad", ge=-10, le=10, max_length=64, doc="initial hand joint angles; [] = open"
    )
    object: str = param("ball", choices=("ball", "box", "none"), doc="the free object")
    object_radius: float = param(
        0.0175,
        unit="m",
        gt=0.0,
        le=5,
        doc="ball radius; 35 mm diameter assumed (the paper gives none)",
    )
    object_size: list[float] = param(
        [0.05, 0.05, 0.05], unit="m", length=3, gt=0.0, le=10, doc="box full extents"
    )
    object_mass: float = param(
        0.025, unit="kg", gt=0.0, le=1000, doc="assumed: a solid-rubber ball of 35 mm (~1.1 g/cm^3)"
    )
    object_position: list[float] = param(
        [1.5, 0.0, 1.0],
        unit="m",
        length=3,
        ge=-100,
        le=100,
        doc="initial centre of the object (world)",
    )
    object_rpy: list[float] = param(
        [0.0, 0.0, 0.0],
        unit="rad",
        length=3,
        ge=-10,
        le=10,
        doc="initial orientation (roll-pitch-yaw)",
    )
    object_velocity: list[float] = param(
        [0.0, 0.0, 0.0], unit="m/s", length=3, ge=-1000, le=1000, doc="initial linear velocity"
    )
    object_angular_velocity: list[float] = param(
        [0.0, 0.0, 0.0], unit="rad/s", length=3, ge=-1e4, le=1e4, doc="initial angular velocity"
    )
    object_impulses: list[list[float]] = param(
        [],
        doc="external impulses on the object, [[t, Jx, Jy, Jz], "
        "...] (s, N*s, world): a disturbance such as a "
        "mid-flight kick (plants/arm_rig/impulse.py)",
    )
    object_gravity: bool = param(True, doc="gravity acts on the object (false: it floats)")
    object_albedo: float = param(0.9, unit="1", ge=0.0, le=1.0, doc="brightness seen by cameras")
    object_lateral_friction: float = param(
        0.8, unit="1", ge=0.0, le=10, doc="Coulomb coefficient (rubber, assumed)"
    )
    hand_lateral_friction: float = param(
        1.0, unit="1", ge=0.0, le=10, doc="Coulomb coefficient of palm/fingers (rubber pads)"
    )
    gravity: float = param(9.81, unit="m/s^2", ge=0.0, le=100, doc="|g| along world -z")
    catch_hold_time: float = param(
        0.05,
        unit="s",
        gt=0.0,
        le=600,
        doc="catch: held this long (touching >= catch_min_parts of "
        "palm/fingers, moving with the hand)",
    )
    catch_min_parts: int = param(2, ge=1, le=16, doc="distinct hand parts (palm, fingers) touching")
    catch_relative_speed: float = param(
        0.1, unit="m/s", gt=0.0, le=100, doc="max object speed relative to the palm when held"
    )
    miss_height: float = param(
        0.0,
        unit="m",
        ge=-100,
        le=100,
        doc="object centre below this world z: drop (after a catch) or miss",
    )

    engine: dict[str, Any] = param(
        {},
        omit_empty=True,
        doc="the physics engine and its settings, {type: ENGINE, ...}: type pybullet "
        "(object_rolling_friction, object_spinning_friction, object_restitution, "
        "hand_restitution, contact_stiffness, contact_damping, solver_iterations: flat here "
        "in older scenarios and logs, moved in on load) or mujoco (mj_solref, "
        "mj_limit_solref, mj_solimp, mj_cone, mj_condim, mj_iterations, mj_noslip_iterations, "
        "mj_integrator, hand_servo_gain: docs/mujoco.md) or drake (dk_contact_approximation, "
        "dk_contact_model, dk_hydroelastic_modulus, dk_point_stiffness, dk_dissipation, "
        "dk_hand_servo_gain: docs/drake.md), each engine's as `replay describe` gives them; "
        "empty: the plant type's own engine (PyBullet). Engines are registered in the entry "
        "point group paper_replay.engines (plants/arm_rig/engine.py)",
    )

    own_engine: ClassVar[str] = "pybullet"  # the engine where ``engine`` is empty

    @classmethod
    def migrate(cls, node: Any, *, log: bool) -> None:
        """An older form of these params (a YAML mapping: a scenario's, ``log``: a log's) made
        current in place before it is checked (replay/scenario/loader.py): PyBullet's settings
        given flat moved into ``engine`` (engine.py ``migrate_flat_settings``)."""
        from plants.arm_rig.engine import migrate_flat_settings

        migrate_flat_settings(node, cls.own_engine, log=log)

    def __post_init__(self) -> None:
        """Lists sized for the arm and hand chosen (the plant needs one value per joint); the
        engine's settings typed (``engine_settings``, not a field: ``engine`` keeps them as
        plain data, every default filled in)."""
        from plants.arm_rig.engine import engine_settings
        from replay.scenario.loader import to_plain

        self.engine_settings = engine_settings(self.engine)
        self.engine = {} if self.engine_settings is None else to_plain(self.engine_settings)
        dof = _DOF[self.arm]
        for name in ("initial_q", "initial_qd", "torque_limits", "velocity_limits"):
            n = len(getattr(self, name))
            if n not in (0, dof):
                raise ParamError(
                    name, f"expected {dof} values for {self.arm} (or [] for the default), got {n}"
                )
        for i, j in enumerate(self.locked_joints):
            if j not in _JOINTS[:dof]:
                raise ParamError(
                    f"locked_joints[{i}]",
                    f"{self.arm} has joints {', '.join(_JOINTS[:dof])}, not {j!r}",
                )
        n_hand = len(HANDS[self.hand].joints) if self.hand != "none" else 0
        if self.hand_initial and len(self.hand_initial) != n_hand:
            raise ParamError(
                "hand_initial",
                f"expected {n_hand} values for hand {self.hand!r} "
                f"(or [] for open), got {len(self.hand_initial)}",
            )


@dataclass
class GraspParams(Params):
    """The grasping rig (Namiki et al. 1999): velocity-commanded servos on the arm and hand, a
    pan/tilt head, a wrist F/T sensor, the object held by a human hand on a constraint plane.
    Every value here is an assumption unless a scenario says otherwise (the paper gives none)."""

    arm_servo_bandwidth: float = param(
        500.0,
        unit="rad/s",
        gt=0.0,
        le=1500.0,
        doc="closed-loop bandwidth of the arm's AC servo velocity loops (inertia-decoupled, "
        "plants/arm_rig/servo.py: every joint's; assumed ~80 Hz)",
    )
    plane_normal: list = param(
        [1.0, 0.0, 0.0],
        unit="1",
        length=3,
        doc="normal of the constraint plane through the object's initial "
        "centre (world); the human moves the object in it",
    )
    human_speed: float = param(
        0.10, unit="m/s", ge=0.0, doc="RMS in-plane speed of the human's path"
    )
    human_roll_rate: float = param(
        0.2, unit="rad/s", ge=0.0, doc="RMS rate of the human's roll about the plane normal"
    )
    human_f_min: float = param(0.1, unit="Hz", gt=0.0, doc="lowest frequency of the path")
    human_f_max: float = param(1.0, unit="Hz", gt=0.0, doc="band limit of the path")
    human_components: int = param(6, ge=1, limit="table_rows", doc="sinusoids per path axis")
    human_max_force: float = param(
        30.0,
        unit="N",
        gt=0.0,
        doc="limit on the magnitude of the human hand's total force on the object (grip and "
        "arm strength)",
    )
    human_stiffness: float = param(
        500.0,
        unit="N/m",
        gt=0.0,
        doc="stiffness of the human hand's hold about its path (assumed: a human arm's "
        "endpoint stiffness is ~200-1000 N/m)",
    )
    human_damping: float = param(
        10.0, unit="N*s/m", ge=0.0, doc="damping of the human hand's hold about its path"
    )
    human_rot_stiffness: float = param(
        0.5, unit="N*m/rad", ge=0.0, doc="rotational stiffness of the human's hold (assumed)"
    )
    human_rot_damping: float = param(
        0.01, unit="N*m*s/rad", ge=0.0, doc="rotational damping of the human's hold"
    )
    human_max_torque: float = param(
        1.0, unit="N*m", gt=0.0, doc="limit on the magnitude of the human hand's torque"
    )
    human_start: float = param(0.0, unit="s", ge=0.0, doc="the human starts moving at this time")
    human_kick_rate: float = param(
        0.0,
        unit="1/s",
        ge=0.0,
        le=100.0,  # (each kick is summed at every step: a bound, far above a human's)
        omit_empty=True,
        doc="sudden kicks of the human's path: a Poisson process of this mean rate (0: none), "
        "each a step of human_kick_speed in the path's in-plane velocity, in a random direction, "
        "lasting human_kick_duration (plants/arm_rig/human_path.py)",
    )
    human_kick_speed: float = param(
        0.0, unit="m/s", ge=0.0, le=10.0, omit_empty=True, doc="a kick's step in the path's speed"
    )
    human_kick_duration: float = param(
        0.0, unit="s", ge=0.0, le=10.0, omit_empty=True, doc="how long a kick's velocity step lasts"
    )
    head_position: list = param(
        [0.0, 0.0, 1.0], unit="m", length=3, doc="world point where the pan and tilt axes meet"
    )
    head_yaw: float = param(0.0, unit="rad", doc="heading of the head's base about world +z")
    head_camera_offset: float = param(
        0.03, unit="m", ge=0.0, doc="camera ahead of the tilt axis along the line of sight"
    )
    head_initial: list = param(
        [], unit="rad", doc="initial (pan, tilt); [] = looking at the object's centre"
    )
    head_lower: list = param([-1.5, -1.0], unit="rad", length=2, doc="(pan, tilt) lower stops")
    head_upper: list = param([1.5, 1.0], unit="rad", length=2, doc="(pan, tilt) upper stops")
    head_inertia: list = param(
        [2.0e-3, 1.0e-3],
        unit="kg*m^2",
        length=2,
        gt=0.0,
        doc="inertia about the pan and tilt axes (camera platform)",
    )
    head_torque_limit: list = param(
        [0.5, 0.5], unit="N*m", length=2, gt=0.0, doc="DC servo torque limits (pan, tilt)"
    )
    head_velocity_limit: list = param(
        [10.0, 10.0], unit="rad/s", length=2, gt=0.0, doc="(pan, tilt) speed the method may command"
    )
    head_servo_bandwidth: float = param(
        300.0, unit="rad/s", gt=0.0, doc="velocity-loop bandwidth of the head's DC servos"
    )
    slip_distance: float = param(
        0.001,
        unit="m",
        gt=0.0,
        doc="while grasped, the object moving this far in the hand's frame within slip_time "
        "starts a slip (a slip event: sustained relative motion, not one step's solver "
        "chatter); under half of it over slip_time ends it",
    )
    slip_time: float = param(0.01, unit="s", gt=0.0, doc="the window of slip_distance")
    grasp_max_drift: float = param(
        0.010,
        unit="m",
        gt=0.0,
        doc="held: during a grasp the object stays within this of where it sat in the hand "
        "(the hand's frame) when the grasp began",
    )
    grasp_max_human_offset: float = param(
        0.020,
        unit="m",
        gt=0.0,
        doc="with the human: during a grasp the object stays within this of the human hand's "
        "path (not carried away)",
    )
    grasp_max_off_plane: float = param(
        0.020,
        unit="m",
        gt=0.0,
        doc="on its plane: over the whole run the object stays within this of its constraint "
        "plane (the reach did not shove it off; the human's own tolerance, "
        "grasp_max_human_offset: 10 N on its 500 N/m hold)",
    )
    grasp_min_grasps: int = param(1, ge=1, doc="grasps a successful run has")
    grasp_min_hold: float = param(
        0.3,
        unit="s",
        ge=0.0,
        doc="a successful run holds one grasp at least this long while the human moves the object",
    )
