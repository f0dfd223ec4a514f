"""Namiki & Ishikawa 2003, Figs. 6-9, drawn from runs' logs.

- Fig. 6: the two costs of eq. 25 per optimisation iteration (``/optimization/cost``); the
  unoptimised run's single record is iteration 0, the initial parameters.
- Fig. 7: the catching trajectory: the ball (``/object/state``), the desired end effector
  l(q_d) and the actual l(q) (the controller's ``/effector/state``: the catch point, where the
  ball's centre sits on the palm), per axis against time and seen from the side (x-z).
- Fig. 8: joint angles q1, q2, q4 (``/arm/joint_state``) with q_d (``/arm/joint_command``).
- Fig. 9: command torques (``/arm/joint_command``) with the torque limits.

Figs. 7-9 overlay the optimised run (solid) and the unoptimised one (dashed) when both logs are
given; every other catching run gets its own Fig. 7.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from analysis.catching.metrics import first_contact, opt_limits  # noqa: E402
from analysis.catching.run import (  # noqa: E402
    ACTIVE,
    JOINTS,
    CatchRun,
    load_run,
    optimised_and_initial,
)
from analysis import line_labels  # noqa: E402
from analysis import runs as run_labels  # noqa: E402
from analysis.figure_files import save  # noqa: E402
from analysis.needs import has, skip  # noqa: E402
from replay.log import LogReader  # noqa: E402
from replay.messages import (  # noqa: E402
    TOPIC_ARM_JOINT_COMMAND,
    TOPIC_ARM_JOINT_STATE,
    TOPIC_EFFECTOR_STATE,
    TOPIC_OBJECT_STATE,
    TOPIC_OPTIMIZATION_COST,
)

STYLE = {"optimised": dict(ls="-", lw=1.5), "initial": dict(ls="--", lw=1.3)}
C_BALL, C_DES, C_ACT = "tab:orange", "tab:blue", "tab:green"
# the variants overlaid on a pair (runs of the same experiments that differ in a setting)
MAX_VARIANTS = 4
VARIANT_STYLES = (
    dict(ls=":", lw=1.6),
    dict(ls="-.", lw=1.3),
    dict(ls=(0, (5, 1, 1, 1, 1, 1)), lw=1.3),
    dict(ls=(0, (1, 3)), lw=1.8),
)
VARIANT_COLORS = ("tab:purple", "tab:brown", "tab:olive", "tab:cyan")
# what each figure reads (the contract a catching controller fulfils: docs/catching.md)
TOPICS = {
    "Fig. 6": (TOPIC_OPTIMIZATION_COST,),
    "Fig. 7": (TOPIC_OBJECT_STATE, TOPIC_EFFECTOR_STATE, TOPIC_ARM_JOINT_COMMAND),
    "Fig. 8": (
        TOPIC_ARM_JOINT_STATE,
        TOPIC_EFFECTOR_STATE,
        TOPIC_ARM_JOINT_COMMAND,
        TOPIC_OBJECT_STATE,  # (the window ends at the first contact, placed on the ball)
    ),
    "Fig. 9": (TOPIC_EFFECTOR_STATE, TOPIC_ARM_JOINT_COMMAND, TOPIC_OBJECT_STATE),
}
_VARIANT: dict[str, int] = {}  # run key -> its variant index (-1: a run drawn alone)
_LABEL: dict[str, str] = {}  # run key -> what its scenario changes (analysis/runs.py)


def _titled(run: CatchRun) -> str:
    """The run's key with what it changes, where the key does not say it already."""
    label = _LABEL.get(run.name, "")
    return f"{run.name} ({label})" if label and label not in run.name else run.name


def _label(run: CatchRun) -> str:
    what = "optimised" if run.mapping == "optimised" else "initial parameters"
    if run.mapping not in ("optimised", "initial"):
        what = f"controller {run.mapping}"
    label = _LABEL.get(run.name, "")
    return f"{run.name} ({what}{'; ' + label if label and label not in run.name else ''})"


def _style(run: CatchRun) -> dict:
    if _VARIANT.get(run.name, -1) >= 0:
        return VARIANT_STYLES[_VARIANT[run.name] % len(VARIANT_STYLES)]
    return STYLE["optimised" if run.mapping == "optimised" else "initial"]


