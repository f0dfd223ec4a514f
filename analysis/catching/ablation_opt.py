"""Catching's optimisation thesis where the paper ran it (issue #38; Namiki & Ishikawa 2003,
Figs. 6, 8, 9): does optimising alpha offline (eq. 25 under eqs. 13, 22, 24) reduce the joint
torques and travel at 8-10 m/s, and at which torque limits?

The sweep (``sweeps/catch_optimisation.yaml``, made by ``python -m analysis.catching.ablation_opt
sweep``) crosses one linked axis ``cell`` -- a torque-limit scale s of the assumed public_urdf
set (60, 60, 45, 30) N*m with one alpha -- with the shared perturbed throws
(:func:`analysis.catching.throws.perturbed_throws`, 8-10 m/s). The alphas (``ALPHAS``):

- ``initial``: the minimum-norm alpha meeting eq. 13 only (no cost): the paper's unoptimised one;
- ``optimised``: eq. 25 re-optimised at the level, eq. 22's hinge on at s x (60, 60, 30) N*m;
- ``optimised, eq. 22 off``: the shipped alpha (``alpha_optimised.json``: eq. 22 not imposed);
- ``eq13 from 4-5 m/s`` and ``eq13 random``: the fair falsifiers, alphas that meet eq. 13 exactly
  but were not optimised for these throws (``optimise.project_eq13``, ``null_space_alpha``).

The run quantities come from the plant's truth over t0 (first ball measurement) -> the first
ball-robot ``contact`` event (``analysis.catching.thesis_claims.window_effort``): joint travel
sum |dq| and sum tau^2 dt of the applied torque on J1, J2, J4, and the share of those steps with
a joint at its torque limit. Optimised against initial is compared throw by throw (the same
throws): the ratio of the means with a paired bootstrap 95 % interval; an interval that holds
1 is a tie. Catch rates carry Wilson 95 % intervals.
"""

from __future__ import annotations

import json
import math
from collections import defaultdict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter  # noqa: E402

from analysis.catching.ablations import wilson  # noqa: E402
from replay.resources import data_path, scenario_dir  # noqa: E402
from analysis.ablation_plot import plain_log_ticks, plot_rates, shifts  # noqa: E402
from analysis.ablation_table import caught  # noqa: E402
from analysis.figure_files import save  # noqa: E402
from replay.sweep.table import as_float  # noqa: E402

NAME = "catch_optimisation"
ROOT = Path(__file__).resolve().parents[2]  # (a checkout: where `sweep` and `store` write)
SCENARIO = scenario_dir() / "catch_optimised.yaml"
ALPHA_DIR = data_path("catching")
# alpha files as the sweep names them: relative to the scenario's folder, as a scenario file
# writes them (a sweep's worker resolves them there: replay.scenario.loader.file_dirs); a
# missing file would be recomputed as eq. 25's optimum, so every run logs the model cost of the
# alpha it used (effort_metrics' alpha_cost) and tests/replay/sweep/test_sweep_file_params.py
# checks that every shipped sweep's file exists
ALPHA_REL = "../data/catching"
PLANT_TAU = (60.0, 60.0, 45.0, 30.0)  # N*m: public_urdf (assumed, scenarios/catch_optimised.yaml)
OPT_TAU = (60.0, 60.0, 30.0)  # N*m: eq. 22's tau_max on J1, J2, J4 at scale 1
SCALES = (0.5, 1.0, 2.0, 3.0, 4.0, 8.0)  # torque-limit scales swept
N_THROWS = 30  # shared perturbed throws, 8-10 m/s (>= 20 a cell)
THROW_SEED = 20030914  # analysis.catching.throws.perturbed_throws' default: the shared set
RANDOM_SEED = 2003  # the random null-space direction of the 'eq13 random' falsifier
N_BOOT = 2000
INITIAL, OPTIMISED, SHIPPED = "initial", "optimised", "optimised, eq. 22 off"
OTHER, RANDOM = "eq13 from 4-5 m/s", "eq13 random"
RANDOM_FULL = "eq13 random, optimum's length"
NEIGHBOUR = "optimised, K_tau per level"  # the cost-weight rule's neighbour: w_tau = 1
ALPHAS = (INITIAL, OPTIMISED, NEIGHBOUR, SHIPPED, OTHER, RANDOM, RANDOM_FULL)
FALSIFIER_FILES = {
    OTHER: "alpha_eq13_from_4_5ms.json",
    RANDOM: "alpha_eq13_random.json",
    RANDOM_FULL: "alpha_eq13_random_long.json",
}
FULL_SCALES = (1.0, 4.0)  # the levels the long random step (a strawman: eq. 24 broken) runs at
NEIGHBOUR_SCALES = (2.0, 4.0, 8.0)  # (at 1 it is 'optimised'; at 0.5 eq. 22 is far off)


