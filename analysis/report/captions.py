"""The papers' own figure captions (quoted from the texts in shared/papers/), by paper and number."""

CAPTIONS = {
    "higashimori2007": {
        6: "A series of photos during the 3-step capturing strategy.",
        7: "Translational and rotational velocities with respect to time during the 3-step "
        "capturing strategy.",
    },
    "namiki2003": {
        6: "Optimization of cost functions",
        7: "Catching trajectory (with optimization).",
        8: "Time response of joint angles.",
        9: "Time response of joint command torques.",
    },
    "namiki1999": {
        # (Figs. 6-8, photo sequences, are drawn as one filmstrip of the run: NAMED)
        9: "Feedback Response",
    },
}

# the method a figure of the paper is drawn for, where its caption names one: the same figure of
# a run of another method is captioned "cf." and names both (a 2-step run's Fig. 7 is not the
# paper's 3-step Fig. 7)
DRAWN_FOR = {
    ("higashimori2007", 6): "stick_3step",
    ("higashimori2007", 7): "stick_3step",
}

# the figures that draw no one figure of the paper, by paper and how their file name ends (a
# stick strategy's runs at several frictions, an experiment's variants, a grasp run's filmstrip)
NAMED = {
    "higashimori2007": {
        "_friction": "Friction independence: the velocities of the runs of one strategy at "
        "each friction μ (cf. Fig. 7)",
        "_variants": "The runs of one experiment overlaid, each labelled by what it sets "
        "differently (cf. Fig. 7)",
    },
    "namiki1999": {
        "_filmstrip": "The run as a filmstrip of close-ups (cf. Figs. 6-8, the paper’s photo "
        "sequences “Experimental Result: Grasping of a Hexahedron” and “… of a Sphere”)",
    },
}