def _color(run: CatchRun) -> str:
    if _VARIANT.get(run.name, -1) >= 0:
        return VARIANT_COLORS[_VARIANT[run.name] % len(VARIANT_COLORS)]
    return "tab:blue" if run.mapping == "optimised" else "tab:red"


def _span(run: CatchRun, after: float = 0.08) -> tuple[float, float]:
    start = (run.t0 if run.t0 is not None else run.t_ctrl[0]) - 0.02
    end = (run.t_c if run.t_c is not None else run.t_ctrl[-1]) + after
    return start, min(end, run.t_ctrl[-1])


def _to_contact(run: CatchRun) -> tuple[float, float]:
    """Figs. 8, 9's window: from 20 ms before t0 to the first ball-robot contact (the plant's
    event; the optimisation's claim is about the motion before the ball is met), else t_c."""
    start = (run.t0 if run.t0 is not None else run.t_ctrl[0]) - 0.02
    c = first_contact(run)
    end = c["t"] if c is not None else (run.t_c if run.t_c is not None else run.t_ctrl[-1])
    return start, min(end, run.t_ctrl[-1])


MARKS = {  # what a vertical line is, in a figure's footer
    "t₀": "t₀ (first vision frame used)",
    "t_c": "t_c (r_o on the catch surface, q4 = q_α)",
    "contact": "first contact",
    "catch": "catch",
    "miss": "miss",
    "drop": "drop",
    "more": line_labels.MORE,
}


def _lines_said(drawn: set[str]) -> str:
    """The footer's account of the vertical lines drawn (only those)."""
    said = [text for name, text in MARKS.items() if name in drawn]
    return "vertical lines: " + ", ".join(said) if said else "no event in the time span"


def _marks(ax, run: CatchRun, style: dict, drawn: set[str]) -> list[tuple[float, str]]:
    """Draw t0 (mapping starts), t_c (catch surface), first contact and catch/miss within the
    axes' time span (at most :data:`~analysis.line_labels.MAX_MARKS` of a kind); returns them
    for :func:`analysis.line_labels.place` (after the layout) and adds what it drew to
    ``drawn`` (for the footer)."""
    marks = [(run.t0, "t₀"), (run.t_c, "t_c")]
    c = first_contact(run)
    if c is not None:
        marks.append((c["t"], "contact"))
    lo, hi = ax.get_xlim()
    for kind in ("catch", "miss", "drop"):
        inside = (e for e in run.events if e["kind"] == kind and lo <= e["t"] <= hi)
        shown, more = line_labels.first(inside)
        marks += [(e["t"], kind) for e in shown]
        drawn.update(("more",) if more else ())
    kept = [(t, name) for t, name in marks if t is not None and lo <= t <= hi]
    for t, _ in kept:
        ax.axvline(t, color="0.55", lw=0.7, ls=style.get("ls", "-"))
    drawn.update(name for _, name in kept)
    return kept


def fig6(opt: CatchRun | None, ini: CatchRun | None, variants: tuple[CatchRun, ...] = ()):
    fig, (ax_t, ax_w) = plt.subplots(2, 1, sharex=True, figsize=(6.0, 5.0))
    pair = ((opt, "tab:blue", "optimisation (eq. 25)"), (ini, "tab:red", "initial parameters"))
    for run, color, label in (
        *((r, c, f"{_titled(r)}: {what}") for r, c, what in pair if r is not None),
        *((r, _color(r), _label(r)) for r in variants),
    ):
        if not run.costs:
            continue
        it = [c["iteration"] for c in run.costs]
        one = len(it) == 1  # (a single iterate: an open square)
        style = dict(marker="s" if one else "o", ms=8 if one else 5)
        for ax, cost in ((ax_t, "torque_cost"), (ax_w, "velocity_cost")):
            ax.plot(
                it,
                [c[cost] for c in run.costs],
                color=color,
                label=label,
                fillstyle="none" if one else "full",
                **style,
            )
    ax_t.set_ylabel("Σ τᵀ K_τ τ (dynamics)")
    ax_w.set_ylabel("Σ ωᵀ K_ω ω (kinematics)")
    ax_w.set_xlabel("optimisation iteration")
    ref = opt or ini
    if ref is not None:
        tau, w = opt_limits(ref)
        fig.text(
            0.01,
            0.005,
            "K_τ = diag(1/τ_max²), τ_max = ("
            + ", ".join(f"{x:g}" for x in tau)
            + ") N·m;\nK_ω = diag(1/ω_max²), ω_max = ("
            + ", ".join(f"{x:g}" for x in w)
            + ") rad/s;  joints 1, 2, 4",
            fontsize=7,
            color="0.35",
            va="bottom",
        )
    for ax in (ax_t, ax_w):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    ax_t.set_title("Optimisation of the cost functions (cf. Fig. 6)", fontsize=10)
    fig.tight_layout(rect=(0, 0.05, 1, 1))  # (the footer's two lines below)
    return fig