def level_file(scale: float, neighbour: bool = False) -> str:
    return f"alpha_catchopt_x{scale:g}" + ("_ktau_level" if neighbour else "") + ".json"


# -- the cells: what each alpha sets at each level ---------------------------------------------


def _opt_sets(scale: float, neighbour: bool = False) -> dict:
    """Eq. 25 at a level: eq. 22's limits s x OPT_TAU with its hinge as eq. 24's (weight
    limit_penalty = 100), K_tau held at scale 1's normalisers (w_tau = s^2, since K_tau =
    w_tau diag(1/tau_max^2)): only the constraint moves with the level, not the cost. The
    ``neighbour`` rule keeps w_tau = 1 (K_tau normalised by the level's limits, as the shipped
    scenario's rule reads): the torque term weighs 1/s^2 as much against the velocity term."""
    return {
        "controller.params.mapping": "optimised",
        "controller.params.alpha_file": f"{ALPHA_REL}/{level_file(scale, neighbour)}",
        "controller.params.opt_torque_limits": [scale * t for t in OPT_TAU],
        "controller.params.w_tau": 1.0 if neighbour else scale * scale,
        "controller.params.torque_limit_penalty": -1.0,
    }


def _default_sets(mapping: str, alpha_file: str) -> dict:
    """The shipped optimisation's configuration (eq. 22 reported, not imposed; its normalisers
    the scale-1 limits whatever the plant's, so that the stored alphas' keys match)."""
    return {
        "controller.params.mapping": mapping,
        "controller.params.alpha_file": alpha_file,
        "controller.params.opt_torque_limits": list(OPT_TAU),
        "controller.params.w_tau": 1.0,
        "controller.params.torque_limit_penalty": 0.0,
    }


def cell_sets(scale: float, alpha: str) -> dict:
    """The scenario fields of one cell: the plant's limits at the scale and the alpha."""
    plant = {"plant.params.torque_limits": [scale * t for t in PLANT_TAU]}
    if alpha in (OPTIMISED, NEIGHBOUR):
        return plant | _opt_sets(scale, alpha == NEIGHBOUR)
    if alpha == INITIAL:
        return plant | _default_sets("initial", "")
    name = "alpha_optimised.json" if alpha == SHIPPED else FALSIFIER_FILES[alpha]
    return plant | _default_sets("optimised", f"{ALPHA_REL}/{name}")


def cell_label(scale: float, alpha: str) -> str:
    return f"x{scale:g} {alpha}"


def parse_cell(label: str) -> tuple[float, str]:
    """'x2 optimised' -> (2.0, 'optimised')."""
    head, _, alpha = str(label).partition(" ")
    return float(head.removeprefix("x")), alpha


def throws(n: int = N_THROWS) -> list[dict]:
    from analysis.catching.throws import perturbed_throws

    return perturbed_throws(n, THROW_SEED)


def throw_label(i: int, throw: dict) -> str:
    return f"throw {i} ({throw['speed']:.2f} m/s)"


# -- the offline alphas (data/catching/) -------------------------------------------------------


def _controller(sets: dict, scenario: Path = SCENARIO):
    """A runner whose controller holds the cell's problem, built with mapping 'initial' (so
    nothing is optimised on construction); the caller closes its plant."""
    from replay.runner import Runner
    from replay.scenario import load_scenario

    fresh = sets | {"controller.params.mapping": "initial", "controller.params.alpha_file": ""}
    return Runner(load_scenario(scenario, [f"{k}={json.dumps(v)}" for k, v in fresh.items()]))


SLOW_FALSIFIER = "alpha_5ms_eq13_from_8_10ms.json"  # for catch_5ms_optimised (4.5 m/s)


def write_slow_falsifier(dest: Path = ALPHA_DIR) -> dict:
    """The 4.5 m/s rows' falsifier made fair: the 8-10 m/s optimum (alpha_optimised.json)
    projected onto catch_5ms_optimised's eq. 13, keyed to that scenario's configuration (use it
    with ``controller.params.alpha_file``). Returns its cost record."""
    from replay.control.catching.optimise import OptimResult, load_alpha, project_eq13, save_alpha

    runner = _controller({}, scenario_dir() / "catch_5ms_optimised.yaml")
    try:
        ctrl = runner.controller
        prob = ctrl.problem
        alpha = project_eq13(
            load_alpha(ALPHA_DIR / "alpha_optimised.json")["alpha"], prob.C, prob.rhs
        )
        res = OptimResult(
            alpha=alpha,
            alpha0=ctrl.alpha0,
            history=[prob.objective.record(0, alpha)],
            constraint_residual=float(np.max(np.abs(prob.C @ alpha - prob.rhs))),
        )
        why = (
            "falsifier, not an optimum: alpha_optimised.json (eq. 25 for 8-10 m/s throws) "
            "projected onto catch_5ms_optimised's eq. 13 (the nearest alpha with C alpha = rhs)"
        )
        meta = {"key": ctrl.config.key(ctrl.model), "config": vars(ctrl.config), "made": why}
        save_alpha(dest / SLOW_FALSIFIER, res, meta)
        return vars(res.history[-1])
    finally:
        runner.plant.close()


