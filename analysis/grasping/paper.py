"""Namiki, Nakabo, Ishii & Ishikawa 1999, registered once (entry point ``paper_replay.papers``):
everything of the grasp by name. Its method is ``replay/control/grasping/``, its plants the arm
rig's grasp plants (``plants/bullet_arm/grasp_plant.py``, ``plants/mujoco_arm/grasp_plant.py``),
its analysis this package, its scenarios ``scenarios/grasp_*.yaml``, its sweeps
``sweeps/grasp_*.yaml``."""

from replay.papers import Paper

PAPER = Paper(
    key="namiki1999",
    title="High Speed Grasping Using Visual and Force Feedback",
    authors="Namiki, Nakabo, Ishii & Ishikawa",
    text="004_9b0d52b607ebcc1f.txt",
    order=3,
    controllers={
        "grasp_recognition": "replay.control.grasping:RecognitionTask",
        "grasp_head": "replay.control.grasping:HeadTrackingTask",
        "grasp_arm": "replay.control.grasping:ArmControlTask",
        "grasp_hand": "replay.control.grasping:HandControlTask",
        "grasp_schedule": "replay.control.grasping:ScheduleTask",
    },
    plants={
        # the grasping rig, its engine plant.params.engine (PyBullet where empty)
        "grasp_rig": "plants.arm_rig.grasp_rig:GraspRig",
        "mujoco_grasp": "plants.mujoco_arm.grasp_plant:MujocoGraspPlant",  # (MuJoCo's flat: old logs)
    },
    renamed_plants={"bullet_grasp": "grasp_rig"},
    sensors={
        "vision_chip": "replay.sensors.vision_chip:VisionChipSensor",
        "wrist_ft": "replay.sensors.force:WristFTSensor",
        "hand_torque": "replay.sensors.force:HandTorqueSensor",
    },
    viewer_scenes={
        "grasp_rig": "plants.arm_rig.grasp_viewer_scene:GraspScene",
        "mujoco_grasp": "plants.mujoco_arm.viewer_scene:MujocoGraspScene",
    },
    figures="analysis.grasping.figures:make_figures",
    claims="analysis.grasping.claims:evaluate",
    layout="analysis.grasping.layout:layout",
    captions={9: "Feedback Response"},  # (Figs. 6-8, photo sequences: the filmstrip, named)
    named={
        "_filmstrip": "The run as a filmstrip of close-ups (cf. Figs. 6-8, the paper’s photo "
        "sequences “Experimental Result: Grasping of a Hexahedron” and “… of a Sphere”)",
    },
)
