"""The timeline: a slider over simulated time, play/pause, playback speed (down to 1/100),
one frame back and forth, and the log's events as buttons that jump there: the paper's
milestones (``MILESTONES``: capture, catch, grasp, release, outcome, ...) always listed, the
others grouped by kind with their counts and found through a kind dropdown and a text filter
(a flood of ``torque_limit`` events cannot push a milestone out of the list).

The slider is the single source of truth: every way of moving in time (dragging, playing,
stepping, an event button) sets the slider's value, and its update callback shows that time.
"""

from __future__ import annotations

import threading
import time
from fractions import Fraction
from typing import Any, Callable

import numpy as np

from replay.viewer.guard import safe
from replay.viewer.markup import TEXT_CHARS, clean, plain

SPEEDS = ("1/100", "1/50", "1/20", "1/10", "1/5", "1/4", "1/2", "1", "2")
DEFAULT_SPEED = "1/10"
MAX_EVENT_BUTTONS = 40  # listed for the filter's choice; the rest are counted, not listed
MAX_KINDS = 50  # kinds in the summary and the kind dropdown (the filter finds the others)
# the experiment's milestones, by event kind: always listed as buttons, whatever else happened
MILESTONES = ("capture", "catch", "grasp", "release", "drop", "miss", "outcome", "interrupted")
ALL_KINDS = "all kinds"
TICK = 1.0 / 30.0  # playback refresh period (s, wall clock)


def speed_value(label: str) -> float:
    return float(Fraction(label))


def _event_brief(e: dict) -> str:
    data = e.get("data") or {}
    for key in ("finger", "joint", "parts", "reason"):
        if key in data:
            v = data[key]
            v = "+".join(map(str, v[:12])) if isinstance(v, list) else v
            return f" ({key} {v})"
    return ""


def event_label(e: dict, who: str = "") -> str:
    """A button's label: ``[run: ]t s  kind (detail)``."""
    prefix = f"{who}: " if who else ""
    return clean(f"{prefix}{e['t']:.4f} s  {e.get('kind', '?')}{_event_brief(e)}", TEXT_CHARS)


def kind_counts(events: list[tuple[str, dict]]) -> dict[str, int]:
    """Events per kind, kinds in the order they first happen."""
    counts: dict[str, int] = {}
    for _, e in events:
        k = str(e.get("kind", "?"))
        counts[k] = counts.get(k, 0) + 1
    return counts


def milestones(events: list[tuple[str, dict]]) -> list[tuple[str, dict]]:
    """The events whose kind is one of the paper's milestones (``MILESTONES``), in time order."""
    return [(label, e) for label, e in events if e.get("kind") in MILESTONES]


def kind_option(kind: str, n: int) -> str:
    return f"{kind} ({n})"


def select_events(
    events: list[tuple[str, dict]], kind: str | None = None, text: str = "", multi: bool = False
) -> list[tuple[str, dict]]:
    """The events of ``kind`` (None: every kind) whose button label contains ``text`` (any
    case; several words: all of them)."""
    words = text.lower().split()
    out = []
    for label, e in events:
        if kind is not None and str(e.get("kind", "?")) != kind:
            continue
        name = event_label(e, label if multi else "").lower()
        if all(w in name for w in words):
            out.append((label, e))
    return out