def write_alphas(dest: Path = ALPHA_DIR) -> dict[str, dict]:
    """Every alpha file the sweep reads except the shipped one: eq. 25 re-optimised at each
    level, and the two falsifiers (keyed to the shipped configuration, so that the controller
    takes them as they are). Returns {file name: its last cost record}."""
    from replay.control.catching.optimise import OptimResult, load_alpha, save_alpha

    out = {}
    levels = [(s, False) for s in SCALES] + [(s, True) for s in NEIGHBOUR_SCALES]
    for s, neighbour in levels:
        name = level_file(s, neighbour)
        runner = _controller(_opt_sets(s, neighbour))
        try:
            runner.controller.write_alpha_file(dest / name)
        finally:
            runner.plant.close()
        out[name] = load_alpha(dest / name)["history"][-1]
    runner = _controller(_default_sets("optimised", ""))
    try:
        ctrl = runner.controller
        for label, (alpha, why) in falsifier_alphas(ctrl).items():
            prob = ctrl.problem
            res = OptimResult(
                alpha=alpha,
                alpha0=ctrl.alpha0,
                history=[prob.objective.record(0, alpha)],
                constraint_residual=float(np.max(np.abs(prob.C @ alpha - prob.rhs))),
            )
            meta = {"key": ctrl.config.key(ctrl.model), "config": vars(ctrl.config), "made": why}
            save_alpha(dest / FALSIFIER_FILES[label], res, meta)
            out[FALSIFIER_FILES[label]] = res.history[-1]
    finally:
        runner.plant.close()
    return out


def falsifier_alphas(ctrl) -> dict[str, tuple[np.ndarray, str]]:
    """The falsifiers' alphas for a controller of the shipped configuration, each meeting its
    eq. 13 exactly, none optimised for its throws: {label: (alpha, how it was made)}."""
    from replay.control.catching.optimise import load_alpha, null_space_alpha, project_eq13

    prob = ctrl.problem
    shipped = load_alpha(ALPHA_DIR / "alpha_optimised.json")["alpha"]
    other = load_alpha(ALPHA_DIR / "alpha_5ms_optimised.json")["alpha"]
    size = float(np.linalg.norm(shipped - ctrl.alpha0))
    step = admissible_step(prob, size)
    return {
        OTHER: (
            project_eq13(other, prob.C, prob.rhs),
            "falsifier, not an optimum: alpha_5ms_optimised.json (eq. 25 for 4-5 m/s throws) "
            "projected onto this set's eq. 13 (the nearest alpha with C alpha = rhs)",
        ),
        RANDOM: (
            null_space_alpha(prob.C, prob.rhs, step, RANDOM_SEED),
            f"falsifier, not an optimum: alpha0 + Z beta, beta a random direction (seed "
            f"{RANDOM_SEED}), |Z beta| = {step:.4g}, the longest step up to the optimum's "
            f"({size:.4g}) that keeps eq. 24 over the sample set",
        ),
        RANDOM_FULL: (
            null_space_alpha(prob.C, prob.rhs, size, RANDOM_SEED),
            f"falsifier, not an optimum: alpha0 + Z beta, beta a random direction (seed "
            f"{RANDOM_SEED}), |Z beta| = |alpha_optimised - alpha0| = {size:.4g} (eq. 24 not "
            "kept)",
        ),
    }


def admissible_step(prob, size: float, iters: int = 40) -> float:
    """The longest step along the 'eq13 random' direction, at most ``size``, whose alpha keeps
    eq. 24 (max |omega|/omega_max <= 1 over the sample set; bisection)."""
    from replay.control.catching.optimise import null_space_alpha

    def ok(h: float) -> bool:
        alpha = null_space_alpha(prob.C, prob.rhs, h, RANDOM_SEED)
        return prob.objective.record(0, alpha).max_velocity_ratio <= 1.0

    if ok(size):
        return size
    lo, hi = 0.0, size
    for _ in range(iters):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if ok(mid) else (lo, mid)
    return lo


