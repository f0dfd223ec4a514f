"""The gains of eqs. 1, 2 and 4 at another loop period: a discrete-time redesign that keeps each
loop's closed-loop pole where the 1 ms design put it (Namiki et al. 1999 tune nothing for other
periods: every loop runs at 1 ms, Sec. 2; the default gains are assumed, tuned at 1 ms).

Each loop is a proportional velocity command on an integrating joint, sampled and held at the
task's period T (the velocity servos, 2 ms and faster, are neglected):

- **direct** loops measure their own state fresh (the arm's x^a and the hand's theta^h from the
  encoders; eqs. 2, 4): x[k+1] = x[k] + T K (r - x[k]), one pole z = 1 - K T. The 1 ms design
  K1 has z1 = 1 - K1 T1, a continuous-time rate lambda = -ln(1 - K1 T1) / T1 (K^a1 = 60 1/s:
  61.9 1/s). At T the pole is kept, z = exp(-lambda T):

      K(T) = (1 - exp(-lambda T)) / T                                       (direct)

- the **head** (eq. 1) sees its error through the chip's image, one frame (T) late:
  x[k+1] = x[k] + T K (r - x[k-1]), z^2 - z + K T = 0. The 1 ms design's dominant root
  p1 = (1 + sqrt(1 - 4 K1 T1)) / 2 gives lambda = -ln(p1) / T1 (K^v = 60 1/s: 66.2 1/s); at T the
  dominant root is kept, p = exp(-lambda T), the other is 1 - p, so K T = p (1 - p). The roots
  stay real (no overshoot, as at 1 ms) only while p >= 1/2; beyond that (T > ln 2 / lambda,
  10.5 ms) the fastest well-damped loop is the critically damped one, a double root at 1/2:

      K(T) = p (1 - p) / T,   p = max(exp(-lambda T), 1/2)                   (delayed)

A loop with the gains of 1 ms at 33 ms has K T = 1.98: the head's roots leave the unit circle
(K T > 1) and the arm's pole sits at -0.98 (a sign-flipping oscillation): a lost loop, not a lack
of information. tests/control/grasping/test_gain_rule.py steps both loops (with the servo lags)
at 1-33 ms.
"""

from __future__ import annotations

import math

DESIGN_PERIOD = 0.001  # s: the period the tasks' default gains are tuned for (Sec. 2's 1 ms)


def direct_rate(k1: float, design: float = DESIGN_PERIOD) -> float:
    """lambda (1/s) of a direct loop with gain ``k1`` (1/s) at period ``design`` (s)."""
    if not 0.0 <= k1 * design < 1.0:
        raise ValueError(f"a gain of {k1} 1/s at {design} s has no real decaying pole")
    return -math.log1p(-k1 * design) / design


def direct_gain(k1: float, period: float, design: float = DESIGN_PERIOD) -> float:
    """K(T) of a direct loop: the pole of ``k1`` at ``design`` kept at ``period`` (s)."""
    if k1 == 0.0:
        return 0.0
    return -math.expm1(-direct_rate(k1, design) * period) / period


def delayed_rate(k1: float, design: float = DESIGN_PERIOD) -> float:
    """lambda (1/s): the dominant root's rate of a one-frame-late loop with gain ``k1``."""
    if not 0.0 <= 4.0 * k1 * design <= 1.0:
        raise ValueError(f"a gain of {k1} 1/s at {design} s with a frame's latency oscillates")
    return -math.log((1.0 + math.sqrt(1.0 - 4.0 * k1 * design)) / 2.0) / design


def delayed_gain(k1: float, period: float, design: float = DESIGN_PERIOD) -> float:
    """K(T) of a one-frame-late loop: its dominant root kept, at most critically damped."""
    if k1 == 0.0:
        return 0.0
    p = max(math.exp(-delayed_rate(k1, design) * period), 0.5)
    return p * (1.0 - p) / period


def direct_gains(gains: list, period: float) -> list[float]:
    """Each of ``gains`` by :func:`direct_gain` (``period`` 0: as given, the fixed rule)."""
    return [direct_gain(k, period) if period > 0.0 else float(k) for k in gains]


def scale(k1: float, period: float) -> float:
    """K(T) / K(T1) of a direct loop with ``k1``: the factor a loop gain shares with it."""
    return direct_gain(k1, period) / k1 if period > 0.0 and k1 > 0.0 else 1.0


def check_period(rule_period: float, measured: float, task: str) -> None:
    """The discrete rule's ``gain_period`` must be the task's loop period (its rate)."""
    if rule_period > 0.0 and abs(measured - rule_period) > 1e-6 + 1e-3 * rule_period:
        raise ValueError(
            f"{task}: gain_period {rule_period} s, but the task runs every {measured:.6g} s "
            "(set gain_period to 1 / the task's rate)"
        )
