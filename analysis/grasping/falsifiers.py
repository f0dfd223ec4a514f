"""The variants under which a measured row of the grasp's claims table must turn to "differs"
(``replay falsify``; analysis/claims.py)."""

from __future__ import annotations

from analysis.claims import Falsifier


STABLE = "stable grasping: held while the human moves the object, compliant to the human's force"

_NO_FORCE = {"tasks.arm.params.K_af": 0.0}

_WEAK_TRACKING = {"tasks.arm.params.K_a1": [0.0, 2.0, 2.0, 1.0, 0.0, 0.0]}

# the recognition's shape thresholds set out of their range (the hand preshapes by the recognised
# shape's name, so a wrong preshape needs a wrong shape): the switch that removes the preshape.
# Not a falsifier: with it the object is still grasped, so the preshape row compares labels and
# is a configuration row; kept for the grasp component ablation (issue #38)
_MISJUDGE = {
    "box": (
        "box seen as a circle",
        {
            "tasks.vision.params.rectangle_elongation": 3.0,
            "tasks.vision.params.rectangle_fill": 0.999,
        },
        "the recognition's thresholds out of range (a rectangle only when elongated 3:1 or "
        "filling 99.9 % of its box; the 10 x 5 cm box is 1.6-2.0 and rolled): the box is "
        "judged a circle and the hand preshapes for a ball",
    ),
    "ball": (
        "ball seen as a rectangle",
        {"tasks.vision.params.rectangle_elongation": 1.0},
        "the recognition's elongation threshold at its floor (1.0: every target is elongated "
        "at least that much): the ball is judged a rectangle and the hand preshapes for a box",
    ),
}

_OBJECT = {"grasp_hexahedron": "box", "grasp_sphere": "ball", "grasp_cycle": "box"}


def _falsifiers(name: str) -> tuple[Falsifier, ...]:
    """The variants of scenario ``name`` that must turn each measured row to "differs" (a
    merged row differs as soon as one run's part does)."""
    return (
        Falsifier(
            "tracking 0.0-0.5, reaching and grasping done at 0.8, read as seconds",
            "slow reach",
            name,
            {"tasks.schedule.params.reach_time": 0.6},
            "a 0.6 s reach brings the grasp to ~1.1 s",
        ),
        Falsifier(
            "the hand meets the object without impact (first contact speed)",
            "fingers slam shut",
            name,
            {"tasks.hand.params.touch_speed": 78.5},
            "the fingers cross the last clearance at the drives' full speed (78.5 rad/s, the "
            "hand's limit) instead of 4 rad/s: they strike the object",
        ),
        Falsifier(
            STABLE,
            "no force feedback",
            name,
            _NO_FORCE,
            "K^af = 0: the arm does not yield to the human, who is left behind: the held "
            "object is carried away from the human's path, the human pulls it with all its "
            "strength",
        ),
        Falsifier(
            "tracking error on the plane (Y, Z), releasing and tracking phases",
            "weak tracking gain",
            name,
            _WEAK_TRACKING,
            "eq. 2's K^a1 2 1/s: the hand lags the object by far more than a fifth of its "
            "excursion",
        ),
        Falsifier(
            "eq. 1 keeps the target at the image centre",
            "slow head",
            name,
            {"tasks.head.params.K_v": [2.0, 2.0]},
            "eq. 1's K^v 2 1/s: the head lags the moving object by pixels",
        ),
        Falsifier(
            "eq. 3's partition: tracking unaffected by reaching",
            "look then move",
            name,
            {"tasks.arm.params.reach_tracking": 0.0},
            "no S K^a1 term while reaching (a sequential controller that stops tracking to "
            "reach): the object moves on in the plane while the hand goes straight in",
        ),
        Falsifier(
            "the hand's X follows the reaching trajectory (Fig. 9)",
            "weak reach gain",
            name,
            {"tasks.arm.params.K_a2": [4.0, 0.0, 0.0, 0.0, 20.0, 20.0]},
            "eq. 2's K^a2 4 1/s on X: the hand lags the reaching trajectory",
        ),
    )


FALSIFIERS: tuple[Falsifier, ...] = _falsifiers("grasp_hexahedron")