def model_costs(dest: Path = ALPHA_DIR) -> dict[str, dict]:
    """The optimiser's model (eq. 17 over its 27-throw sample set) of every alpha file the
    sweep reads: {file: {torque_cost, velocity_cost, max_torque_ratio, max_velocity_ratio}} of
    the stored alpha (initial: iteration 0 of a level's history)."""
    from replay.control.catching.optimise import load_alpha

    out = {}
    files = [level_file(s) for s in SCALES] + [level_file(s, True) for s in NEIGHBOUR_SCALES]
    files += list(FALSIFIER_FILES.values())
    for name in files + ["alpha_optimised.json"]:
        path = dest / name
        if path.is_file():
            h = load_alpha(path)["history"]
            out[name] = {"first": vars(h[0]), "last": vars(h[-1])}
    return out


# -- the sweep file ------------------------------------------------------------------------------

_HEADER = """\
# Namiki & Ishikawa 2003, Figs. 6, 8, 9 (issue #38): does optimising alpha offline (eq. 25 under
# eqs. 13, 22, 24) reduce joint torque and travel at the paper's 8-10 m/s, and at which torque
# limits? MADE BY `python -m analysis.catching.ablation_opt sweep` (do not edit by hand).
#
# Torque limits (assumed: the paper gives none): the plant's public_urdf (60, 60, 45, 30) N*m
# scaled by s in {scales}; eq. 22's tau_max = s x (60, 60, 30) N*m on J1, J2, J4.
# The rule that keeps the comparison fair at every level:
# - 'optimised': eq. 25 re-optimised offline at the level (data/catching/alpha_catchopt_xS.json,
#   `python -m analysis.catching.ablation_opt alphas`) with eq. 22's hinge ON (weight 100, as eq.
#   24's) and K_tau held at s = 1's normalisers (w_tau = s^2): only the constraint moves;
#   its neighbour 'optimised, K_tau per level' (w_tau = 1: K_tau normalised by the level's
#   limits, so the torque term weighs 1/s^2 as much) at s = 2, 4, 8 (_ktau_level.json);
# - 'initial': the minimum-norm alpha that meets eq. 13 only (it does not depend on the limits);
# - 'optimised, eq. 22 off': the shipped alpha_optimised.json (catch_optimised's: eq. 22 not
#   imposed, the hinge inactive at s >= 4 where it is the 'optimised' one);
# - falsifiers, alphas that meet eq. 13 exactly but are not optimised for these throws:
#   'eq13 from 4-5 m/s' = alpha_5ms_optimised.json projected onto this set's eq. 13 (the 4.5 m/s
#   falsifier made fair); 'eq13 random' = alpha0 + a seeded random null-space step, the longest
#   (up to the optimum's length) that keeps eq. 24; "eq13 random, optimum's length" the same
#   direction at the optimum's length (breaks eq. 24: a strawman, only at x1 and x4)
#   (data/catching/alpha_eq13_*.json, keyed to the shipped configuration);
# - PD gains, velocity limits (eq. 24 at (3, 13.5, 37) rad/s) and the hand unchanged.
# Throws: the shared perturbed set (analysis.catching.throws.perturbed_throws, seed {seed}):
# {n} throws at 8-10 m/s, the same for every cell. Metrics (analysis.catching.ablation_opt:
# effort_metrics): plant truth from the first ball measurement to the first ball-robot contact.
"""


def sweep_data() -> dict:
    cells = {
        cell_label(s, a): cell_sets(s, a)
        for s in SCALES
        for a in ALPHAS
        if (a != RANDOM_FULL or s in FULL_SCALES) and (a != NEIGHBOUR or s in NEIGHBOUR_SCALES)
    }
    grid_throws = {
        throw_label(i, th): {
            "plant.params.object_position": [round(x, 6) for x in th["position"]],
            "plant.params.object_velocity": [round(x, 6) for x in th["velocity"]],
        }
        for i, th in enumerate(throws())
    }
    return {
        "name": NAME,
        "paper": "namiki2003",
        "description": "joint torque and travel of initial vs optimised alpha against torque limits",
        "scenario": "../scenarios/catch_optimised.yaml",
        "seed": 0,
        "set": {"timing.duration": 0.45, "stop.after": 0.0},
        "grid": {"cell": cells, "throw": grid_throws},
        "metrics": "analysis.catching.ablation_opt:effort_metrics",
        "plot": "analysis.catching.ablation_opt:plot_catch_opt",
        "caption": (
            "At 8-10 m/s, sum tau^2 dt and joint travel before first contact of each alpha "
            "relative to the initial one on the same throws (paired bootstrap 95 % intervals), "
            "and the catch rate (Wilson 95 %), against the torque-limit scale."
        ),
        "summary": "analysis.catching.ablation_opt:summary_catch_opt",
    }


def sweep_text() -> str:
    import yaml

    head = _HEADER.format(scales=", ".join(f"{s:g}" for s in SCALES), seed=THROW_SEED, n=N_THROWS)
    body = yaml.safe_dump(sweep_data(), sort_keys=False, width=100, default_flow_style=None)
    return head + body


# -- the metrics of one run ----------------------------------------------------------------------


