"""Robot models without a simulator: serial-chain kinematics/dynamics, the WAM, hand tables.

Pure NumPy (no simulator import): controllers and analysis may use these freely.
"""

from replay.robot.arm_types import ArmCommand, ArmSpec, HandSpec, ObjectSpec
from replay.robot.serial_chain import DHRow, RigidBody, SerialChain
from replay.robot.wam import wam_chain

__all__ = [
    "ArmCommand",
    "ArmSpec",
    "HandSpec",
    "ObjectSpec",
    "DHRow",
    "RigidBody",
    "SerialChain",
    "wam_chain",
]
