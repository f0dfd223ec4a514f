"""``replay falsify``: show that every measured "reproduced" row of a paper's claims table can fail.

For a paper, the baseline logs are its default scenarios (those ``make run`` runs:
``scenarios/{stick,catch,grasp}_*.yaml`` whose ``paper`` is it) run into a folder, or the logs
already in ``--logs DIR`` that are runs of a scenario as shipped (a variant, one with a
``--set``, is left out with a note: the falsifiers run the shipped scenario). Each
:class:`~analysis.claims.Falsifier` the paper's claims module declares is then run (its scenario
with its overrides) and stands in for the log it ``replaces``; the paper's rows are evaluated
again and the falsifier's row must read "differs".

A measured row that is "reproduced" at baseline and has no falsifier, or whose falsifier leaves
it anything but "differs", fails the check. Rows of other kinds (``other regime``,
``extension``: outside the paper's experiment, never counted) have their falsifiers listed, not
run.

``replay falsify --store`` keeps the result (:func:`store`): per paper, when it ran, on which code
version, with which command, and each verdict (row, variant, baseline, status, flipped) in
``data/claims/falsified.json``; the claims table and the report count a reproduced row only if
it is recorded there as flipped (``analysis.claims.counted``).
"""

from __future__ import annotations

import hashlib
import json
import sys
from datetime import datetime, timezone
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

import yaml

from analysis.claims import Claim, Falsifier, falsifiers_of
from analysis.runs import describe
from replay import registry
from replay.log import LogReader
from replay.resources import find_scenario, scenario_dir
from replay.scenario import load_scenario

DEFAULT_GLOBS = ("stick_*.yaml", "catch_*.yaml", "grasp_*.yaml")  # as the Makefile's SCENARIOS


@dataclass
class Verdict:
    row: str
    variant: str  # the falsifier's name, or "" for a row that has none
    replaces: str
    baseline: str  # the row's status at baseline ("" when the row is not in the table)
    status: str  # the row's status with the variant in place ("" when not run)
    ok: bool
    why: str = ""

    @property
    def flipped(self) -> bool:
        """The falsifier ran and turned its row to "differs"."""
        return bool(self.variant) and self.ok and self.status == "differs"

    def line(self) -> str:
        if not self.variant:
            return f"FAIL  {self.row}: reproduced, but no falsifier is declared"
        if not self.status and self.why:  # (not run: nothing to flip, or never counted)
            return f"skip  {self.row} | {self.variant} | {self.why}"
        mark = "ok  " if self.ok else "FAIL"
        got = f"{self.baseline} -> {self.status}" if self.status else self.baseline or "(no row)"
        return f"{mark}  {self.row} | {self.variant} (replaces {self.replaces}) | {got}"


# the scenarios and logs of another engine than the reference (``catch_optimised_mujoco``, or
# any run whose scenario sets ``plant.params.engine``: analysis.engines.engine_of): the claims
# table joins their rows with the reference run's by quantity; the falsifiers are the reference
# table's, so the check runs on the reference engine's runs


def _reference_engine(config: dict, name: str) -> bool:
    """A resolved scenario (``config``, named ``name``) runs in the reference engine."""
    from analysis.engines import REFERENCE, engine_of

    return engine_of(config, name) == REFERENCE


def default_scenarios(paper: str) -> list[Path]:
    """The paper's default scenarios, as ``make run`` runs them (other engines' aside)."""
    from replay.scenario import resolved_yaml

    out = []
    for pattern in DEFAULT_GLOBS:
        for path in sorted(scenario_dir().glob(pattern)):
            sc = load_scenario(path)
            if sc.paper == paper and _reference_engine(
                yaml.safe_load(resolved_yaml(sc)), path.stem
            ):
                out.append(path)
    return out


def _sets(overrides) -> list[str]:
    return [
        f"{k}={yaml.safe_dump(v, default_flow_style=True).strip().removesuffix('...').strip()}"
        for k, v in overrides.items()
    ]


def run_scenario(path: str | Path, out: Path, sets: Iterable[str] = ()) -> LogReader:
    from replay.runner import Runner

    sc = load_scenario(find_scenario(str(path)), sets=list(sets))
    Runner(sc).run(out)
    return LogReader(out)


def _row(rows: list[Claim], quantity: str) -> Claim | None:
    return next((r for r in rows if r.quantity == quantity), None)