def effort_metrics(log) -> dict:
    """Plant truth over t0 -> first ball-robot contact: joint travel (rad), sum tau^2 dt
    (N^2 m^2 s) on J1, J2, J4, the window, and the share of its steps with a joint at its torque
    limit (the applied torque within 0.1 % of it: the arm could not deliver more); and which
    alpha the run used: its model torque cost and iterations as the run logged them
    (``/optimization/cost``; a stored alpha keeps its file's history)."""
    from analysis.catching.thesis_claims import ACTIVE, window_effort
    from replay.messages import TOPIC_ARM_JOINT_STATE

    from replay.messages import TOPIC_OPTIMIZATION_COST

    costs = sorted(log.series(TOPIC_OPTIMIZATION_COST), key=lambda c: c["iteration"])
    used = {"alpha_iterations": len(costs) - 1, "alpha_cost": round(costs[-1]["torque_cost"], 3)}
    w = window_effort(log)
    if w is None:
        return used
    import yaml

    sc = yaml.safe_load(log.series("/scenario")[0]["yaml"])
    lim = np.asarray(sc["plant"]["params"]["torque_limits"], float)[ACTIVE]
    js = [
        m["effort"]
        for m in log.series(TOPIC_ARM_JOINT_STATE)
        if w["t0"] - 1e-9 <= m["t"] <= w["t_contact"] + 1e-9
    ]
    tau = np.abs(np.asarray(js, float)[:, ACTIVE])
    at_limit = np.any(tau >= 0.999 * lim, axis=1)
    return used | {
        "travel": round(w["travel_sum"], 6),
        "tau_sq_dt": round(w["tau_sq_dt_sum"], 6),
        "t0": w["t0"],
        "t_contact": w["t_contact"],
        "saturated_share": round(float(np.mean(at_limit)), 4),
    }


def effort_profile(log) -> dict:
    """Sum tau^2 dt of the applied torque on J1, J2, J4 (plant truth, N^2 m^2 s) from t0 (first
    ball measurement) to: the first contact, the mapping's hold (q_d frozen at the catch surface,
    the end of the trajectory eq. 25 samples) and the log's end; with those instants (s)."""
    from analysis.catching.thesis_claims import ACTIVE
    from analysis.series import events
    from replay.messages import TOPIC_ARM_JOINT_STATE, TOPIC_CATCHING_STATE

    js = log.series(TOPIC_ARM_JOINT_STATE)
    t = np.array([m["t"] for m in js])
    tau = np.array([m["effort"] for m in js])[:, ACTIVE]
    e = np.concatenate([[0.0], np.cumsum(np.sum(tau[1:] ** 2, axis=1) * np.diff(t))])
    t0 = float(log.series(TOPIC_CATCHING_STATE)[0]["t"])
    first = {k: float(next(iter(events(log, k)))["t"]) for k in ("contact", "mapping_hold")}

    def upto(x: float) -> float:
        return float(e[np.searchsorted(t, x + 1e-9) - 1] - e[np.searchsorted(t, t0 - 1e-9)])

    out = {f"t_{k}": v for k, v in first.items()}
    return out | {
        "to_contact": upto(first["contact"]),
        "to_hold": upto(first["mapping_hold"]),
        "to_end": upto(float(t[-1])),
    }


def mechanism(scale: float = 8.0) -> dict:
    """The nominal 9 m/s throw (catch_optimised's) with the initial and the shipped optimised
    alpha at a torque-limit scale, logged 50 ms past the catch: {alpha: effort_profile}."""
    import tempfile

    from replay.log import LogReader
    from replay.runner import Runner
    from replay.scenario import load_scenario

    out = {}
    with tempfile.TemporaryDirectory(prefix="catchopt-") as tmp:
        for alpha in (INITIAL, SHIPPED):
            sets = {**cell_sets(scale, alpha), "timing.duration": 0.45, "stop.after": 0.05}
            sc = load_scenario(SCENARIO, [f"{k}={json.dumps(v)}" for k, v in sets.items()])
            path = Path(tmp) / "run.mcap"
            Runner(sc).run(path)
            out[alpha] = effort_profile(LogReader(path))
    return out


# -- reading the table ---------------------------------------------------------------------------


def _by_cell(rows: list[dict]) -> dict[tuple[float, str], dict[str, dict]]:
    """{(scale, alpha): {throw label: row}}."""
    out: dict = defaultdict(dict)
    for r in rows:
        out[parse_cell(r["cell"])][r["throw"]] = r
    return dict(out)


