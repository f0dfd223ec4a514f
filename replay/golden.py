"""Golden-log regression: re-run a scenario and compare its log with a stored one, channel by
channel, as decoded messages with tolerances (never as bytes).

``data/golden/manifest.yaml`` names each golden log, the scenario it comes from, ``--set``
overrides that keep it small, and per-topic tolerances (absolute and relative, on every number).
"""

from __future__ import annotations

import math
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import yaml

from replay.foxglove.schemas import message_dict
from replay.log import LogError, LogMessage, LogReader
from replay.messages import TOPIC_LOG, TOPIC_SCENARIO
from replay.resources import shipped_root
from replay.runner import Runner
from replay.scenario import load_scenario
from replay.scenario.yamlio import ScenarioError, compose, read_text, show

GOLDEN_DIR = Path("data/golden")  # under replay.resources.shipped_root()
MANIFEST = "manifest.yaml"
IGNORED_FIELDS = {
    TOPIC_SCENARIO: {"version"},  # the code version differs by design
    TOPIC_LOG: {"message"},  # /events as text: /events itself is compared with tolerances
}
# camera images (/camera/...): the PNG bytes are left out, a grey level may move between
# builds as the renderers' floats do; their vision topics are compared with tolerances
IMAGE_PREFIX, IMAGE_IGNORED = "/camera/", {"data"}


def _decoded(log: LogReader, topic: str) -> list[LogMessage]:
    """A topic's messages as dicts: JSON as is, Foxglove's protobuf ones decoded."""
    msgs = list(log.messages(topic))
    if not msgs:
        msgs = [LogMessage(r.topic, r.t_ns, message_dict(r.schema, r.data)) for r in log.raw(topic)]
    return msgs


@dataclass
class Golden:
    name: str
    scenario: Path
    log: Path
    sets: list = field(default_factory=list)
    tolerances: dict = field(default_factory=dict)  # topic -> {abs, rel}
    default_tolerance: dict = field(default_factory=lambda: {"abs": 1e-9, "rel": 1e-9})


@dataclass
class Difference:
    topic: str
    index: int
    t: float
    field: str
    golden: object
    run: object
    tolerance: str = ""

    def __str__(self) -> str:
        where = f"{self.topic} message #{self.index} (t = {self.t:.6f} s)"
        if self.field:
            where += f", field {self.field}"
        tol = f" (tolerance {self.tolerance})" if self.tolerance else ""
        return f"{where}: golden {self.golden!r} vs run {self.run!r}{tol}"


class ManifestError(ValueError):
    """The golden manifest is missing or malformed (one line: file:line:col and what)."""


def _tolerance(value, where: str) -> dict:
    if not (
        isinstance(value, dict)
        and set(value) <= {"abs", "rel"}
        and all(
            isinstance(v, (int, float)) and not isinstance(v, bool) and 0 <= v < 1e9
            for v in value.values()
        )
    ):
        raise ManifestError(
            f"{where}: expected {{abs: number >= 0, rel: number >= 0}}, got {show(value)}"
        )
    return {k: float(v) for k, v in value.items()}


def load_manifest(root: Path | None = None) -> dict[str, Golden]:
    root = shipped_root() if root is None else root
    path = root / GOLDEN_DIR / MANIFEST
    if not path.is_file():
        raise FileNotFoundError(path)
    try:
        text = read_text(path)
        compose(text, str(path), what="a manifest")  # encoding, shape and size checks
        data = yaml.safe_load(text) or {}
    except ScenarioError as exc:
        raise ManifestError(str(exc)) from None
    except yaml.YAMLError as exc:
        raise ManifestError(f"{path}: not valid YAML: {exc}") from None
    if not isinstance(data, dict):
        raise ManifestError(
            f"{path}: expected a mapping of golden names, got {type(data).__name__}"
        )
    out = {}
    for name, g in data.items():
        where = f"{path}: {name}"
        if not (
            isinstance(g, dict)
            and isinstance(g.get("scenario"), str)
            and isinstance(g.get("log"), str)
        ):
            raise ManifestError(f"{where}: expected a mapping with scenario: FILE and log: FILE")
        sets = g.get("sets", [])
        if not (isinstance(sets, list) and all(isinstance(x, str) for x in sets)):
            raise ManifestError(f"{where}.sets: expected a list of key.path=value strings")
        tolerances = g.get("tolerances", {})
        if not isinstance(tolerances, dict):
            raise ManifestError(f"{where}.tolerances: expected a mapping topic -> tolerance")
        out[str(name)] = Golden(
            name=str(name),
            scenario=root / g["scenario"],
            log=root / GOLDEN_DIR / g["log"],
            sets=sets,
            tolerances={
                str(t): _tolerance(v, f"{where}.tolerances.{t}") for t, v in tolerances.items()
            },
            default_tolerance=_tolerance(
                g.get("default_tolerance", {"abs": 1e-9, "rel": 1e-9}), f"{where}.default_tolerance"
            ),
        )
    return out


