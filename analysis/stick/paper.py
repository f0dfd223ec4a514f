"""Higashimori et al. 2007, registered once (entry point ``paper_replay.papers``): everything of
the stick capture by name. Its method is ``replay/control/stick/``, its plant ``plants/airtable/``,
its analysis this package, its scenarios ``scenarios/stick_*.yaml``, its sweeps
``sweeps/stick_*.yaml``."""

from replay.papers import Paper

PAPER = Paper(
    key="higashimori2007",
    title="Friction Independent Dynamic Capturing Strategy for a 2D Stick-shaped Object",
    authors="Higashimori, Kimura, Ishii & Kaneko",
    text="002_9fb29b566fa62b9e.txt",
    order=1,
    controllers={
        "stick_2step": "replay.control.stick.strategy:TwoStepController",
        "stick_3step": "replay.control.stick.strategy:ThreeStepController",
    },
    plants={"airtable": "plants.airtable:AirTablePlant"},
    sensors={"stick_camera": "plants.airtable.camera:StickCamera"},
    viewer_scenes={"airtable": "plants.airtable.viewer_scene:AirTableScene"},
    figures="analysis.stick.figures:make_figures",
    claims="analysis.stick.claims:evaluate",
    layout="analysis.stick.layout:layout",
    captions={
        6: "A series of photos during the 3-step capturing strategy.",
        7: "Translational and rotational velocities with respect to time during the 3-step "
        "capturing strategy.",
    },
    drawn_for={6: "stick_3step", 7: "stick_3step"},
    named={
        "_friction": "Friction independence: the velocities of the runs of one strategy at "
        "each friction μ (cf. Fig. 7)",
        "_variants": "The runs of one experiment overlaid, each labelled by what it sets "
        "differently (cf. Fig. 7)",
    },
)