def paired_ratio(a: list[float], b: list[float], seed: int = 0) -> tuple[float, float, float]:
    """mean(a) / mean(b) over the pairs where both are finite, with a paired bootstrap 95 %
    interval (N_BOOT resamples of the pairs, percentiles)."""
    x, y = np.asarray(a, float), np.asarray(b, float)
    ok = np.isfinite(x) & np.isfinite(y)
    x, y = x[ok], y[ok]
    if len(x) < 2 or np.mean(y) <= 0:
        return float("nan"), float("nan"), float("nan")
    idx = np.random.default_rng(seed).integers(0, len(x), (N_BOOT, len(x)))
    boot = x[idx].mean(axis=1) / y[idx].mean(axis=1)
    lo, hi = np.percentile(boot, [2.5, 97.5])
    return float(np.mean(x) / np.mean(y)), float(lo), float(hi)


def mean_ci(a: list[float], seed: int = 0) -> tuple[float, float, float]:
    """Mean with a bootstrap 95 % interval (finite values only)."""
    x = np.asarray(a, float)
    x = x[np.isfinite(x)]
    if len(x) < 2:
        return float("nan"), float("nan"), float("nan")
    boot = x[np.random.default_rng(seed).integers(0, len(x), (N_BOOT, len(x)))].mean(axis=1)
    lo, hi = np.percentile(boot, [2.5, 97.5])
    return float(np.mean(x)), float(lo), float(hi)


def _column(by_throw: dict, keys: list, metric: str) -> list[float]:
    """A metric (``x.`` column) of the rows of ``keys`` in order, nan where absent."""
    return [as_float(by_throw[k].get(f"x.{metric}")) if k in by_throw else math.nan for k in keys]


def compare(rows: list[dict]) -> dict[tuple[float, str], dict]:
    """Per (scale, alpha): catches k/n, the mean metrics with intervals, and the paired ratios to
    the initial alpha at the same scale (travel, tau_sq_dt), on the same throws."""
    cells = _by_cell(rows)
    out = {}
    for (scale, alpha), by_throw in cells.items():
        base = cells.get((scale, INITIAL), {})
        keys = sorted(by_throw)
        k = sum(caught(by_throw[t]) for t in keys)
        res: dict = {"k": k, "n": len(keys), "rate": wilson(k, len(keys))}
        for c in ("travel", "tau_sq_dt", "saturated_share"):
            res[c] = mean_ci(_column(by_throw, keys, c))
        for c in ("travel", "tau_sq_dt"):
            res[f"{c}_ratio"] = paired_ratio(_column(by_throw, keys, c), _column(base, keys, c))
        out[(scale, alpha)] = res
    return out


def verdict_of(ratio: tuple[float, float, float]) -> str:
    """'lower' / 'higher' if the 95 % interval excludes 1, else 'tie'."""
    _, lo, hi = ratio
    if not (math.isfinite(lo) and math.isfinite(hi)):
        return "n/a"
    return "lower" if hi < 1.0 else "higher" if lo > 1.0 else "tie"


def _pct(r: tuple[float, float, float]) -> str:
    m, lo, hi = r
    return f"{100 * (m - 1):+.0f} % [{100 * (lo - 1):+.0f}, {100 * (hi - 1):+.0f}]"


# -- plot, sentence, thesis ----------------------------------------------------------------------

_STYLE = {
    OPTIMISED: ("tab:blue", "o-"),
    NEIGHBOUR: ("tab:purple", "P-."),
    SHIPPED: ("tab:cyan", "D:"),
    OTHER: ("tab:red", "s--"),
    RANDOM: ("tab:orange", "^--"),
    RANDOM_FULL: ("tab:brown", "x:"),
    INITIAL: ("0.3", "v-"),
}


