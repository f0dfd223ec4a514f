"""The 2-step and 3-step capturing strategies (Higashimori et al. 2007, Sec. III) as controllers.

- :class:`TwoStepController` (Sec. III-B): the first collision stops the spin at
  theta_1 = alpha(v_0) (eqs. 30, 31); the closing then runs along the line of v_0 (eqs. 32, 33).
- :class:`ThreeStepController` (Sec. III-C): the first collision stops the translation at
  theta_1 = alpha(v_0) (eqs. 34, 35), the second stops the spin at theta_2 = alpha(lambda_2) and
  sends the stick along lambda_2 (eqs. 36, 37); then the closing (eq. 38).

Each gives the contacts of its collisions (``collision``) to the shared machinery of
:class:`~replay.control.stick.capture.StickCaptureController` (phases, hand plans, fallbacks,
events and the capture check: see ``capture``). Pure NumPy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from replay.params import ParamError, param
from replay.control.stick import collision as sc
from replay.control.stick.capture import StickCaptureController, StickCaptureParams
from replay.control.stick.estimator import StickEstimate
from replay.control.stick.hand_model import Config, HandModel

# Config and HandModel are re-exported: callers (the tests) model the hand with them
__all__ = [
    "TwoStepParams",
    "ThreeStepParams",
    "TwoStepController",
    "ThreeStepController",
    "Config",
    "HandModel",
]


# ------------------------------------------------------------------------------------------
# Parameters (the fields both share: stick_capture.StickCaptureParams)
# ------------------------------------------------------------------------------------------


@dataclass
class TwoStepParams(StickCaptureParams):
    pass


@dataclass
class ThreeStepParams(StickCaptureParams):
    lambda_2: list[float] = param(
        [1.0, 0.0],
        unit="1",
        length=2,
        ge=-1.0,
        le=1.0,
        doc="selection vector lambda_2 of eq. 36: the direction of v_2 "
        "(default: along world x, the stick perpendicular to the palm)",
    )
    lambda_2_auto_sign: bool = param(
        True,
        unit="1",
        choices=(True, False),
        doc="use -lambda_2 when that sends the stick toward the "
        "centre of the base range (tried first; the other "
        "sign only if it cannot be reached)",
    )

    def __post_init__(self) -> None:
        if math.hypot(*self.lambda_2) < 1e-6:
            raise ParamError("lambda_2", "expected a direction, got the zero vector")


# ------------------------------------------------------------------------------------------
# The strategies
# ------------------------------------------------------------------------------------------


class TwoStepController(StickCaptureController):
    """Sec. III-B: omega_1 = 0 at theta_1 = alpha(v_0) with p = -1 (eqs. 30, 31), then closing
    along the line of v_0 (eqs. 32, 33)."""

    Params: ClassVar[type] = TwoStepParams
    description = "Higashimori et al. 2007: 2-step friction independent stick capture"
    n_steps: ClassVar[int] = 1

    def _options(self, est, step):
        st = self.stick
        sol = sc.two_step_first(st.mass, st.inertia, st.restitution, est.u, st.length)
        return [] if sol is None else [sol]

    def _spin_stop(self, step):
        return step == 1


class ThreeStepController(StickCaptureController):
    """Sec. III-C: v_1 = 0 at theta_1 = alpha(v_0) (eqs. 34, 35), omega_2 = 0 at
    theta_2 = alpha(lambda_2) with v_2 along lambda_2 (eqs. 36, 37), then closing (eq. 38)."""

    Params: ClassVar[type] = ThreeStepParams
    description = "Higashimori et al. 2007: 3-step friction independent stick capture"
    n_steps: ClassVar[int] = 2
    _lam: tuple | None = None  # lambda_2 (unit), -lambda_2 and the centre of the base range

    def lambdas(self, est: StickEstimate) -> list[np.ndarray]:
        """lambda_2 (unit), and -lambda_2 first when auto-sign prefers it."""
        if self._lam is None:  # (from the params and the spec only)
            lam = np.asarray(self.params.lambda_2, dtype=float)
            lam = lam / np.linalg.norm(lam)
            centre = [0.5 * (lo + hi) for lo, hi in self.hand.base_limits]
            self._lam = (lam, -lam, centre)
        lam, neg, centre = self._lam
        if not self.params.lambda_2_auto_sign:
            return [lam]
        if lam[0] * (centre[0] - est.x) + lam[1] * (centre[1] - est.y) < 0.0:
            return [neg, lam]
        return [lam, neg]

    def _options(self, est, step):
        st = self.stick
        m, inertia, e = st.mass, st.inertia, st.restitution
        if step == 1:
            sol = sc.three_step_first(m, inertia, e, est.u, st.length)
            return [] if sol is None else [sol]
        out = []
        for lam in self.lambdas(est):
            sol = sc.three_step_second(m, inertia, e, est.u, lam, st.length)
            if sol is not None:
                out.append(sol)
        return out

    def _spin_stop(self, step):
        return step == 2

    def _finger_order(self, sol, step):
        if step != 2:
            return (0, 1), False
        v2 = np.array(sol.u_after[:2])
        proj = [float(np.dot(self.hand.root_offsets[k], v2)) for k in (0, 1)]
        rear = int(np.argmin(proj))  # the finger that pushes stays behind the stick
        return (rear, 1 - rear), True