def _ball_series(run: CatchRun, t0: float, t1: float):
    w = run.window(run.t_obj, t0, t1)
    return run.t_obj[w], run.ball[w]


def fig7(runs: list[CatchRun], title: str):
    fig = plt.figure(figsize=(10.0, 7.0))
    gs = fig.add_gridspec(2, 3, height_ratios=(1.0, 1.25))
    axes = [fig.add_subplot(gs[0, i]) for i in range(3)]
    side = fig.add_subplot(gs[1, :])
    span = (min(_span(r)[0] for r in runs), max(_span(r)[1] for r in runs))
    for ax in axes:
        ax.set_xlim(*span)
    named: list[tuple[float, str]] = []  # the first run's marks, named on the x panel
    drawn: set[str] = set()
    for run in runs:
        st = _style(run)
        t0, t1 = _span(run)
        wc = run.window(run.t_ctrl, t0, t1)
        tb, ball = _ball_series(run, t0, t1)
        for i, ax in enumerate(axes):
            ax.plot(tb, ball[:, i], color=C_BALL, **st)
            ax.plot(run.t_ctrl[wc], run.effector_desired[wc, i], color=C_DES, **st)
            ax.plot(run.t_ctrl[wc], run.effector[wc, i], color=C_ACT, **st)
            marks = _marks(ax, run, st, drawn)
            if run is runs[0] and i == 0:
                named = marks
        side.plot(ball[:, 0], ball[:, 2], color=C_BALL, **st)
        side.plot(run.effector_desired[wc, 0], run.effector_desired[wc, 2], color=C_DES, **st)
        side.plot(run.effector[wc, 0], run.effector[wc, 2], color=C_ACT, **st)
        if run.t_c is not None:
            k = run.ctrl_index(run.t_c)
            side.plot(*run.effector_desired[k, [0, 2]], "o", color=C_DES, ms=6, fillstyle="none")
        c = first_contact(run)
        if c is not None:
            side.plot(*run.ball_at(c["t"])[0][[0, 2]], "x", color=C_BALL, ms=7)
    for ax, name in zip(axes, "xyz"):
        ax.set_ylabel(f"{name} [m]")
        ax.set_xlabel("time [s]")
        ax.grid(alpha=0.3)
    side.set_xlabel("x [m]")
    side.set_ylabel("z [m]")
    side.set_aspect("equal", adjustable="datalim")
    side.grid(alpha=0.3)
    side.set_title("side view (x-z): ○ l(q_d) at t_c, × ball at the first contact", fontsize=9)
    # colour says what a curve is, line style which run: two legends, so that no entry
    # stands for a curve of its own
    colours = side.legend(
        handles=[
            plt.Line2D([], [], color=C_BALL, label="ball r_o (truth)"),
            plt.Line2D([], [], color=C_DES, label="desired l(q_d)"),
            plt.Line2D([], [], color=C_ACT, label="actual l(q)"),
        ],
        fontsize=7,
        loc="upper left",
        title="colour",
        title_fontsize=7,
    )
    side.add_artist(colours)
    side.legend(
        handles=[plt.Line2D([], [], color="0.2", label=_label(r), **_style(r)) for r in runs],
        fontsize=7,
        loc="lower right",
        title="line style (every curve and mark of a run)",
        title_fontsize=7,
    )
    fig.suptitle(title, fontsize=10)
    fig.text(
        0.01,
        0.005,
        "l(q): the catch point (ball centre on the palm); " + _lines_said(drawn),
        fontsize=7,
        color="0.35",
        va="bottom",
    )
    fig.tight_layout(rect=(0, 0.02, 1, 0.97))
    line_labels.place(axes[0], named)
    return fig