def plot_catch_opt(rows: list[dict], out: Path, stem: str) -> list[Path]:
    res = compare(rows)
    scales = sorted({s for s, _ in res})
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(6.6, 9.2))
    ratio_alphas = [a for a in ALPHAS if a != INITIAL]
    for ax, what, label in (
        (axes[0], "tau_sq_dt_ratio", "Σ τ² dt before contact\nrel. to initial α"),
        (axes[1], "travel_ratio", "joint travel before contact\nrel. to initial α"),
    ):
        for alpha, dx in zip(ratio_alphas, shifts(len(ratio_alphas), 0.02)):
            pts = [(s, res[(s, alpha)][what]) for s in scales if (s, alpha) in res]
            if not pts:
                continue
            xs = np.array([p[0] for p in pts]) * 10**dx
            m = np.array([p[1][0] for p in pts])
            err = np.array([[p[1][0] - p[1][1], p[1][2] - p[1][0]] for p in pts]).T.clip(min=0)
            color, fmt = _STYLE[alpha]
            ax.errorbar(
                xs, m, yerr=err, fmt=fmt, color=color, capsize=3, elinewidth=0.8, label=alpha
            )
        ax.axhline(1.0, color="0.5", lw=0.8)
        ax.set_yscale("log")  # ratios: x2 and x0.5 equally far from 1
        ax.yaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.yaxis.set_minor_formatter(NullFormatter())
        ax.set_ylabel(label + "\n(ratio of means, paired\nbootstrap 95 %, log)", fontsize=8)
        ax.grid(True, which="both", alpha=0.3)
    feasible = eq22_feasible_scale()
    for ax in axes:
        if feasible is not None:
            ax.axvspan(
                feasible,
                max(scales) * 1.2,
                color="tab:green",
                alpha=0.08,
                label="eq. 22 holds at the model optimum" if ax is axes[0] else None,
            )
    for alpha, dx in zip(ALPHAS, shifts(len(ALPHAS), 0.02)):
        pts = [(s, res[(s, alpha)]) for s in scales if (s, alpha) in res]
        if not pts:
            continue
        color, fmt = _STYLE[alpha]
        plot_rates(
            axes[2],
            [p[0] for p in pts],
            [p[1]["k"] for p in pts],
            [p[1]["n"] for p in pts],
            fmt,
            alpha,
            dx,
            log_x=True,
            color=color,
        )
    axes[2].set_ylabel("catch rate k/n\n(Wilson 95 %)", fontsize=8)
    axes[2].set_ylim(-0.05, 1.05)
    axes[2].grid(True, alpha=0.3)
    axes[2].set_xscale("log")
    plain_log_ticks(axes[2])
    axes[2].set_xticks(scales)
    axes[2].set_xlabel("torque-limit scale s (limits s × (60, 60, 45, 30) N·m)")
    axes[0].legend(fontsize=7)
    axes[2].legend(fontsize=7, ncol=2, loc="upper center", bbox_to_anchor=(0.5, -0.3))
    axes[0].set_title("Optimised vs initial α at 8-10 m/s against the torque limits", fontsize=10)
    fig.tight_layout()
    return save(fig, out, stem)


def eq22_feasible_scale(dest: Path = ALPHA_DIR) -> float | None:
    """The smallest swept scale whose re-optimised alpha meets eq. 22 in the model (max
    |tau|/tau_max <= 1 over the sample set), or None."""
    costs = model_costs(dest)
    ok = [
        s
        for s in SCALES
        if costs.get(level_file(s), {}).get("last", {}).get("max_torque_ratio", math.inf) <= 1.0
    ]
    return min(ok) if ok else None


def _reduced(r: dict) -> bool:
    return verdict_of(r["tau_sq_dt_ratio"]) == "lower" and verdict_of(r["travel_ratio"]) in (
        "lower",
        "tie",
    )


def summary_catch_opt(rows: list[dict]) -> str:
    res = compare(rows)
    parts = []
    for s in sorted({s for s, _ in res}):
        r, i = res.get((s, OPTIMISED)), res.get((s, INITIAL))
        if r is None or i is None:
            continue
        parts.append(
            f"x{s:g}: Σ τ² dt {_pct(r['tau_sq_dt_ratio'])}, travel {_pct(r['travel_ratio'])}, "
            f"caught {r['k']}/{r['n']} vs {i['k']}/{i['n']}"
        )
    return (
        "Re-optimised α against the initial α on the same 8-10 m/s throws (ratio of means − 1, "
        "paired bootstrap 95 %): " + "; ".join(parts) + "."
    )


def _beats_falsifiers(res: dict, s: float) -> bool:
    """The optimised alpha's sum tau^2 dt ratio lies below every falsifier's at the level, the
    intervals apart (else an unoptimised eq.-13 alpha does as well: not the optimisation)."""
    hi = res[(s, OPTIMISED)]["tau_sq_dt_ratio"][2]
    return all(hi < res[(s, a)]["tau_sq_dt_ratio"][1] for a in (OTHER, RANDOM) if (s, a) in res)


def _neighbour_said(res: dict, s: float) -> str:
    """The cost-weight neighbour at a level, if it ran: its ratios and catches."""
    r = res.get((s, NEIGHBOUR))
    if r is None:
        return ""
    return (
        f"; with K_τ normalised per level instead (w_τ = 1) x{s:g}: Σ τ² dt "
        f"{_pct(r['tau_sq_dt_ratio'])}, travel {_pct(r['travel_ratio'])}, caught {r['k']}/{r['n']}"
    )


