"""Velocity estimation and trajectory prediction of the stick from high-speed vision.

Higashimori et al. 2007, Sec. IV-A: "PC estimates the velocity and predicts the trajectory of
object" from 300 fps measurements of position and orientation. Between collisions the stick moves
with constant velocities (Assumption 6), so x, y and theta are fitted as straight lines in time by
least squares over a sliding window of the latest samples.

Orientation: a camera sees a stick's axis only modulo pi (theta in (-pi/2, pi/2]). Each sample is
unwrapped to the branch theta + k pi nearest the current prediction (or the previous sample), so
the estimator's theta is continuous; it aliases only beyond pi/2 of rotation between samples
(471 rad/s at 300 fps).

Collisions: once the fit is ready (``min_samples`` since the last restart: a shorter fit
extrapolates too noisily), a sample farther than ``pos_tol`` (m) or ``theta_tol`` (rad) from the
prediction of the current fit breaks the constant-velocity model. With
``confirm`` = 2 (default) the break is accepted when the next sample deviates too (an isolated
outlier is dropped); the fit then restarts from the deviating samples, and
:meth:`StickEstimator.add` returns True.

Defaults (SI): window 30 samples (0.1 s at 300 fps), ready after 6 samples (20 ms), pos_tol
0.002 m, theta_tol 0.03 rad, confirm 2. Pure Python (running sums, a closed-form fit).
"""

from __future__ import annotations

import math
from dataclasses import dataclass


REANCHOR = 1.0  # s, the running sums are rebuilt from the window once their anchor is this old


@dataclass(frozen=True, init=False)
class StickEstimate:
    """The constant-velocity fit, evaluated at ``t_ref`` (the latest sample's time)."""

    t_ref: float  # s
    x: float  # m
    y: float  # m
    theta: float  # rad, continuous (unwrapped)
    vx: float  # m/s
    vy: float  # m/s
    omega: float  # rad/s
    n: int  # samples in the fit
    rms_xy: float  # m, residual rms of the position fit
    rms_theta: float  # rad, residual rms of the orientation fit

    def __init__(
        self,
        t_ref: float,
        x: float,
        y: float,
        theta: float,
        vx: float,
        vy: float,
        omega: float,
        n: int,
        rms_xy: float,
        rms_theta: float,
    ) -> None:
        # the fields straight into the instance's dict (a frozen dataclass's generated __init__ sets
        # each through object.__setattr__, ~1 us a field on Python 3.11; test_stick_fast_paths.py
        # holds this one to the generated one's result)
        d = self.__dict__
        d["t_ref"], d["x"], d["y"], d["theta"] = t_ref, x, y, theta
        d["vx"], d["vy"], d["omega"] = vx, vy, omega
        d["n"], d["rms_xy"], d["rms_theta"] = n, rms_xy, rms_theta

    @property
    def u(self) -> tuple[float, float, float]:
        """(vx, vy, omega), the paper's u_B."""
        return (self.vx, self.vy, self.omega)

    @property
    def speed(self) -> float:
        return math.hypot(self.vx, self.vy)

    def at(self, t: float) -> tuple[float, float, float]:
        """Pose (x, y, theta) at time ``t`` under constant velocities."""
        dt = t - self.t_ref
        return (self.x + self.vx * dt, self.y + self.vy * dt, self.theta + self.omega * dt)


def unwrap_to(theta_mod_pi: float, near: float) -> float:
    """The branch theta + k pi closest to ``near``."""
    return theta_mod_pi + math.pi * round((near - theta_mod_pi) / math.pi)