def check(
    evaluate: Callable[[dict[str, LogReader]], list[Claim]],
    baseline: dict[str, LogReader],
    falsifiers: Iterable[Falsifier],
    run_variant: Callable[[Falsifier], LogReader],
    progress: Callable[[str], None] = lambda s: None,
) -> list[Verdict]:
    """Run each falsifier of a reproduced measured row in place of its log and re-evaluate.

    Returns one verdict per falsifier (of a row that is reproduced at baseline; others are
    reported, not run) and one failing verdict per reproduced measured row without any."""
    rows = evaluate(baseline)
    falsifiers = tuple(falsifiers)
    out: list[Verdict] = []
    for f in falsifiers:
        base = _row(rows, f.row)
        if base is None or base.kind != "measured" or base.status != "reproduced":
            # nothing to flip: a row that is missing (its log not run), does not agree, or is
            # of a kind that never counts (another regime, an extension)
            why = (
                "no such row"
                if base is None
                else f"{base.kind}, never counted: not run"
                if base.kind != "measured"
                else f"{base.status}: nothing to flip"
            )
            out.append(
                Verdict(f.row, f.name, f.replaces, base.status if base else "", "", True, why)
            )
            continue
        if f.replaces not in baseline:
            out.append(
                Verdict(
                    f.row, f.name, f.replaces, base.status, "", False, "no baseline log to replace"
                )
            )
            continue
        progress(f"{f.name} (for {f.row})")
        variant = run_variant(f)
        logs = dict(baseline)
        logs[f.replaces] = variant
        now = _row(evaluate(logs), f.row)
        status = now.status if now is not None else "(row gone)"
        out.append(Verdict(f.row, f.name, f.replaces, base.status, status, status == "differs"))
    covered = {f.row for f in falsifiers}
    for r in rows:
        if r.kind == "measured" and r.status == "reproduced" and r.quantity not in covered:
            out.append(Verdict(r.quantity, "", "", r.status, "", False))
    return out


def _baseline_logs(paper: str, logs_dir: Path, say: Callable[[str], None]) -> dict[str, LogReader]:
    """``paper``'s runs as shipped in ``logs_dir`` by scenario name (``--logs``). Left out with
    a note: a variant, a log that is not whole (truncated, damaged: the falsifiers' runs are),
    and a second log of one name (the first by file name is the baseline)."""
    baseline: dict[str, LogReader] = {}
    for p in sorted(logs_dir.glob("*.mcap")):
        r = LogReader(p)
        sc = r.scenario()
        if not _reference_engine(r.scenario_config(), sc["name"]):
            continue
        if yaml.safe_load(sc["yaml"]).get("paper") != paper:
            continue
        why = _no_baseline(r, baseline.get(sc["name"]))
        if why:
            say(f"{paper}: left out {p}: {sc['name']} {why}")
            continue
        baseline[sc["name"]] = r
    return baseline


def _no_baseline(log: LogReader, first: LogReader | None) -> str:
    """Why ``log`` is no baseline ("" if it is one); ``first``: the baseline of its name."""
    changed = describe(log).label  # (the falsifiers run the scenario as shipped)
    if changed:
        return f"({changed}) is no baseline"
    if log.check().status != "complete":
        return f"is {log.status}: no baseline"
    if first is not None:
        return f"has another log, {first.path}: the baseline"
    return ""


def falsify_paper(
    paper: str,
    work: Path,
    logs_dir: Path | None = None,
    progress: Callable[[str], None] | None = None,
) -> list[Verdict]:
    """The whole check for one paper; runs go under ``work`` (baseline/ and variants/)."""
    say = progress or (lambda s: print(s, file=sys.stderr))
    evaluate = registry.load("claims", paper)
    baseline: dict[str, LogReader] = {}
    if logs_dir is not None:
        baseline = _baseline_logs(paper, Path(logs_dir), say)
    else:
        (work / "baseline").mkdir(parents=True, exist_ok=True)
        for path in default_scenarios(paper):
            say(f"{paper}: baseline {path.stem}")
            baseline[path.stem] = run_scenario(path, work / "baseline" / f"{path.stem}.mcap")
    (work / "variants").mkdir(parents=True, exist_ok=True)

    def run_variant(f: Falsifier) -> LogReader:
        scenario = f.scenario or f.replaces
        sets = _sets(f.overrides)
        key = hashlib.sha1("\n".join([scenario, *sets]).encode()).hexdigest()[:8]
        out = work / "variants" / f"{f.replaces}--{f.name}-{key}.mcap"
        if out.is_file():
            return LogReader(out)  # the same variant for another row: run once
        return run_scenario(scenario, out, sets)

    return check(
        evaluate,
        baseline,
        falsifiers_of(evaluate),
        run_variant,
        progress=lambda s: say(f"{paper}: variant {s}"),
    )


def store(
    paper: str,
    verdicts: Iterable[Verdict],
    command: str,
    path: Path | None = None,
    when: datetime | None = None,
    code: str | None = None,
) -> Path:
    """Record ``paper``'s verdicts in ``path`` (default data/claims/falsified.json), keeping the
    other papers' records: when (UTC), the code version, the command, and per verdict its row,
    variant, the run it replaced, the row's status at baseline and with the variant, and whether
    it flipped."""
    from analysis.claims import falsified_path
    from replay.version import code_version

    path = Path(path or falsified_path())
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        data = {}
    if not isinstance(data, dict):
        data = {}
    stamp = (when or datetime.now(timezone.utc)).astimezone(timezone.utc)
    data[paper] = {
        "when": stamp.strftime("%Y-%m-%d %H:%M UTC"),
        "code": code or code_version(),
        "command": command,
        "rows": [
            {
                "row": v.row,
                "variant": v.variant,
                "replaces": v.replaces,
                "baseline": v.baseline,
                "status": v.status,
                "flipped": v.flipped,
            }
            for v in verdicts
        ],
    }
    path.write_text(json.dumps(data, indent=1, ensure_ascii=False, sort_keys=True) + "\n", "utf-8")
    return path