def thesis(tables: dict) -> dict:
    """The verdict on Figs. 6/8/9's thesis from the stored table: {verdict, numbers, figure}.
    A level supports it if the re-optimised alpha lowers sum tau^2 dt against the initial one
    (paired interval below 1) without raising travel, and beats the falsifiers (eq. 13 met, no
    optimisation) beyond the intervals; 'holds' at every swept level, 'holds only when ...' at
    some, 'does not hold' at none."""
    rows = tables.get(NAME) if isinstance(tables, dict) else tables
    res = compare(rows or [])
    scales = sorted({s for s, a in res if a == OPTIMISED})
    if not scales:
        return {"verdict": "not run", "numbers": f"run `replay ablate {NAME}`", "figure": NAME}
    good = [s for s in scales if _reduced(res[(s, OPTIMISED)]) and _beats_falsifiers(res, s)]
    if len(good) == len(scales):
        verdict = "holds"
    elif good and good == scales[scales.index(min(good)) :]:
        verdict = f"holds only when the torque limits are ≥ x{min(good):g} the assumed ones"
    elif good:
        verdict = "holds only at torque limits x" + ", x".join(f"{s:g}" for s in good)
    else:
        verdict = "does not hold"
    top, base = scales[-1], 1.0 if 1.0 in scales else scales[0]
    o, ob = res[(top, OPTIMISED)], res[(base, OPTIMISED)]
    feasible = eq22_feasible_scale()
    fal = ", ".join(
        f"{a} {_pct(res[(top, a)]['tau_sq_dt_ratio'])}" for a in (OTHER, RANDOM) if (top, a) in res
    )
    numbers = (
        f"re-optimised α vs the initial α on {o['n']} throws at 8-10 m/s (ratio of means − 1, "
        "paired bootstrap 95 %), torque limits x the assumed (60, 60, 45, 30) N·m: Σ τ² dt "
        + ", ".join(f"x{s:g} {_pct(res[(s, OPTIMISED)]['tau_sq_dt_ratio'])}" for s in scales)
        + f"; travel x{base:g} {_pct(ob['travel_ratio'])}, x{top:g} {_pct(o['travel_ratio'])}"
        + (f"; eq. 22 holds at the model optimum from x{feasible:g}" if feasible else "")
        + f", joints at their limit x{top:g} {100 * o['saturated_share'][0]:.0f} % of steps"
        + f"; unoptimised eq.-13 α (falsifiers) at x{top:g}: {fal}"
        + _neighbour_said(res, top)
        + f"; caught x{base:g} {ob['k']}/{ob['n']}, x{top:g} {o['k']}/{o['n']} (initial "
        f"{res[(base, INITIAL)]['k']}/{res[(base, INITIAL)]['n']}, "
        f"{res[(top, INITIAL)]['k']}/{res[(top, INITIAL)]['n']})"
    )
    return {"verdict": verdict, "numbers": numbers, "figure": NAME}


def markdown(rows: list[dict]) -> str:
    """The table of every cell: catches, means and paired ratios with their intervals."""
    res = compare(rows)
    lines = [
        "| scale | α | caught | Σ τ² dt [N²·m²·s] | vs initial | travel [rad] | vs initial | "
        "at torque limit |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for (s, a), r in sorted(res.items(), key=lambda kv: (kv[0][0], ALPHAS.index(kv[0][1]))):
        lo, hi = r["rate"]
        t, tr, sat = r["tau_sq_dt"], r["travel"], r["saturated_share"]
        lines.append(
            f"| x{s:g} | {a} | {r['k']}/{r['n']} [{100 * lo:.0f}–{100 * hi:.0f} %] | "
            f"{t[0]:.1f} [{t[1]:.1f}, {t[2]:.1f}] | "
            + ("—" if a == INITIAL else _pct(r["tau_sq_dt_ratio"]))
            + f" | {tr[0]:.3f} [{tr[1]:.3f}, {tr[2]:.3f}] | "
            + ("—" if a == INITIAL else _pct(r["travel_ratio"]))
            + f" | {100 * sat[0]:.0f} % |"
        )
    return "\n".join(lines)


if __name__ == "__main__":  # python -m analysis.catching.ablation_opt alphas|sweep|table|mechanism
    import sys

    what = sys.argv[1] if len(sys.argv) > 1 else ""
    if what == "alphas":
        for name, rec in write_alphas().items():
            print(name, json.dumps(vars(rec)))
        print(SLOW_FALSIFIER, json.dumps(write_slow_falsifier()))
    elif what == "sweep":
        (ROOT / "sweeps" / f"{NAME}.yaml").write_text(sweep_text(), encoding="utf-8")
        print(f"wrote sweeps/{NAME}.yaml")
    elif what == "mechanism":
        for scale in (1.0, 8.0):
            for alpha, prof in mechanism(scale).items():
                print(f"x{scale:g} {alpha}:", json.dumps({k: round(v, 3) for k, v in prof.items()}))
    elif what == "table":
        from replay.sweep.table import read_table

        table = ROOT / "data" / "ablations" / f"{NAME}.csv"
        text = markdown(read_table(table))
        (ROOT / "data" / "ablations" / f"{NAME}.md").write_text(text + "\n", encoding="utf-8")
        print(text)
    else:
        sys.exit("usage: python -m analysis.catching.ablation_opt alphas|sweep|table|mechanism")
