"""The engine-free arm rig: a WAM (4/7 axes), a hand, a free object and, for the grasping rig, a
head, a wrist F/T sensor and a human hand, as the physics engines' plants share it.

Nothing here imports a simulator: ``params`` and ``settings`` (the plug-ins' parameters and their
one resolver), the rig's state arithmetic (``arm_state``), its payloads, the catch and grasp
verdicts, the head, the human's path and the viewer scenes. The engines' plants are
``plants.bullet_arm`` (PyBullet) and ``plants.mujoco_arm`` (MuJoCo).
"""
