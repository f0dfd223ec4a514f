"""The bullet_arm plant's scenario parameters (checked by the loader before a run starts)."""

from __future__ import annotations

from dataclasses import dataclass

from replay.params import ParamError, param
from replay.robot.hand import CATCH_CLOSING_SPEED   # Namiki & Ishikawa IV-A: 90 deg in 20 ms
from replay.robot.hand import HANDS
from replay.robot.wam import TORQUE_LIMIT_SETS

_DOF = {"wam4": 4, "wam7": 7}
_JOINTS = tuple(f"J{i}" for i in range(1, 8))     # the WAM table's joint names (data/robots)


@dataclass
class Params:
    arm: str = param("wam4", choices=("wam4", "wam7"),
                     doc="Barrett WAM with 4 axes (J1-J4 + tool plate) or 7 axes (with wrist)")
    tool_d: float = param(-1.0, unit="m", ge=-10.0, le=2.0,
                          doc="tool frame offset along the last DH z axis; negative = the table's "
                              "(wam4: 0.35 m, the manual; libbarrett wam4.conf uses 0.36 m; "
                              "wam7: 0, the J7 flange)")
    base_position: list[float] = param([0.0, 0.0, 0.0], unit="m", length=3, ge=-100, le=100,
                                doc="world position of the base plate (J1 axis foot)")
    base_rpy: list[float] = param([0.0, 0.0, 0.0], unit="rad", length=3, ge=-10, le=10,
                           doc="base plate orientation, URDF roll-pitch-yaw")
    initial_q: list[float] = param([], unit="rad", ge=-10, le=10, max_length=7,
                            doc="initial arm joint angles, one per axis; [] = all zero. "
                                "Catching (Namiki & Ishikawa IV-A): [0, pi/4, 0, 0]")
    initial_qd: list[float] = param([], unit="rad/s", ge=-100, le=100, max_length=7,
                                   doc="initial arm joint velocities; [] = zero")
    locked_joints: list[str] = param([], choices=_JOINTS, max_length=7,
                                     doc="arm joints held rigidly at their initial angle "
                                        "(built as fixed joints), e.g. ['J3'] for catching")
    torque_limit_set: str = param(
        "public_urdf", choices=tuple(TORQUE_LIMIT_SETS),
        doc="named torque limits (wam.yaml notes: sources disagree): 'libbarrett' control-signal "
            "limits (25, 20, 15, 15, 5, 5, 5) N*m, or 'public_urdf' effort limits "
            "(60, 60, 45, 30, 10, 10, 10) N*m. Default public_urdf: libbarrett's numbers clamp "
            "the output of its PID joint controllers (a software setting), while a model's "
            "effort limit stands for what the actuators give; the paper's arm was driven harder "
            "than a stock WAM (5 m/s, 30 m/s^2). A scenario states which it uses")
    torque_limits: list[float] = param([], unit="N*m", ge=0.0, le=1e4, max_length=7,
                                doc="explicit |tau| limits per axis; [] = torque_limit_set")
    velocity_limits: list[float] = param([], unit="rad/s", gt=0.0, le=1000, max_length=7,
                                  doc="|qd| limits per axis; [] = 3.0 rad/s each (assumed, no "
                                      "table source)")
    enforce_velocity_limits: bool = param(
        False, doc="if true, a joint at its speed limit gets no torque further in its direction "
                   "of motion; if false, exceeding it is only reported (velocity_limit event)")
    hand: str = param("catch3", choices=("catch3", "grasp4", "none"),
                      doc="hand table: catch3 (3 fingers, 3 axes), grasp4 (4 fingers, 14 joints, "
                          "provisional sizes), none")
    hand_closing_speed: float = param(CATCH_CLOSING_SPEED, unit="rad/s", gt=0.0, le=1e4,
                                      doc="hand joints' speed limit; 90 deg in 20 ms = 78.54")
    hand_max_torque: float = param(2.0, unit="N*m", gt=0.0, le=1e3,
                                   doc="each hand joint's actuator torque limit (assumed)")
    hand_initial: list[float] = param([], unit="rad", ge=-10, le=10, max_length=64,
                                     doc="initial hand joint angles; [] = open")
    object: str = param("ball", choices=("ball", "box", "none"), doc="the free object")
    object_radius: float = param(0.0175, unit="m", gt=0.0, le=5,
                                 doc="ball radius; 35 mm diameter assumed (the paper gives none)")
    object_size: list[float] = param([0.05, 0.05, 0.05], unit="m", length=3, gt=0.0, le=10,
                              doc="box full extents")
    object_mass: float = param(0.025, unit="kg", gt=0.0, le=1000,
                               doc="assumed: a solid-rubber ball of 35 mm (~1.1 g/cm^3)")
    object_position: list[float] = param([1.5, 0.0, 1.0], unit="m", length=3, ge=-100, le=100,
                                  doc="initial centre of the object (world)")
    object_rpy: list[float] = param([0.0, 0.0, 0.0], unit="rad", length=3, ge=-10, le=10,
                             doc="initial orientation (roll-pitch-yaw)")
    object_velocity: list[float] = param([0.0, 0.0, 0.0], unit="m/s", length=3, ge=-1000,
                                        le=1000,
                                  doc="initial linear velocity")
    object_angular_velocity: list[float] = param([0.0, 0.0, 0.0], unit="rad/s", length=3,
                                                ge=-1e4, le=1e4,
                                          doc="initial angular velocity")
    object_gravity: bool = param(True, doc="gravity acts on the object (false: it floats)")
    object_albedo: float = param(0.9, unit="1", ge=0.0, le=1.0, doc="brightness seen by cameras")
    object_lateral_friction: float = param(0.8, unit="1", ge=0.0, le=10,
                                           doc="Coulomb coefficient (rubber, assumed)")
    object_rolling_friction: float = param(0.0, unit="m", ge=0.0, le=10,
                                           doc="PyBullet rolling friction")
    object_spinning_friction: float = param(0.0, unit="m", ge=0.0, le=10,
                                            doc="PyBullet spinning friction")
    object_restitution: float = param(0.6, unit="1", ge=0.0, le=1.0,
                                      doc="PyBullet restitution (multiplied with the robot's)")
    hand_lateral_friction: float = param(1.0, unit="1", ge=0.0, le=10,
                                         doc="Coulomb coefficient of palm/fingers (rubber pads)")
    hand_restitution: float = param(0.3, unit="1", ge=0.0, le=1.0,
                                    doc="PyBullet restitution of the robot's links")
    contact_stiffness: float = param(0.0, unit="N/m", ge=0.0, le=1e12,
                                     doc="object contact stiffness; 0 = PyBullet's rigid contact")
    contact_damping: float = param(0.0, unit="N*s/m", ge=0.0, le=1e9,
                                   doc="object contact damping (used with contact_stiffness)")
    solver_iterations: int = param(50, ge=1, le=1000, doc="PyBullet constraint solver iterations")
    gravity: float = param(9.81, unit="m/s^2", ge=0.0, le=100, doc="|g| along world -z")
    catch_hold_time: float = param(0.05, unit="s", gt=0.0, le=600,
                                   doc="catch: held this long (touching >= catch_min_parts of "
                                       "palm/fingers, moving with the hand)")
    catch_min_parts: int = param(2, ge=1, le=16, doc="distinct hand parts (palm, fingers) touching")
    catch_relative_speed: float = param(0.1, unit="m/s", gt=0.0, le=100,
                                        doc="max object speed relative to the palm when held")
    miss_height: float = param(0.0, unit="m", ge=-100, le=100,
                               doc="object centre below this world z: drop (after a catch) or "
                                   "miss")

    def __post_init__(self) -> None:
        """Lists sized for the arm and hand chosen (the plant needs one value per joint)."""
        dof = _DOF[self.arm]
        for name in ("initial_q", "initial_qd", "torque_limits", "velocity_limits"):
            n = len(getattr(self, name))
            if n not in (0, dof):
                raise ParamError(name, f"expected {dof} values for {self.arm} (or [] for the "
                                 f"default), got {n}")
        for i, j in enumerate(self.locked_joints):
            if j not in _JOINTS[:dof]:
                raise ParamError(f"locked_joints[{i}]", f"{self.arm} has joints "
                                 f"{', '.join(_JOINTS[:dof])}, not {j!r}")
        n_hand = len(HANDS[self.hand].joints) if self.hand != "none" else 0
        if self.hand_initial and len(self.hand_initial) != n_hand:
            raise ParamError("hand_initial", f"expected {n_hand} values for hand {self.hand!r} "
                             f"(or [] for open), got {len(self.hand_initial)}")