MIN_SPAN = 0.1  # rad: the least range of a joint-angle panel (a planar throw leaves q1 ~1e-5)


def _min_span(ax, name: str) -> None:
    """Widen ``ax``'s angle range to :data:`MIN_SPAN` about its middle; a joint that stays
    within a thousandth of that is said to be still (q1 in a planar throw)."""
    lo, hi = ax.get_ylim()
    if hi - lo >= MIN_SPAN:
        return
    mid = (lo + hi) / 2.0
    ax.set_ylim(mid - MIN_SPAN / 2.0, mid + MIN_SPAN / 2.0)
    lo, hi = ax.dataLim.intervaly  # (the curves' own range, without the margins)
    if hi - lo < MIN_SPAN / 100:
        ax.text(
            0.01,
            0.05,
            f"{name} ≈ {round(mid, 3) + 0.0:.3f} rad throughout (range {hi - lo:.0e} rad: "
            "a planar throw)",
            transform=ax.transAxes,
            fontsize=7,
            color="0.35",
        )


def _joint_figure(runs: list[CatchRun], title: str, what: str):
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(6.6, 6.4))
    named: list[tuple[float, str]] = []  # the first run's marks, named on the top panel
    drawn: set[str] = set()
    axes[0].set_xlim(min(_to_contact(r)[0] for r in runs), max(_to_contact(r)[1] for r in runs))
    for run in runs:
        st = _style(run)
        t0, t1 = _to_contact(run)
        wa = run.window(run.t_arm, t0, t1)
        wc = run.window(run.t_ctrl, t0, t1)
        for ax, j, name in zip(axes, ACTIVE, JOINTS):
            if what == "angles":
                ax.plot(
                    run.t_arm[wa],
                    run.q[wa, j],
                    color=_color(run),
                    label=f"q, {_label(run)}",
                    **st,
                )
                ax.plot(
                    run.t_ctrl[wc],
                    run.q_desired[wc, j],
                    color="0.35",
                    lw=0.8,
                    ls=st["ls"],
                    label=f"q_d, {run.name}",
                )
                ax.set_ylabel(f"q{name[1]} [rad]")
            else:
                ax.plot(
                    run.t_ctrl[wc],
                    run.torque[wc, j],
                    color=_color(run),
                    label=_label(run),
                    **st,
                )
                ax.set_ylabel(f"τ{name[1]} [N·m]")
            marks = _marks(ax, run, st, drawn)
            if run is runs[0] and j == 0:
                named = marks
    if what == "torques":
        tau, _ = opt_limits(runs[0])
        for ax, lim in zip(axes, tau):
            for s in (-1, 1):
                ax.axhline(s * lim, color="0.6", lw=0.8, ls=":")
    else:
        for ax, name in zip(axes, JOINTS):
            _min_span(ax, f"q{name[1]}")
    for ax in axes:
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel("time [s]")
    axes[0].set_title(title, fontsize=10)
    note = (
        "axis 3 locked at 0; thin grey: q_d = g∘l_c⁻¹(r_o)"
        if what == "angles"
        else "command torque τ = τ_ff(q_d) + PD, clipped at the limits (dotted)"
    )
    fig.text(
        0.01,
        0.005,
        note + ";\nfrom t₀ to the first contact; " + _lines_said(drawn),
        fontsize=7,
        color="0.35",
        va="bottom",
    )
    fig.tight_layout(rect=(0, 0.04, 1, 1))  # (the footer's two lines below)
    line_labels.place(axes[0], named)
    axes[0].legend(fontsize=7, loc="best")  # (after the labels: "best" keeps clear of them)
    return fig


