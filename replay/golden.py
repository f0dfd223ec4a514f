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

import yaml

from replay.log import LogReader
from replay.messages import TOPIC_SCENARIO
from replay.resources import shipped_root
from replay.runner import Runner
from replay.scenario import load_scenario

GOLDEN_DIR = Path("data/golden")   # under replay.resources.shipped_root()
MANIFEST = "manifest.yaml"
IGNORED_FIELDS = {TOPIC_SCENARIO: {"version"}}   # the code version differs by design


@dataclass
class Golden:
    name: str
    scenario: Path
    log: Path
    sets: list = field(default_factory=list)
    tolerances: dict = field(default_factory=dict)   # topic -> {abs, rel}
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


def load_manifest(root: Path | None = None) -> dict[str, Golden]:
    root = shipped_root() if root is None else root
    path = root / GOLDEN_DIR / MANIFEST
    data = yaml.safe_load(path.read_text()) or {}
    out = {}
    for name, g in data.items():
        out[name] = Golden(name=name, scenario=root / g["scenario"],
                           log=root / GOLDEN_DIR / g["log"], sets=list(g.get("sets", [])),
                           tolerances=g.get("tolerances", {}),
                           default_tolerance=g.get("default_tolerance",
                                                   {"abs": 1e-9, "rel": 1e-9}))
    return out


def run_golden(g: Golden, out: Path) -> Path:
    sc = load_scenario(g.scenario, sets=g.sets)
    Runner(sc).run(out)
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


def compare_logs(golden_path: Path, run_path: Path, tolerances: dict,
                 default_tolerance: dict | None = None) -> list[Difference]:
    """The first difference of each topic (empty when the run matches)."""
    default_tolerance = default_tolerance or {"abs": 1e-9, "rel": 1e-9}
    golden, run = LogReader(golden_path), LogReader(run_path)
    g_counts, r_counts = golden.topic_counts(), run.topic_counts()
    diffs: list[Difference] = []
    for topic in sorted(set(g_counts) | set(r_counts)):
        tol = {**default_tolerance, **tolerances.get(topic, {})}
        tol_text = f"abs {tol.get('abs', 0):g}, rel {tol.get('rel', 0):g}"
        g_msgs = list(golden.messages(topic))
        r_msgs = list(run.messages(topic))
        ignored = IGNORED_FIELDS.get(topic, set())
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
                diffs.append(Difference(topic, n, t, "(message count)", len(g_msgs),
                                        len(r_msgs)))
    diffs.sort(key=lambda d: d.t)
    return diffs


def check(g: Golden) -> list[Difference]:
    with tempfile.TemporaryDirectory() as tmp:
        out = run_golden(g, Path(tmp) / f"{g.name}.mcap")
        return compare_logs(g.log, out, g.tolerances, g.default_tolerance)


def update(g: Golden) -> Path:
    g.log.parent.mkdir(parents=True, exist_ok=True)
    return run_golden(g, g.log)
