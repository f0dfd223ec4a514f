"""The grasp/release schedule and the reaching target x_d^a (Namiki et al. 1999, Sec. 4.2, Figs.
7 and 9), given beforehand: nothing here depends on what is sensed.

Each cycle: ``track`` (the hand follows the object at ``x_far`` from the plane: tracking only,
Fig. 7: 0.0-0.5 s), ``reach`` (x_d^a moves from ``x_far`` to ``x_grasp`` along the plane's
normal with a minimum-jerk profile in ``reach_time``: Fig. 7: 0.5-0.8 s, reaching and grasping),
``hold`` (the grasp, ``hold_time``; <= 0 = to the end of the run), ``release`` (x_d^a back to
``x_far`` in ``release_time`` while the hand opens), then the next cycle's ``track``
(``track_time_next``) ... for ``cycles`` cycles, then tracking to the end. The hand's grasping
trajectory theta_d^h follows ``reach_progress`` ("planned according to reaching motion x_d^a",
Sec. 4.3).
"""

from __future__ import annotations

from dataclasses import dataclass

from replay.control.grasping.payloads import GraspState
from replay.interfaces import Controller, Occurrence
from replay.messages import TOPIC_GRASP_STATE
from replay.params import param
from replay.robot.arm_types import GraspSpec, ServoCommand


@dataclass
class ScheduleParams:
    track_time: float = param(0.5, unit="s", ge=0.0, doc="first tracking phase (Fig. 7: 0.5)")
    reach_time: float = param(0.3, unit="s", gt=0.0, doc="reaching and grasping (Fig. 7: 0.3)")
    hold_time: float = param(0.0, unit="s", doc="grasp held this long; <= 0: to the end")
    release_time: float = param(0.3, unit="s", gt=0.0, doc="release and retreat")
    track_time_next: float = param(0.7, unit="s", ge=0.0, doc="tracking between cycles")
    cycles: int = param(1, ge=1, limit="table_rows", doc="grasp/release cycles")
    x_far: float = param(
        0.15,
        unit="m",
        gt=0.0,
        doc="x_d^a while tracking: the hand's grasp point this far before the "
        "plane (along its normal)",
    )
    x_grasp: float = param(
        0.0, unit="m", doc="x_d^a at the grasp: the grasp point this far before the plane"
    )


def min_jerk(s: float) -> float:
    s = min(max(s, 0.0), 1.0)
    return s * s * s * (10.0 - 15.0 * s + 6.0 * s * s)


class ScheduleTask(Controller):
    """The grasp/release schedule and the reaching target x_d^a, given beforehand."""

    Params = ScheduleParams
    spec_type = GraspSpec
    command_type = ServoCommand
    reads = ()
    description = "grasp/release schedule and the reaching target x_d^a given beforehand"

    def __init__(self, params: ScheduleParams, *, spec: GraspSpec) -> None:
        super().__init__(params, spec=spec)
        P = params
        if spec.plane is None:
            raise ValueError("the schedule needs a plant with a constraint plane")
        self.point = [float(x) for x in spec.plane.point]
        self.normal = [float(x) for x in spec.plane.normal]
        self.segments: list[tuple[float, float, str, int]] = []  # (start, end, phase, cycle)
        t = 0.0
        for c in range(P.cycles):
            track = P.track_time if c == 0 else P.track_time_next
            self.segments.append((t, t + track, "track", c))
            t += track
            self.segments.append((t, t + P.reach_time, "reach", c))
            t += P.reach_time
            if P.hold_time <= 0.0:
                self.segments.append((t, float("inf"), "hold", c))
                break
            self.segments.append((t, t + P.hold_time, "hold", c))
            t += P.hold_time
            self.segments.append((t, t + P.release_time, "release", c))
            t += P.release_time
        else:
            self.segments.append((t, float("inf"), "track", P.cycles))
        self._phase: tuple[str, int] | None = None
        self._events: list[Occurrence] = []
        self._out: GraspState | None = None

    def at(self, t: float) -> GraspState:
        P = self.params
        for start, end, phase, cycle in self.segments:
            if t < end - 1e-12:
                break
        tau = t - start
        s = 0.0
        if phase == "reach":
            s = min_jerk(tau / P.reach_time)
        elif phase == "hold":
            s = 1.0
        elif phase == "release":
            s = 1.0 - min_jerk(tau / P.release_time)
        dist = P.x_far + s * (P.x_grasp - P.x_far)  # before the plane, along -n
        x = [self.point[i] - dist * self.normal[i] for i in range(3)]
        grasp = phase in ("reach", "hold")
        return GraspState(t, phase, cycle, [*x, 0.0, 0.0, 0.0], s, grasp, tau)

    def update(self, t: float, measurements) -> None:
        out = self._out = self.at(t)
        key = (out.phase, out.cycle)
        if key != self._phase:
            self._phase = key
            self._events.append(Occurrence("phase", {"phase": key[0], "cycle": key[1]}))
        return None

    def telemetry(self, t: float) -> dict:
        return {TOPIC_GRASP_STATE: self._out}

    def pop_events(self) -> list[Occurrence]:
        ev, self._events = self._events, []
        return ev

    def outcome(self, t: float) -> dict:
        return {"phases": [[s, p, c] for s, e, p, c in self.segments if s < t]}
