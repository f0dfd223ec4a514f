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
        # (Figs. 6-8 are drawn as one filmstrip of the run, captioned by its file name)
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
