"""Claims per physics engine: each arm claim's row with the PyBullet and the MuJoCo value side by
side (docs/mujoco.md), the catch (or grasp) rates of both engines on the same throws (or human
paths), and the closing note (which claims hold in both engines, which in one).

A MuJoCo run is the scenario of the same name with ``_mujoco`` appended
(``catch_optimised_mujoco`` is ``catch_optimised`` with ``plant.type: mujoco_arm``,
``grasp_hexahedron_mujoco`` is ``grasp_hexahedron`` with ``mujoco_grasp``). The paper's own
``evaluate`` (``analysis.catch_claims.evaluate``, ``analysis.grasp_claims.evaluate``: a MuJoCo
log's typed params are the MuJoCo rig's, analysis/grasp_run.py) is run once on each engine's
logs, named without the suffix, so both give the same rows; the rows are then joined by quantity.
Every verdict stays the paper module's, from each engine's truth topics.

Wiring (for the claims table and the report): ``engine_rows(evaluate, logs)`` in place of
``evaluate(logs)`` when ``logs`` holds ``*_mujoco`` runs; ``closing_note(rows)`` below the table.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

from analysis.claims import Claim

SUFFIX = "_mujoco"
ENGINES = ("PyBullet", "MuJoCo")


def split_logs(logs: Mapping[str, Any]) -> tuple[dict[str, Any], dict[str, Any]]:
    """(PyBullet logs, MuJoCo logs), the MuJoCo ones named as their PyBullet twins."""
    pb = {n: log for n, log in logs.items() if not n.endswith(SUFFIX)}
    mj = {n[: -len(SUFFIX)]: log for n, log in logs.items() if n.endswith(SUFFIX)}
    return pb, mj


def join(pybullet: Sequence[Claim], mujoco: Sequence[Claim]) -> list[Claim]:
    """One row per quantity: both engines' measurements; the status both share, else
    ``differs`` (the claim does not hold in both engines) with each engine's status."""
    by_q = {r.quantity: r for r in mujoco}
    out = []
    seen = set()
    for a in pybullet:
        b = by_q.get(a.quantity)
        seen.add(a.quantity)
        out.append(_pair(a, b))
    for b in mujoco:
        if b.quantity not in seen:
            out.append(_pair(None, b))
    return out


def _pair(a: Claim | None, b: Claim | None) -> Claim:
    ref = a or b
    assert ref is not None
    ma = a.measured if a else "not run"
    mb = b.measured if b else "not run"
    sa = a.status if a else "not run"
    sb = b.status if b else "not run"
    if sa == sb:
        status, parted = sa, ""
    elif "not run" in (sa, sb):  # one engine has no run for it: the other's verdict stands
        status, parted = (sb if sa == "not run" else sa), ""
    else:
        status = "differs" if "reproduced" in (sa, sb) else sb
        parted = f"engines part: PyBullet {sa}, MuJoCo {sb}"
    note = "; ".join(x for x in (parted, ref.note) if x)
    return Claim(
        ref.quantity,
        ref.stated,
        f"PyBullet: {ma} ‖ MuJoCo: {mb}",
        status,
        note,
        kind=ref.kind,
    )


def engine_rows(evaluate: Callable[[dict], list[Claim]], logs: Mapping[str, Any]) -> list[Claim]:
    """The paper's rows per engine, joined (``join``)."""
    pb, mj = split_logs(logs)
    return join(evaluate(pb) if pb else [], evaluate(mj) if mj else [])


def evaluate_runs(
    evaluate: Callable[[dict], list[Claim]], logs: Mapping[str, Any]
) -> tuple[list[Claim], str]:
    """(rows, note) as the claims table and the report show them: with MuJoCo runs among
    ``logs`` both engines side by side and the closing note; else the paper's rows alone."""
    if not any(n.endswith(SUFFIX) for n in logs):
        return evaluate(dict(logs)), ""
    rows = engine_rows(evaluate, logs)
    return rows, closing_note(rows)


def rate_row(label: str, stated: str, outcomes: Mapping[str, Sequence[Mapping]]) -> Claim:
    """A catch (or grasp) rate per engine on the same perturbed set: ``outcomes`` maps an
    engine to its runs' ``outcome`` data (the plants' verdict). Reproduced when every engine
    reaches 90 %; the failures' reasons in the note."""
    parts, notes, ok = [], [], True
    for engine, res in outcomes.items():
        n = len(res)
        k = sum(bool(o["success"]) for o in res)
        parts.append(f"{engine}: {k}/{n} = {100 * k / n:.0f} %" if n else f"{engine}: not run")
        ok = ok and n > 0 and k >= 0.9 * n
        fails = sorted({str(o["reason"]) for o in res if not o["success"]})
        if fails:
            notes.append(f"{engine} failures: {'; '.join(fails)}")
    return Claim(
        label, stated, ", ".join(parts), "reproduced" if ok else "differs", "; ".join(notes)
    )


def closing_note(rows: Sequence[Claim]) -> str:
    """Which measured claims hold in both engines, which in one (and why: the row's note)."""
    both, one, neither, single = [], [], [], 0
    for r in rows:
        if r.kind != "measured":
            continue
        if r.measured.startswith("PyBullet: not run") or r.measured.endswith("MuJoCo: not run"):
            single += 1  # run in one engine only: no cross-engine verdict
            continue
        if r.status == "reproduced":
            both.append(r.quantity)
        elif "engines part" in r.note:
            one.append(f"{r.quantity} ({r.note.split(';')[0].removeprefix('engines part: ')})")
        elif r.status == "differs":  # (ties, notes and rows not run in either: no verdict)
            neither.append(r.quantity)
    lines = [f"Hold in both engines ({len(both)}): {', '.join(both) or 'none'}."]
    lines.append(f"Hold in one engine only ({len(one)}): {', '.join(one) or 'none'}.")
    lines.append(f"Hold in neither ({len(neither)}): {', '.join(neither) or 'none'}.")
    if single:
        lines.append(f"Run in one engine only, not compared: {single} measured rows.")
    return "\n".join(lines)