def _pair_figures(
    pair: list[CatchRun], logs: dict[str, LogReader], out: Path, prefix: str, note: str = ""
) -> list[Path]:
    """Figs. 6-9 of ``pair`` (optimised, initial) and its variants, each figure over the runs
    whose logs hold what it reads (the others named in a note)."""
    opt = next((r for r in pair if r.mapping == "optimised" and r.name not in _VARIANT), None)
    ini = next((r for r in pair if r is not opt and r.name not in _VARIANT), None)
    what = " vs ".join(_titled(r) for r in pair if r.name not in _VARIANT) + note
    if any(r.name in _VARIANT for r in pair):
        what += f" and {sum(r.name in _VARIANT for r in pair)} variant(s)"

    def fit(fig: str) -> list[CatchRun]:
        return [r for r in pair if has({r.name: logs[r.name]}, TOPICS[fig], f"{prefix} {fig}")]

    paths: list[Path] = []
    six = fit("Fig. 6")
    if six:
        variants = tuple(r for r in six if r not in (opt, ini))
        shown = [r.name for r in six]
        o, i = (opt if opt in six else None), (ini if ini in six else None)
        paths += save(fig6(o, i, variants), out, f"{prefix}_fig6", shown)
    for fig, make in (
        ("Fig. 7", lambda rs: fig7(rs, f"Catching trajectory: {what} (cf. Fig. 7)")),
        ("Fig. 8", lambda rs: _joint_figure(rs, f"Joint angles: {what} (cf. Fig. 8)", "angles")),
        (
            "Fig. 9",
            lambda rs: _joint_figure(rs, f"Command torques: {what} (cf. Fig. 9)", "torques"),
        ),
    ):
        drawn = fit(fig)
        if drawn:
            stem = f"{prefix}_fig{fig[-1]}"
            paths += save(make(drawn), out, stem, [r.name for r in drawn])
    return paths


def _variants(
    pair: list[CatchRun], rest: dict[str, CatchRun], logs: dict[str, LogReader]
) -> list[CatchRun]:
    """The runs of ``rest`` (not the pair) of the same experiments as the pair's runs."""
    experiments = {run_labels.describe(logs[r.name], r.name).experiment for r in pair}
    experiments.discard("")
    return [
        r
        for n, r in rest.items()
        if r not in pair and run_labels.describe(logs[n], n).experiment in experiments
    ]


SLOW_PAIR = ("catch_5ms_optimised", "catch_5ms_initial")  # 4.5 m/s, outside the paper's speeds


def make_figures(logs: dict[str, LogReader], out: Path) -> list[Path]:
    """Figs. 6-9 for the optimised / unoptimised pair with every run of the same experiments
    overlaid (a variant: the same scenario with a setting changed, up to MAX_VARIANTS), again
    for the 4.5 m/s pair (``catch_5ms_fig*``, outside the paper's 8-10 m/s), and Fig. 7 for
    every other run."""
    try:
        return _make_figures(logs, Path(out))
    finally:  # (fig6 ... fig9 called alone afterwards draw their runs plainly)
        _VARIANT.clear()
        _LABEL.clear()


def _make_figures(logs: dict[str, LogReader], out: Path) -> list[Path]:
    runs = {name: load_run(log, name) for name, log in sorted(logs.items())}
    if not runs:
        return []
    _LABEL.update({n: run_labels.describe(log, n).label for n, log in logs.items()})
    slow = [runs[n] for n in SLOW_PAIR if n in runs]
    rest = {n: r for n, r in runs.items() if n not in SLOW_PAIR}
    opt, ini = optimised_and_initial(rest) if rest else (None, None)
    pair = [r for r in (opt, ini) if r is not None]
    groups = [(pair, "catch", ""), (slow, "catch_5ms", " (4.5 m/s, not the paper's)")]
    paths: list[Path] = []
    alone = dict(rest)
    for group, prefix, note in groups:
        if not group:
            continue
        for r in group:
            alone.pop(r.name, None)
        more = _variants(group, alone, logs)
        for k, r in enumerate(more):
            if k < MAX_VARIANTS:
                _VARIANT[r.name] = k
                alone.pop(r.name)
            else:
                skip(
                    f"{r.name}: not overlaid on {prefix} Figs. 6-9 (at most {MAX_VARIANTS} "
                    "variants of a pair): drawn in a Fig. 7 of its own"
                )
        paths += _pair_figures(group + more[:MAX_VARIANTS], logs, out, prefix, note)
    for name, run in alone.items():
        _VARIANT[name] = -1
        if has({name: logs[name]}, TOPICS["Fig. 7"], "catch Fig. 7"):
            paths += save(
                fig7([run], f"Catching trajectory: {_label(run)} (cf. Fig. 7)"),
                out,
                f"{name}_fig7",
                [name],
            )
    return paths
