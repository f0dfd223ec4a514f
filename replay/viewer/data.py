"""Log -> compact NumPy arrays: one :class:`Track` per topic, found by time with ``searchsorted``.

A log is read once, message by message (the MCAP reader decompresses one chunk at a time), and
each message's numbers go straight into float64 columns: the decoded JSON is dropped at once,
so the file is never held in memory twice. Non-numeric fields (joint names) are kept once, from
a topic's first message. The same accumulator grows during a live run (``replay run --view``),
where the runner hands it each message as it is written.

A log is someone else's data: what one run keeps (columns at 8 bytes a number, events, topics)
is at most ``viewer_bytes`` (:mod:`replay.limits`), counted as it is allocated; the count in
the log's statistics only sizes the first allocation, up to :data:`HINT_BYTES`; a label or an
event field too big to be a name or a detail is left out, and a note says so.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from replay import registry
from replay.limits import LimitError, check, limit
from replay.log import LogError, LogReader
from replay.messages import TOPIC_EVENTS, TOPIC_SCENARIO, to_dict
from replay.viewer.errors import ViewerError
from replay.viewer.markup import LABEL_CHARS, clean

# topics kept as Python objects rather than columns (few messages, free-form data)
OBJECT_TOPICS = (TOPIC_SCENARIO, TOPIC_EVENTS)
HINT_BYTES = 16 * 2**20  # a topic's first columns, sized by the log's count: at most this
TOPIC_BYTES = 4096  # what a topic costs besides its columns (its Python objects), counted
FIELD_BYTES = 256  # and each of its fields (a column's or a label's Python objects)
LABEL_BYTES = 65_536  # a non-numeric field kept (joint names): at most this big
EVENT_FIELD_BYTES = 16_384  # one field of an event's data kept: at most this big
EVENT_BYTES = 65_536  # an event's data kept: at most this big (fields past it left out)


def _size(value, cap: int) -> int:
    """About the bytes decoded JSON ``value`` takes as Python objects, counted until past
    ``cap`` (a huge value costs no more time than a small one)."""
    total, stack = 0, [value]
    while stack and total <= cap:
        v = stack.pop()
        if isinstance(v, str):
            total += 50 + len(v)
        elif isinstance(v, list):
            total += 56 + 8 * len(v)
            if total <= cap:
                stack.extend(v)
        elif isinstance(v, dict):
            total += 64 + 100 * len(v)
            if total <= cap:
                stack.extend(v.keys())
                stack.extend(v.values())
        else:
            total += 32
    return total


class _Budget:
    """What one run keeps, counted against ``viewer_bytes`` (read once)."""

    def __init__(self) -> None:
        self.cap = limit("viewer_bytes")
        self.used = 0

    def left(self) -> int:
        return self.cap - self.used

    def take(self, n: int, topic: str) -> None:
        """Count ``n`` more bytes, kept for ``topic``; :class:`LimitError` past the limit."""
        check("viewer_bytes", self.used + n, f"what the viewer keeps of one run (at {topic})")
        self.used += n


@dataclass
class Track:
    """One topic's messages as columns: ``t`` (s, ascending) and ``fields[name]`` (n, ...)."""

    topic: str
    t: np.ndarray
    fields: dict[str, np.ndarray]
    labels: dict[str, Any] = field(default_factory=dict)  # non-numeric fields, first message
    ragged: tuple[str, ...] = ()  # fields whose shape changed (NaN rows)

    def __len__(self) -> int:
        return len(self.t)

    def index(self, t: float) -> int:
        """The last message at or before ``t`` (-1 before the first one)."""
        return int(np.searchsorted(self.t, t + 1e-12, side="right")) - 1

    def at(self, name: str, t: float):
        """Field ``name`` of the last message at or before ``t``, or None."""
        i = self.index(t)
        col = self.fields.get(name)
        if i < 0 or col is None:
            return None
        return col[i]

    def has(self, name: str) -> bool:
        return name in self.fields and len(self.t) > 0