class Timeline:
    def __init__(
        self,
        server,
        t_range: tuple[float, float],
        frames: np.ndarray,
        events: list[tuple[str, dict]],
        show: Callable[[float], None],
        speed: str = DEFAULT_SPEED,
    ) -> None:
        import viser

        self._icons = (viser.Icon.PLAYER_PLAY, viser.Icon.PLAYER_PAUSE)
        self.server = server
        self.t0, self.t1 = t_range
        self.frames = (
            np.unique(np.asarray(frames, dtype=float))
            if len(frames)
            else np.array([self.t0, self.t1])
        )
        self._show = show
        self.playing = False
        self._stop = threading.Event()
        gui = server.gui
        dt = float(np.median(np.diff(self.frames))) if len(self.frames) > 1 else 1e-3
        self.dt = dt if dt > 0 else 1e-3
        step = 10.0 ** np.floor(np.log10(self.dt))  # a decade at or below a frame
        self._add_controls(gui, events, step, speed)
        self.events = list(events)
        self.multi = len({label for label, _ in self.events}) > 1
        self.counts = kind_counts(self.events)
        self.milestone_buttons: list = []  # (t, button): always listed
        self.event_buttons: list = []  # (t, button): the filter's choice
        self._listed: list = []  # the filter's handles (buttons, the "more" note)
        self.kind: Any = None  # the kind dropdown, the filter text box, the "N more" note
        self.filter: Any = None
        self.more: Any = None
        if self.events:
            self._add_events_panel(gui)
        self._thread = threading.Thread(target=self._run, name="replay-viewer-player", daemon=True)
        self._thread.start()

    def _add_controls(self, gui, events, step: float, speed: str) -> None:
        """The time slider (its marks at the milestones first), play, frame steps, speed, loop
        and the status line."""
        marked = milestones(events)[:12]  # the slider marks the milestones first
        marked += [le for le in events if le[1].get("kind") not in MILESTONES][: 12 - len(marked)]
        marks = sorted({(round(e.get("t", 0.0), 6), "") for _, e in marked})
        self.slider = gui.add_slider(
            "time (s)",
            min=self.t0,
            max=max(self.t1, self.t0 + step),
            step=float(step),
            initial_value=self.t0,
            marks=tuple(marks) or None,
            hint="simulated time",
        )
        self.play = gui.add_button(
            "Play", icon=self._icons[0], hint="play / pause (simulated time × speed)"
        )
        self.back = gui.add_button("◀ frame", hint="one frame back")
        self.fwd = gui.add_button("frame ▶", hint="one frame forward")
        self.speed = gui.add_dropdown(
            "speed",
            SPEEDS,
            initial_value=speed,
            hint="playback speed: simulated s per wall-clock s",
        )
        self.loop = gui.add_checkbox("loop", False)
        self.status = gui.add_markdown("")
        self.slider.on_update(safe(lambda _: self._slid()))
        self.speed.on_update(safe(lambda _: self._speed_chosen()))
        self.play.on_click(safe(lambda _: self.toggle()))
        self.back.on_click(safe(lambda _: self.step(-1)))
        self.fwd.on_click(safe(lambda _: self.step(+1)))

    def _add_events_panel(self, gui) -> None:
        """The events folder: counts by kind, the milestones' buttons, and the kind and text
        filters over the listed events."""
        import viser

        with gui.add_folder("Events", expand_by_default=True):
            kinds = list(self.counts.items())[:MAX_KINDS]
            more = len(self.counts) - len(kinds)
            gui.add_markdown(
                f"{len(self.events)} events: "
                + " · ".join(f"{plain(k)} × {n}" for k, n in kinds)
                + (f" · {more} more kinds" if more > 0 else "")
            )
            stones = milestones(self.events)
            if stones:
                gui.add_markdown("**milestones**")
            for label, e in stones[:MAX_EVENT_BUTTONS]:
                self.milestone_buttons.append(self._button(label, e, icon=viser.Icon.FLAG))
            self.kind = gui.add_dropdown(
                "kind",
                (ALL_KINDS, *(kind_option(k, n) for k, n in kinds)),
                initial_value=ALL_KINDS,
                hint="list the events of one kind",
            )
            self.filter = gui.add_text(
                "filter", "", hint="list the events whose label holds these words"
            )
            self._list_folder = gui.add_folder("listed", expand_by_default=True)
            self.kind.on_update(safe(lambda _: self.relist()))
            self.filter.on_update(safe(lambda _: self.relist()))
            self.relist()

    def _button(self, label: str, e: dict, icon=None):
        b = self.server.gui.add_button(
            event_label(e, label if self.multi else ""), icon=icon, hint="jump to this event"
        )
        t = float(e["t"])
        b.on_click(safe(lambda _: self.seek(t)))
        return t, b

    def selected_kind(self) -> str | None:
        value = self.kind.value if self.kind is not None else ALL_KINDS
        for k, n in self.counts.items():
            if value == kind_option(k, n):
                return k
        return None

    def relist(self) -> None:
        """List (at most ``MAX_EVENT_BUTTONS`` of) the events the kind and the filter choose."""
        if self.kind is None or self.filter is None:
            return
        for h in self._listed:
            h.remove()
        chosen = select_events(self.events, self.selected_kind(), self.filter.value, self.multi)
        self._listed, self.event_buttons = [], []
        with self._list_folder:
            for label, e in chosen[:MAX_EVENT_BUTTONS]:
                t, b = self._button(label, e)
                self.event_buttons.append((t, b))
                self._listed.append(b)
            rest = len(chosen) - MAX_EVENT_BUTTONS
            self.more = None
            if rest > 0:
                self.more = self.server.gui.add_markdown(
                    f"*{rest} more not listed: choose a kind or filter "
                    "(`replay info LOG` lists all)*"
                )
                self._listed.append(self.more)
            elif not chosen:
                self._listed.append(self.server.gui.add_markdown("*no event matches*"))

    # -- moving in time ---------------------------------------------------------------------
    def _slid(self) -> None:
        """The slider moved: show its time. A value no slider of ours sends (not a number, off
        the run) is put back in the run, which calls this again."""
        t = float(self.slider.value)
        if not self.t0 <= t <= max(self.t1, self.slider.max):
            self.slider.value = min(max(t, self.t0), self.t1) if np.isfinite(t) else self.t0
            return
        self._show(t)

    def _speed_chosen(self) -> None:
        if self.speed.value not in SPEEDS:  # not one of the dropdown's: back to the default
            self.speed.value = DEFAULT_SPEED

    @property
    def t(self) -> float:
        return float(self.slider.value)

    def seek(self, t: float) -> None:
        """Jump to simulated time ``t`` (paused)."""
        self.pause()
        self.slider.value = float(min(max(t, self.t0), self.t1))

    def step(self, direction: int) -> None:
        self.pause()
        i = int(np.searchsorted(self.frames, self.t + 1e-9, side="right")) - 1
        j = min(max(i + direction, 0), len(self.frames) - 1)
        if direction < 0 and i >= 0 and self.frames[i] < self.t - 1e-9:
            j = i  # between frames: back goes to the frame at or before t
        self.slider.value = float(self.frames[j])

    def toggle(self) -> None:
        if self.playing:
            self.pause()
        else:
            if self.t >= self.t1 - 1e-12:
                self.slider.value = self.t0
            self.playing = True
            self.play.label = "Pause"
            self.play.icon = self._icons[1]

    def pause(self) -> None:
        if self.playing:
            self.playing = False
            self.play.label = "Play"
            self.play.icon = self._icons[0]
            self._show(self.t)  # the plots' cursor catches up

    def _run(self) -> None:
        last = time.perf_counter()
        while not self._stop.wait(TICK):
            now = time.perf_counter()
            wall, last = now - last, now
            if not self.playing:
                continue
            try:
                speed = self.speed.value if self.speed.value in SPEEDS else DEFAULT_SPEED
                t = self.t + wall * speed_value(speed)
                end = t >= self.t1 and not self.loop.value
                if t >= self.t1:
                    t = self.t1 if end else self.t0
                self.slider.value = t
                if end:
                    self.pause()
            except Exception:  # noqa: BLE001 - the server was stopped under us
                return

    def close(self) -> None:
        self._stop.set()
        self.playing = False
