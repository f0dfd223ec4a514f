"""What a sweep varies: ``--grid key.path=a,b,c`` and ``--random key.path=lo:hi`` (with ``--n``).

A grid axis is a scenario field (any ``--set`` key path) with a list of values; its values are read
as YAML (``1e-3``, ``[1, 2]``, ``true``). An axis may also *link* several fields, one mapping per
value (sweep files only, e.g. a throw speed that sets the release point and velocity together), and
the axis ``scenario`` varies the scenario file itself (e.g. the direct mapping against the
predictive baseline) and the axis ``seed`` the run's seed. Random axes draw ``n`` values uniformly from ``[lo, hi]`` with a generator
seeded by the sweep's seed, so the same command gives the same variants. Variants are the cartesian
product of the grid axes, times the ``n`` random draws: their count, known before any is made, is
bounded by the ``sweep_variants`` limit (:mod:`replay.limits`), and they are made one at a time.

Bad specifications raise :class:`SweepSpecError` (one line; the CLI exits 2).
"""

from __future__ import annotations

import itertools
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterator

import numpy as np
import yaml

from replay.limits import LimitError, check
from replay.scenario.yamlio import show

SCENARIO_AXIS = "scenario"
INT64 = (-(2**63), 2**63 - 1)  # whole-number bounds NumPy's generator draws between


class SweepSpecError(Exception):
    """A malformed ``--grid``/``--random`` or sweep file: one line naming the culprit."""


@dataclass
class Axis:
    name: str  # a key path, SCENARIO_AXIS, or a label for a linked axis
    values: list  # plain values, or dicts {key.path: value} for a linked axis
    labels: list = field(default_factory=list)  # what the table shows per value

    def __post_init__(self) -> None:
        if not self.labels:
            self.labels = [_label(v) for v in self.values]


@dataclass
class RandomAxis:
    name: str
    lo: float
    hi: float
    integer: bool = False


@dataclass
class SweepSpec:
    grid: list[Axis] = field(default_factory=list)
    random: list[RandomAxis] = field(default_factory=list)
    n: int = 1

    @property
    def count(self) -> int:
        """How many variants :meth:`iter_points` makes (the product of the axes' lengths)."""
        return math.prod(len(a.values) for a in self.grid) * (self.n if self.random else 1)

    def check_count(self) -> None:
        """SweepSpecError if the variants are over the ``sweep_variants`` limit."""
        try:
            check("sweep_variants", self.count, "this sweep")
        except LimitError as exc:
            raise SweepSpecError(str(exc)) from None

    def points(self, seed: int) -> list[dict[str, Any]]:
        """Every variant's parameters: {axis name: value} in a fixed order."""
        self.check_count()
        return list(self.iter_points(seed))

    def iter_points(self, seed: int) -> Iterator[dict[str, Any]]:
        """:meth:`points` one at a time (the draws made again for each grid point: the same)."""
        grid = [[(a, i) for i in range(len(a.values))] for a in self.grid]
        for combo in itertools.product(*grid) if grid else [()]:
            for d in self._draws(seed):
                point = {a.name: a.values[i] for a, i in combo}
                point.update(d)
                yield point

    def _draws(self, seed: int) -> Iterator[dict[str, Any]]:
        if not self.random:
            yield {}
            return
        rng = np.random.default_rng(np.random.SeedSequence([seed, 0x5EE9]))
        for _ in range(self.n):
            d: dict[str, Any] = {}
            for r in self.random:
                if r.integer:
                    d[r.name] = int(rng.integers(int(r.lo), int(r.hi), endpoint=True))
                else:
                    d[r.name] = float(rng.uniform(r.lo, r.hi))
            yield d

    def label(self, name: str, value: Any) -> str:
        """The table's cell for an axis value (a linked axis shows its label)."""
        for a in self.grid:
            if a.name == name:
                for v, lab in zip(a.values, a.labels):
                    if v == value:
                        return lab
        return _label(value)

    @property
    def columns(self) -> list[str]:
        return [a.name for a in self.grid] + [r.name for r in self.random]


def _label(v: Any) -> str:
    if isinstance(v, str):
        return v
    return json.dumps(v, separators=(",", ":"))


def _key_path(text: str, option: str) -> str:
    key = text.strip()
    parts = key.split(".")
    if not key or not all(p and p.strip() == p and " " not in p for p in parts):
        raise SweepSpecError(
            f"{option}: bad key path {text!r} (expected e.g. plant.params.stick.friction)"
        )
    return key


