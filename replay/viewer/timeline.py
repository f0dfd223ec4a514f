"""The timeline: a slider over simulated time, play/pause, playback speed (down to 1/100),
one frame back and forth, and the log's events as buttons that jump there.

The slider is the single source of truth: every way of moving in time (dragging, playing,
stepping, an event button) sets the slider's value, and its update callback shows that time.
"""

from __future__ import annotations

import threading
import time
from fractions import Fraction
from typing import Callable

import numpy as np

SPEEDS = ("1/100", "1/50", "1/20", "1/10", "1/5", "1/4", "1/2", "1", "2")
DEFAULT_SPEED = "1/10"
MAX_EVENT_BUTTONS = 40  # per run; the rest are counted, not listed
TICK = 1.0 / 30.0  # playback refresh period (s, wall clock)


def speed_value(label: str) -> float:
    return float(Fraction(label))


def _event_brief(e: dict) -> str:
    data = e.get("data") or {}
    for key in ("finger", "joint", "parts", "reason"):
        if key in data:
            v = data[key]
            v = "+".join(map(str, v)) if isinstance(v, list) else v
            return f" ({key} {v})"
    return ""


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
        marks = [(round(e.get("t", 0.0), 6), "") for _, e in events[:12]]
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
        self.slider.on_update(lambda _: self._show(self.slider.value))
        self.play.on_click(lambda _: self.toggle())
        self.back.on_click(lambda _: self.step(-1))
        self.fwd.on_click(lambda _: self.step(+1))
        self.event_buttons = []
        if events:
            with gui.add_folder("Events", expand_by_default=True):
                per_run: dict[str, int] = {}
                for label, e in events:
                    per_run[label] = per_run.get(label, 0) + 1
                    if per_run[label] > MAX_EVENT_BUTTONS:
                        continue
                    who = f"{label}: " if len({l for l, _ in events}) > 1 else ""
                    b = gui.add_button(
                        f"{who}{e['t']:.4f} s  {e.get('kind', '?')}{_event_brief(e)}",
                        hint="jump to this event",
                    )
                    b.on_click(lambda _, t=float(e["t"]): self.seek(t))
                    self.event_buttons.append((float(e["t"]), b))
                for label, n in per_run.items():
                    if n > MAX_EVENT_BUTTONS:
                        gui.add_markdown(
                            f"*{label}: {n - MAX_EVENT_BUTTONS} more events not "
                            "listed (`replay info LOG` lists all)*"
                        )
        self._thread = threading.Thread(target=self._run, name="replay-viewer-player", daemon=True)
        self._thread.start()

    # -- moving in time ---------------------------------------------------------------------
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
                t = self.t + wall * speed_value(self.speed.value)
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