class StickEstimator:
    """Sliding-window least-squares fit of x, y, theta linear in t, with collision detection."""

    def __init__(
        self,
        *,
        window: int = 30,
        min_samples: int = 6,
        pos_tol: float = 0.002,
        theta_tol: float = 0.03,
        confirm: int = 2,
    ) -> None:
        if window < 2 or min_samples < 2 or min_samples > window or confirm < 1:
            raise ValueError("need 2 <= min_samples <= window and confirm >= 1")
        self.window = window
        self.min_samples = min_samples
        self.pos_tol = pos_tol
        self.theta_tol = theta_tol
        self.confirm = confirm
        self._samples: list[tuple[float, float, float, float]] = []  # (t, x, y, theta unwrapped)
        self._pending: list[tuple[float, float, float, float]] = []
        self._fit: StickEstimate | None = None
        self.breaks: list[float] = []  # time of the first sample after each break
        self.before_break: StickEstimate | None = None  # the fit the last break ended
        self._rebuild()

    # -- input ------------------------------------------------------------------------------
    def add(self, t: float, x: float, y: float, theta: float) -> bool:
        """Add a measurement (theta modulo pi). True when it confirms a collision (model break)."""
        # deviating samples (a collision, maybe after an unseen gap) chain to each other: the old
        # fit's prediction may be half a turn off by then, and two of them a branch apart would
        # fake a spin of pi per frame
        near = self._pending[-1][3] if self._pending else self._predict_theta(t)
        sample = (float(t), float(x), float(y), unwrap_to(float(theta), near))
        if not self.ready() or not self._deviates(sample):
            self._pending.clear()  # isolated outliers are dropped
            self._append(sample)
            return False
        self._pending.append(sample)
        if len(self._pending) < self.confirm:
            return False
        self.before_break = self._fit
        self.breaks.append(self._pending[0][0])
        self._samples = list(self._pending)
        self._pending.clear()
        self._rebuild()
        self._refit()
        return True

    def reset(self) -> None:
        """Forget everything (e.g. the stick was lost)."""
        self._samples.clear()
        self._pending.clear()
        self._rebuild()
        self._fit = None

    # -- output -----------------------------------------------------------------------------
    def ready(self) -> bool:
        """At least ``min_samples`` samples since the last restart."""
        return self._fit is not None and self._fit.n >= self.min_samples

    def estimate(self) -> StickEstimate | None:
        """The current fit (None before the first sample)."""
        return self._fit

    def current(self) -> StickEstimate:
        """The current fit, which :meth:`ready` promises."""
        if self._fit is None:
            raise RuntimeError("no samples yet")
        return self._fit

    def predict(self, t: float) -> tuple[float, float, float]:
        """(x, y, theta) at ``t``, theta continuous."""
        if self._fit is None:
            raise RuntimeError("no samples yet")
        return self._fit.at(t)

    # -- internals --------------------------------------------------------------------------
    def _predict_theta(self, t: float) -> float:
        if self._fit is not None and self._fit.n >= 2:
            return self._fit.at(t)[2]
        if self._samples:
            return self._samples[-1][3]
        return 0.0

    def _deviates(self, sample) -> bool:
        t, x, y, th = sample
        px, py, pth = self.current().at(t)
        return math.hypot(x - px, y - py) > self.pos_tol or abs(th - pth) > self.theta_tol

    def _append(self, sample) -> None:
        self._samples.append(sample)
        self._sum(sample, 1.0)
        if len(self._samples) > self.window:
            for old in self._samples[: len(self._samples) - self.window]:
                self._sum(old, -1.0)
            del self._samples[: len(self._samples) - self.window]
            if sample[0] - self._anchor[0] > REANCHOR:
                self._rebuild()
        self._refit()

    # The fit is kept as running sums over the window (O(1) a sample), of the samples relative
    # to an anchor sample (small numbers: little cancellation); rebuilt from the window at each
    # restart and once the anchor is REANCHOR old (rounding never accumulates for long).
    def _rebuild(self) -> None:
        self._anchor = self._samples[0] if self._samples else (0.0, 0.0, 0.0, 0.0)
        self._sums = [0.0] * 12  # (a list: its floats are not re-boxed on every += and read)
        for sample in self._samples:
            self._sum(sample, 1.0)

    def _sum(self, sample, sign: float) -> None:
        """Add ``sign`` times the sample's terms to the running sums."""
        t0, x0, y0, th0 = self._anchor
        ts, xs, ys, ths = sample
        t = ts - t0
        s = self._sums
        s[0] += sign
        s[1] += sign * t
        s[2] += sign * t * t
        # x, y, theta: the value, t * value and value^2 sums (unrolled)
        v = xs - x0
        s[3] += sign * v
        s[4] += sign * t * v
        s[5] += sign * v * v
        v = ys - y0
        s[6] += sign * v
        s[7] += sign * t * v
        s[8] += sign * v * v
        v = ths - th0
        s[9] += sign * v
        s[10] += sign * t * v
        s[11] += sign * v * v

    def _refit(self) -> None:
        """Least squares of (x, y, theta) = value at t_ref + rate (t - t_ref), in closed form
        from the running sums (rate = S_tv / S_tt of the centred sums)."""
        samples = self._samples
        n = len(samples)
        t_ref = samples[-1][0]
        if n == 1:
            _, x, y, th = samples[0]
            self._fit = StickEstimate(t_ref, x, y, th, 0.0, 0.0, 0.0, 1, 0.0, 0.0)
            return
        s = self._sums
        t0 = self._anchor[0]
        tm = s[1] / n
        s_tt = s[2] - s[1] * tm
        dt_ref = (t_ref - t0) - tm
        out = []
        for i, v0 in ((3, self._anchor[1]), (6, self._anchor[2]), (9, self._anchor[3])):
            vm = s[i] / n
            s_tv = s[i + 1] - s[1] * vm
            rate = s_tv / s_tt if s_tt > 0.0 else 0.0
            rss = max(s[i + 2] - s[i] * vm - rate * s_tv, 0.0)
            out.append((v0 + vm + rate * dt_ref, rate, rss))
        (x, vx, rx), (y, vy, ry), (th, w, rth) = out
        self._fit = StickEstimate(
            t_ref, x, y, th, vx, vy, w, n, math.sqrt((rx + ry) / n), math.sqrt(rth / n)
        )