def _yaml_value(text: str, option: str, key: str) -> Any:
    try:
        value = yaml.safe_load(text) if text.strip() else None
    except (yaml.YAMLError, ValueError):  # (ValueError: an integer of over 4300 digits)
        raise SweepSpecError(f"{option} {key}: value {_short(text)} is not valid YAML") from None
    if isinstance(value, (int, float)) and not isinstance(value, bool) and ":" in text:
        return text.strip()  # YAML 1.1's base 60 ("1:30" is 90): a string, as --set reads it
    return value


def _split_values(text: str) -> list[str]:
    """Split ``a,b,[1,2],c`` at commas outside brackets."""
    parts, depth, cur = [], 0, ""
    for ch in text:
        if ch in "[{":
            depth += 1
        elif ch in "]}":
            depth -= 1
        if ch == "," and depth == 0:
            parts.append(cur)
            cur = ""
        else:
            cur += ch
    parts.append(cur)
    return parts


def parse_grid(text: str) -> Axis:
    """``key.path=a,b,c`` -> an Axis."""
    if "=" not in text:
        raise SweepSpecError(f"--grid expects key.path=a,b,c, got {text!r}")
    key, values = text.split("=", 1)
    key = _key_path(key, "--grid")
    raw = _split_values(values)
    if not values.strip() or any(not r.strip() for r in raw):
        raise SweepSpecError(f"--grid {key}: expected comma-separated values, got {values!r}")
    vals = [_yaml_value(r, "--grid", key) for r in raw]
    if len({_label(v) for v in vals}) != len(vals):
        raise SweepSpecError(f"--grid {key}: a value is given twice in {values!r}")
    return Axis(key, vals)


def _number(text: str, option: str, key: str) -> float:
    v = _yaml_value(text, option, key)
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise SweepSpecError(f"{option} {key}: expected a number, got {_short(text)}")
    if isinstance(v, int) and not INT64[0] <= v <= INT64[1]:
        raise SweepSpecError(
            f"{option} {key}: {_short(text)} is out of range (whole numbers from -2**63 to "
            "2**63-1; write it with a decimal point for a real number)"
        )
    if not math.isfinite(v):
        raise SweepSpecError(f"{option} {key}: expected a finite number, got {_short(text)}")
    return v


def _short(text: str) -> str:
    text = text.strip()
    return repr(text if len(text) <= 40 else f"{text[:20]}...({len(text)} characters)")


def parse_random(text: str) -> RandomAxis:
    """``key.path=lo:hi`` -> a RandomAxis (whole numbers if both bounds are)."""
    if "=" not in text or text.split("=", 1)[1].count(":") != 1:
        raise SweepSpecError(f"--random expects key.path=lo:hi, got {text!r}")
    key, bounds = text.split("=", 1)
    key = _key_path(key, "--random")
    lo_t, hi_t = bounds.split(":", 1)
    lo, hi = _number(lo_t, "--random", key), _number(hi_t, "--random", key)
    if not lo < hi:
        raise SweepSpecError(f"--random {key}: expected lo < hi, got {lo:g}:{hi:g}")
    if not math.isfinite(float(hi) - float(lo)):
        raise SweepSpecError(f"--random {key}: the range {lo:g}:{hi:g} is too wide to draw from")
    integer = isinstance(lo, int) and isinstance(hi, int)
    return RandomAxis(key, lo if integer else float(lo), hi if integer else float(hi), integer)


def from_options(grids: tuple | list, randoms: tuple | list, n: int | None) -> SweepSpec:
    spec = SweepSpec(grid=[parse_grid(g) for g in grids], random=[parse_random(r) for r in randoms])
    if n is not None and n < 1:
        raise SweepSpecError(f"--n: expected at least 1 draw, got {n}")
    if spec.random:
        spec.n = n if n is not None else 10
    elif n is not None:
        raise SweepSpecError("--n needs at least one --random axis")
    _check_unique(spec)
    spec.check_count()
    return spec


def _check_unique(spec: SweepSpec) -> None:
    seen: set[str] = set()
    for name in spec.columns + [
        k for a in spec.grid if a.values and isinstance(a.values[0], dict) for k in a.values[0]
    ]:
        if name in seen:
            raise SweepSpecError(f"{name}: varied twice (one --grid/--random per key)")
        seen.add(name)


# -- sweep files (sweeps/NAME.yaml) ---------------------------------------------------------------


@dataclass
class SweepFile:
    """A named, reproducible sweep: scenario, axes, seed, and how to plot its table."""

    name: str
    path: Path
    scenario: Path
    spec: SweepSpec
    seed: int
    sets: list[str]
    description: str
    plot: str  # "module:function" drawing the table
    caption: str  # what the plot shows, one sentence (the report's text)
    paper: str
    metrics: str = ""  # "module:function" LogReader -> extra columns, or ""
    summary: str = ""  # "module:function" rows -> one sentence of what the plot shows


