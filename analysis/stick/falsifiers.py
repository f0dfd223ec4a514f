"""The variants under which a reproduced row of the stick's claims table must turn to "differs"
(``replay falsify``; analysis/claims.py)."""

from __future__ import annotations

from analysis.claims import Falsifier

_CAM_OFF = {"sensors.camera.params.position_offset": [0.005, 0.0]}

_SLOW = {"plant.params.hand.joint_speed": 2.0}

_WIDE = {"plant.params.stick.collision_width": 0.010}


FALSIFIERS: tuple[Falsifier, ...] = (
    Falsifier(
        "translation after collision 1",
        "width10",
        "stick_3step",
        _WIDE,
        "the real 10 mm width: contact on the face at W/2 lets friction act (Assumption 5 "
        "dropped), so collision 1 leaves the stick translating",
    ),
    Falsifier(
        "spin reversed at collision 1 (eq. 35)",
        "omega0_30",
        "stick_3step",
        {"plant.params.initial.omega": 30.0},
        "at ω_0 = 30 rad/s the opposite-sign root of eq. 34 needs |r_x| > L/2: the plan keeps the "
        "same-sign one",
    ),
    Falsifier(
        "3-step: translation reversed at each closing collision (eq. 33, i ≥ 3)",
        "camera_offset_2mm_y",
        "stick_3step",
        {"sensors.camera.params.position_offset": [0.0, 0.002]},
        "a camera 2 mm (1 px) off along the stick's axis after collision 2: the closing hits "
        "miss the centre of mass (eq. 32's r_x = 0), so they leave spin and turn the stick",
    ),
    Falsifier(
        "stick_3step: captured",
        "slow_fingers",
        "stick_3step",
        _SLOW,
        "finger joints at 2 rad/s instead of 14: the fingertips cannot reach the closing spots",
    ),
    Falsifier(
        "v_2 along an arbitrary ±λ_2, stick perpendicular to it (eqs. 17, 37)",
        "camera_offset_5mm",
        "stick_3step",
        _CAM_OFF,
        "a camera 5 mm off (3 px): collision 1 leaves translation, so collision 2 is not the "
        "friction-independent one eq. 37 plans",
    ),
    Falsifier(
        "stick_3step_width10_long: captured",
        "slow_fingers",
        "stick_3step_width10_long",
        _SLOW,
        "finger joints at 2 rad/s instead of 14: the fingertips cannot reach the closing spots",
    ),
    Falsifier(
        "stick_2step: captured",
        "slow_fingers",
        "stick_2step",
        _SLOW,
        "finger joints at 2 rad/s instead of 14: the hand cannot follow the stick (the 2-step "
        "needs a quick hand, Sec. III-B)",
    ),
    Falsifier(
        "2-step: collision 1",
        "camera_offset_5mm",
        "stick_2step",
        _CAM_OFF,
        "a camera 5 mm off (3 px): the fingertip hits off the r_x of eq. 30, spin remains",
    ),
    Falsifier(
        "2-step: translation reversed at each closing collision (eq. 33, i ≥ 2)",
        "camera_offset_5mm",
        "stick_2step",
        _CAM_OFF,
        "a camera 5 mm off (3 px): spin left by collision 1, closing hits not through the "
        "centre of mass",
    ),
    Falsifier(
        "first collision outcome across μ",
        "width10_mu1",
        "stick_3step_mu1",
        _WIDE,
        "μ = 1 on the real 10 mm width: the contact on the face slides, friction acts",
    ),
    Falsifier(
        "3-step strategy across μ (captured at every μ)",
        "width10_mu1",
        "stick_3step_mu1",
        _WIDE,
        "μ = 1 on the real 10 mm width: the contact on the face slides, friction acts",
    ),
    Falsifier(
        "2-step strategy across μ (collision 1 and capture at every μ)",
        "slow_fingers_mu1",
        "stick_2step_mu1",
        _SLOW,
        "no variant of μ or width alone breaks the 2-step here (μ = 1 at W = 30 mm changes "
        "collision 1 by < 0.005 m/s); slow fingers at μ = 1 show the row can fail",
    ),
)
