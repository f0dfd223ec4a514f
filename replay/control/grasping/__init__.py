"""High-speed grasping with visual and force feedback (Namiki, Nakabo, Ishii & Ishikawa 1999):
the loops of Fig. 4 as separate 1 ms tasks, simulator-free (floats and NumPy).

- ``recognition`` (Sec. 4.1.1): Self Windowing, moments, x^o on the constraint plane, shape;
- ``head_tracking`` (eq. 1), ``arm_control`` (eqs. 2-3), ``hand_control`` (eq. 4, preshaping);
- ``schedule``: grasp/release phases and the reaching target x_d^a, given beforehand (Fig. 9).
"""

from replay.control.grasping.arm_control import ArmControlTask
from replay.control.grasping.hand_control import HandControlTask
from replay.control.grasping.head_tracking import HeadTrackingTask
from replay.control.grasping.recognition import RecognitionTask
from replay.control.grasping.schedule import ScheduleTask

__all__ = [
    "ArmControlTask",
    "HandControlTask",
    "HeadTrackingTask",
    "RecognitionTask",
    "ScheduleTask",
]