def _shape_of(value) -> tuple | None:
    """Column shape of a JSON value: () number, (n,) list of numbers, (n, m) list of lists;
    None for anything else (strings, objects, empty or mixed lists)."""
    if isinstance(value, (bool, int, float)):
        return ()
    if isinstance(value, list) and value:
        if all(isinstance(v, (bool, int, float)) for v in value):
            return (len(value),)
        if all(isinstance(v, list) and v for v in value):
            n = len(value[0])
            if all(
                len(v) == n and all(isinstance(x, (bool, int, float)) for x in v) for v in value
            ):
                return (len(value), n)
    return None


class _TrackBuilder:
    def __init__(self, topic: str, count: int, budget: _Budget) -> None:
        self.topic = topic
        self.count = count  # the log's word for it: a hint, not a promise
        self.budget = budget
        budget.take(TOPIC_BYTES, topic)
        self.cap = self.n = 0
        self.row = 8  # bytes of one message's numbers, its time included
        self.t = np.empty(0)
        self.cols: dict[str, np.ndarray] | None = None
        self.labels: dict[str, Any] = {}
        self.ragged: set[str] = set()
        self.left_out: list[str] = []  # labels too big to keep

    def _layout(self, data: dict) -> None:
        self.budget.take(FIELD_BYTES * len(data), self.topic)
        self.cols = {}
        for name, value in data.items():
            if name == "t":
                continue
            shape = _shape_of(value)
            if shape is None:
                size = _size(value, LABEL_BYTES)
                if size <= LABEL_BYTES:
                    self.budget.take(size, self.topic)
                    self.labels[name] = value
                else:
                    self.left_out.append(name)
            else:
                self.cols[name] = np.empty((0, *shape))
                self.row += 8 * int(np.prod(shape))
        self._resize(min(max(8, self.count), max(8, HINT_BYTES // self.row)))

    def _resize(self, want: int) -> None:
        """Room for ``want`` rows, or as many as the run's budget leaves (one more row than
        held at least: else :class:`LimitError`). Rows past ``n`` are never read."""
        cap = max(self.n + 1, min(want, self.cap + self.budget.left() // self.row))
        self.budget.take((cap - self.cap) * self.row, self.topic)
        t = np.empty(cap)
        t[: self.n] = self.t[: self.n]
        self.t = t
        cols = self.cols or {}
        for name, col in cols.items():
            new = np.empty((cap, *col.shape[1:]))
            new[: self.n] = col[: self.n]
            cols[name] = new
        self.cap = cap

    def add(self, t_ns: int, data: dict) -> None:
        if self.cols is None:
            self._layout(data)
        if self.n == self.cap:
            self._resize(2 * self.cap)
        n = self.n
        self.t[n] = t_ns * 1e-9
        for name, col in (self.cols or {}).items():
            value = data.get(name)
            shape = col.shape[1:]
            try:
                if shape and (
                    not isinstance(value, list)
                    or len(value) != shape[0]
                    or (len(shape) > 1 and np.shape(value) != shape)
                ):
                    raise ValueError(name)  # no broadcasting of a shorter list
                col[n] = value
            except (TypeError, ValueError):  # missing, or its shape changed
                col[n] = np.nan
                self.ragged.add(name)
        self.n = n + 1

    def track(self) -> Track:
        n = self.n
        return Track(
            self.topic,
            self.t[:n],
            {k: v[:n] for k, v in (self.cols or {}).items()},
            dict(self.labels),
            tuple(sorted(self.ragged)),
        )


@dataclass
class RunData:
    """One run as the viewer sees it: its scenario, its tracks, its events."""

    label: str  # scenario name, or the file name
    path: Path | None
    scenario: dict  # the /scenario message ({} if absent)
    config: dict  # the resolved scenario YAML, parsed ({} if absent)
    tracks: dict[str, Track]
    events: list[dict]
    truncated: bool = False
    notes: list[str] = field(default_factory=list)  # what the viewer could not show, and why

    def track(self, topic: str) -> Track | None:
        tr = self.tracks.get(topic)
        return tr if tr is not None and len(tr) else None

    @property
    def plant_type(self) -> str:
        """The plant's type as it is called now (a renamed one's old name mapped)."""
        return registry.current_name(
            "plant", str(_mapping(self.config.get("plant")).get("type", ""))
        )

    @property
    def plant_params(self) -> dict:
        return dict(_mapping(_mapping(self.config.get("plant")).get("params")))

    @property
    def sensors(self) -> dict:
        """The scenario's sensors that are mappings (a log may hold anything)."""
        return {
            k: v for k, v in _mapping(self.config.get("sensors")).items() if isinstance(v, dict)
        }

    def time_range(self) -> tuple[float, float]:
        ts = [tr.t for tr in self.tracks.values() if len(tr)]
        ts += [np.array([e["t"] for e in self.events], dtype=float)] if self.events else []
        if not ts:
            return 0.0, 0.0
        return float(min(a[0] for a in ts if len(a))), float(max(a[-1] for a in ts if len(a)))


def _mapping(value) -> dict:
    return value if isinstance(value, dict) else {}


def _config(text) -> tuple[dict, list[str]]:
    """A log's stored scenario YAML, parsed (``{}`` if absent), and what was wrong with it: the
    viewer draws a run whose YAML is too big, too deep, not YAML or not the right shape with
    default geometry, and says so."""
    if not text:
        return {}, []
    why = ""
    config = None
    if not isinstance(text, str):
        why = "not text"
    else:
        try:
            check("scenario_bytes", len(text.encode("utf-8", "replace")), "the scenario YAML")
            config = yaml.safe_load(text)
        except LimitError as exc:
            why = str(exc)
        except yaml.YAMLError as exc:
            why = exc.__class__.__name__
        except RecursionError:
            why = "nested too deep"
    if why:
        return {}, [f"scenario YAML unreadable ({why}); default geometry used"]
    if not isinstance(config, dict):
        return {}, ["scenario YAML is not a mapping; default geometry used"]
    plant = config.get("plant")
    if plant is not None and not isinstance(plant, dict):
        return config, ["scenario plant is not a mapping; default geometry used"]
    params = _mapping(plant).get("params")
    if params is not None and not isinstance(params, dict):
        return config, ["scenario plant.params is not a mapping; default geometry used"]
    return config, []


def _event(t_ns: int, data: dict) -> tuple[dict, int]:
    """An event as the timeline takes it: ``t`` a finite number (the message's time if not),
    ``kind`` a short line of text, ``data`` a mapping of the fields that fit
    :data:`EVENT_FIELD_BYTES` each and :data:`EVENT_BYTES` in all; and how many were left out."""
    t = data.get("t")
    if isinstance(t, bool) or not isinstance(t, (int, float)) or not np.isfinite(t):
        t = t_ns * 1e-9
    kind = clean(data["kind"]) if "kind" in data else "?"
    kept, size, left_out = {}, 0, 0
    for key, value in _mapping(data.get("data")).items():
        n = _size(key, EVENT_FIELD_BYTES) + _size(value, EVENT_FIELD_BYTES)
        if n > EVENT_FIELD_BYTES or size + n > EVENT_BYTES:
            left_out += 1
        else:
            kept[key], size = value, size + n
    return {"t": float(t), "kind": kind, "data": kept}, left_out


class RunAccumulator:
    """Messages in, :class:`RunData` out; safe to snapshot from another thread while it grows."""

    def __init__(self, path: Path | None = None, counts: dict[str, int] | None = None) -> None:
        self.path = path
        self.counts = counts or {}
        self.scenario: dict = {}
        self.events: list[dict] = []
        self.event_fields_left_out = 0
        self.builders: dict[str, _TrackBuilder] = {}
        self.t_last = 0.0
        self.full = ""  # why messages are no longer kept: over the limit (kept before it)
        self.budget = _Budget()
        self._lock = threading.Lock()

    def add(self, topic: str, t_ns: int, data: dict) -> None:
        """Keep a message; past the run's ``viewer_bytes``, none more (``full`` says why)."""
        with self._lock:
            if self.full:
                return
            try:
                self._add(topic, t_ns, data)
            except LimitError as exc:
                self.full = str(exc)

    def _add(self, topic: str, t_ns: int, data: dict) -> None:
        self.t_last = max(self.t_last, t_ns * 1e-9)
        if topic == TOPIC_SCENARIO:
            self.scenario = data
        elif topic == TOPIC_EVENTS:
            event, left_out = _event(t_ns, data)
            self.budget.take(_size(event, EVENT_BYTES * 2), topic)
            self.events.append(event)
            self.event_fields_left_out += left_out
        else:
            b = self.builders.get(topic)
            if b is None:
                b = self.builders[topic] = _TrackBuilder(
                    topic, self.counts.get(topic, 256), self.budget
                )
            b.add(t_ns, data)

    def observe(self, topic: str, payload, t_ns: int) -> None:
        """A runner observer: ``Runner(..., observers=(acc.observe,))``."""
        self.add(topic, t_ns, to_dict(payload))

    def snapshot(self, truncated: bool = False) -> RunData:
        with self._lock:
            tracks = {topic: b.track() for topic, b in self.builders.items()}
            events = list(self.events)
            scenario = dict(self.scenario)
        config, notes = _config(scenario.get("yaml"))
        name = scenario.get("name")
        label = clean(
            name if name and isinstance(name, str) else self.path.stem if self.path else "live run"
        )
        if self.full:
            notes.insert(0, f"messages past t = {self.t_last:.4f} s not kept: {self.full}")
        for b in self.builders.values():
            for name in b.left_out:
                notes.append(f"{b.topic}.{name}: over {LABEL_BYTES:,} bytes, left out")
        for tr in tracks.values():
            for name in tr.ragged:
                notes.append(
                    f"{tr.topic}.{name} changes shape or is missing in some messages; "
                    "those messages are left out"
                )
        if self.event_fields_left_out:
            notes.append(
                f"{self.event_fields_left_out} event field(s) over {EVENT_FIELD_BYTES:,} bytes "
                f"(or past {EVENT_BYTES:,} in one event) left out"
            )
        return RunData(
            label=str(label),
            path=self.path,
            scenario=scenario,
            config=config,
            tracks=tracks,
            events=events,
            truncated=truncated,
            notes=notes,
        )


def distinct_labels(runs: list[RunData]) -> list[RunData]:
    """``runs`` with a label several share (one scenario name: the default and a variant)
    followed by each one's file name, so the overlay's title, legend and notes tell them apart."""
    shared = [r.label for r in runs]
    for run in runs:
        if shared.count(run.label) > 1 and run.path is not None:
            run.label = clean(f"{clean(run.label, LABEL_CHARS // 2)} ({Path(run.path).name})")
    return runs


def load_run(path: str | Path) -> RunData:
    """Read a run's log into arrays. Raises :class:`ViewerError` (one line) if it cannot."""
    path = Path(path)
    try:
        reader = LogReader(path)
        counts = {} if reader.truncated else reader.topic_counts()
        acc = RunAccumulator(path, counts)
        for m in reader.messages():
            acc.add(m.topic, m.t_ns, m.data)
            if acc.full:
                raise ViewerError(f"{path}: {acc.full}")
    except ViewerError:
        raise
    except LogError as exc:
        raise ViewerError(str(exc)) from None
    except LimitError as exc:  # a REPLAY_LIMIT_* variable that is not a number
        raise ViewerError(str(exc)) from None
    except (ValueError, OSError) as exc:  # a corrupt message (bad JSON) or a read error
        raise ViewerError(f"{path}: unreadable log ({exc})") from None
    run = acc.snapshot(truncated=reader.truncated)
    if not run.tracks and not run.events:
        why = " (truncated before its first chunk)" if reader.truncated else ""
        raise ViewerError(f"{path}: the log holds no messages{why}")
    if reader.truncated:
        _, t1 = run.time_range()
        run.notes.insert(0, f"truncated log: read up to t = {t1:.4f} s")
    if not run.scenario:
        run.notes.append("no /scenario message: default geometry used")
    return run


def resample(t: np.ndarray, y: np.ndarray, grid: np.ndarray) -> np.ndarray:
    """``y(t)`` on ``grid`` by linear interpolation (held constant outside ``t``)."""
    y = np.asarray(y, dtype=float)
    good = np.isfinite(y)
    if not good.any():
        return np.zeros_like(grid)
    return np.interp(grid, t[good], y[good])
