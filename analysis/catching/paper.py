"""Namiki & Ishikawa 2003, registered once (entry point ``paper_replay.papers``): everything of
the ball catch by name. Its methods are ``replay/control/catching/`` (and the compared
``predictive/``, ``feedback/``), its plants the arm rig's (``plants/bullet_arm/``,
``plants/mujoco_arm/``, ``plants/drake_arm/``), its analysis this package, its scenarios ``scenarios/catch_*.yaml``,
its sweeps ``sweeps/catch_*.yaml``."""

from replay.papers import Paper

PAPER = Paper(
    key="namiki2003",
    title="Robotic Catching Using a Direct Mapping from Visual Information to Motor Command",
    authors="Namiki & Ishikawa",
    text="000_e268676ea4c8a813.txt",
    order=2,
    controllers={
        "catching": "replay.control.catching:CatchingController",
        "predictive": "replay.control.predictive:PredictiveController",
        "feedback": "replay.control.feedback:FeedbackController",
    },
    plants={
        # the arm rig, its engine plant.params.engine (PyBullet where empty)
        "arm_rig": "plants.arm_rig.rig:ArmRig",
        "mujoco_arm": "plants.mujoco_arm.plant:MujocoArmPlant",  # (MuJoCo's flat: old logs)
    },
    renamed_plants={"bullet_arm": "arm_rig"},
    sensors={"stereo_ball": "replay.sensors.stereo:StereoBallCamera"},
    viewer_scenes={
        "arm_rig": "plants.arm_rig.viewer_scene:ArmScene",
        "mujoco_arm": "plants.mujoco_arm.viewer_scene:MujocoArmScene",
    },
    figures="analysis.catching.figures:make_figures",
    claims="analysis.catching.claims:evaluate",
    layout="analysis.catching.layout:layout",
    captions={
        6: "Optimization of cost functions",
        7: "Catching trajectory (with optimization).",
        8: "Time response of joint angles.",
        9: "Time response of joint command torques.",
    },
)