Progress = Callable[[float, float], None]  # the runner's progress(t, duration) hook


def run_golden(g: Golden, out: Path, progress: Progress | None = None) -> Path:
    """Run ``g``'s scenario into ``out``; ``progress(t, duration)`` as the runner's hook."""
    sc = load_scenario(g.scenario, sets=g.sets)
    Runner(sc, progress=progress).run(out)
    return out


def _close(a: float, b: float, tol: dict) -> bool:
    return abs(a - b) <= tol.get("abs", 0.0) + tol.get("rel", 0.0) * max(abs(a), abs(b))


def _first_field_difference(a, b, tol: dict, path: str = ""):
    """(field path, golden value, run value) of the first difference, or None."""
    if isinstance(a, bool) or isinstance(b, bool):
        return None if a == b else (path, a, b)
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
            return None
        return None if _close(float(a), float(b), tol) else (path, a, b)
    if isinstance(a, dict) and isinstance(b, dict):
        for key in sorted(set(a) | set(b)):
            sub = f"{path}.{key}" if path else key
            if key not in a or key not in b:
                return (sub, a.get(key, "<missing>"), b.get(key, "<missing>"))
            found = _first_field_difference(a[key], b[key], tol, sub)
            if found:
                return found
        return None
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return (f"{path} (length)", len(a), len(b))
        for i, (x, y) in enumerate(zip(a, b)):
            found = _first_field_difference(x, y, tol, f"{path}[{i}]")
            if found:
                return found
        return None
    return None if a == b else (path, a, b)


def compare_logs(
    golden_path: Path, run_path: Path, tolerances: dict, default_tolerance: dict | None = None
) -> list[Difference]:
    """The first difference of each topic (empty when the run matches)."""
    default_tolerance = default_tolerance or {"abs": 1e-9, "rel": 1e-9}
    golden, run = LogReader(golden_path).check(), LogReader(run_path).check()
    diffs: list[Difference] = []
    for label, log in (("golden", golden), ("run", run)):
        for note in log.describe_problems():
            diffs.append(Difference("(file)", 0, 0.0, f"the {label} log", note, log.status))
    g_counts, r_counts = golden.topic_counts(), run.topic_counts()
    for topic in sorted(set(g_counts) | set(r_counts)):
        tol = {**default_tolerance, **tolerances.get(topic, {})}
        tol_text = f"abs {tol.get('abs', 0):g}, rel {tol.get('rel', 0):g}"
        g_msgs = _decoded(golden, topic)
        r_msgs = _decoded(run, topic)
        ignored = IGNORED_FIELDS.get(
            topic, IMAGE_IGNORED if topic.startswith(IMAGE_PREFIX) else set()
        )
        for i, (gm, rm) in enumerate(zip(g_msgs, r_msgs)):
            if gm.t_ns != rm.t_ns:
                diffs.append(Difference(topic, i, gm.t, "(log time)", gm.t, rm.t))
                break
            ga = {k: v for k, v in gm.data.items() if k not in ignored}
            ra = {k: v for k, v in rm.data.items() if k not in ignored}
            found = _first_field_difference(ga, ra, tol)
            if found:
                diffs.append(Difference(topic, i, gm.t, found[0], found[1], found[2], tol_text))
                break
        else:
            if len(g_msgs) != len(r_msgs):
                n = min(len(g_msgs), len(r_msgs))
                t = (g_msgs if len(g_msgs) > n else r_msgs)[n].t
                diffs.append(Difference(topic, n, t, "(message count)", len(g_msgs), len(r_msgs)))
    diffs.sort(key=lambda d: d.t)
    return diffs


def check(g: Golden, progress: Progress | None = None) -> list[Difference]:
    """The differences of a fresh run from the stored log. Raises :class:`LogError` when the
    stored log cannot be read at all, ``ScenarioError`` when its scenario is bad."""
    with tempfile.TemporaryDirectory() as tmp:
        out = run_golden(g, Path(tmp) / f"{g.name}.mcap", progress)
        try:
            return compare_logs(g.log, out, g.tolerances, g.default_tolerance)
        except LogError as exc:
            raise LogError(f"stored golden log: {exc}") from None


def update(g: Golden, progress: Progress | None = None) -> Path:
    g.log.parent.mkdir(parents=True, exist_ok=True)
    return run_golden(g, g.log, progress)