def load_sweep_file(path: str | Path) -> SweepFile:
    path = Path(path)
    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise SweepSpecError(f"{path}: cannot read sweep file: {exc.strerror}") from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"{path}:{mark.line + 1}:{mark.column + 1}" if mark else str(path)
        raise SweepSpecError(f"{where}: not valid YAML") from None
    if not isinstance(data, dict):
        raise SweepSpecError(f"{path}: a sweep file is a mapping")
    known = {
        "name",
        "description",
        "paper",
        "scenario",
        "seed",
        "set",
        "grid",
        "random",
        "n",
        "plot",
        "caption",
        "metrics",
        "summary",
    }
    unknown = sorted(set(data) - known)
    if unknown:
        raise SweepSpecError(
            f"{path}: unknown field {unknown[0]!r} (expected one of: {', '.join(sorted(known))})"
        )
    for req in ("scenario", "plot"):
        if req not in data:
            raise SweepSpecError(f"{path}: missing field {req!r}")
    grid = []
    for name, values in (data.get("grid") or {}).items():
        grid.append(_file_axis(path, str(name), values))
    randoms = []
    for name, bounds in (data.get("random") or {}).items():
        if not (isinstance(bounds, list) and len(bounds) == 2):
            raise SweepSpecError(f"{path}: random.{name}: expected [lo, hi]")
        randoms.append(parse_random(f"{name}={bounds[0]}:{bounds[1]}"))
    n = data.get("n", 10 if randoms else 1)
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise SweepSpecError(f"{path}: n: expected a whole number of draws >= 1, got {n!r:.40}")
    spec = SweepSpec(grid=grid, random=randoms, n=n)
    _check_unique(spec)
    spec.check_count()
    sets = data.get("set") or {}
    if not isinstance(sets, dict):
        raise SweepSpecError(f"{path}: set: expected a mapping key.path -> value")
    return SweepFile(
        name=str(data.get("name", path.stem)),
        path=path,
        scenario=(path.parent / str(data["scenario"])),
        spec=spec,
        seed=check_seed(data.get("seed", 0), f"{path}: seed"),
        sets=[f"{k}={_yaml_text(v)}" for k, v in sets.items()],
        description=str(data.get("description", "")),
        plot=str(data["plot"]),
        caption=str(data.get("caption", "")).strip(),
        paper=str(data.get("paper", "")),
        metrics=str(data.get("metrics", "")),
        summary=str(data.get("summary", "")),
    )


def _file_axis(path: Path, name: str, values: Any) -> Axis:
    if isinstance(values, dict):  # linked axis: {label: {key.path: value, ...}, ...}
        labels, vals = [], []
        for label, sets in values.items():
            if not isinstance(sets, dict) or not sets:
                raise SweepSpecError(
                    f"{path}: grid.{name}.{label}: expected a mapping key.path -> value"
                )
            for k in sets:
                _key_path(str(k), f"{path}: grid.{name}.{label}")
            labels.append(_label(label))
            vals.append({str(k): v for k, v in sets.items()})
        return Axis(name, vals, labels)
    if not isinstance(values, list) or not values:
        raise SweepSpecError(f"{path}: grid.{name}: expected a non-empty list of values")
    if name == SCENARIO_AXIS:
        return Axis(
            name,
            [str((path.parent / str(v)).as_posix()) for v in values],
            [Path(str(v)).stem for v in values],
        )
    _key_path(name, f"{path}: grid")
    return Axis(name, values)


def _yaml_text(v: Any) -> str:
    return (
        yaml.safe_dump(v, default_flow_style=True, width=10_000).strip().removesuffix("...").strip()
    )


SEED_AXIS = "seed"
SEED_MAX = 2**63 - 1  # a scenario's seed is 0 to 2^63 - 1 (replay.scenario.schema)


def check_seed(value: Any, where: str) -> int:
    """``value`` if it is a scenario's seed (a whole number from 0 to 2^63 - 1), else a
    SweepSpecError naming ``where`` (--seed, a sweep file's seed, the seed axis)."""
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= SEED_MAX:
        raise SweepSpecError(f"{where}: expected a seed from 0 to 2^63 - 1, got {show(value, 24)}")
    return value


def sets_for(point: dict[str, Any]) -> tuple[str | None, int | None, list[str]]:
    """A variant's point -> (scenario file or None, seed or None, ``--set`` assignments)."""
    scenario = seed = None
    sets = []
    for name, value in point.items():
        if name == SCENARIO_AXIS:
            scenario = value
        elif name == SEED_AXIS:
            seed = check_seed(value, SEED_AXIS)
        elif isinstance(value, dict):
            sets += [f"{k}={_yaml_text(v)}" for k, v in value.items()]
        else:
            sets.append(f"{name}={_yaml_text(value)}")
    return scenario, seed, sets
