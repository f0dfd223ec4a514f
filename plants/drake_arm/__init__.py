"""Drake, the arm rig's third physics engine: pydrake's MultibodyPlant from the same robot tables
and URDF (``plants.models``), as the engine adapters ``DrakeEngine`` (the catching rig) and
``DrakeGraspEngine`` (the grasping rig), chosen by ``plant.params.engine: {type: drake, ...}``.

``params`` (``DrakeSettings``, registered in ``paper_replay.engines``) imports no simulator; the
adapters (pydrake) are imported when a rig asks for them. docs/drake.md says what differs from
PyBullet and MuJoCo and why.
"""
