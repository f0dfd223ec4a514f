"""The papers' figures read well: every text inside the figure, the names of marker lines
(t₀, t_c, contact, collision #n) never on one another nor on a legend and inside their axes,
a joint that does not move shown on a sensible scale, a legend entry for every kind of curve
drawn, and a footer that explains only what is drawn. Measured on the drawn figures (text
extents after a draw), not on pixels."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import pytest
from matplotlib.text import Annotation, Text

from analysis.catching import figures as catch_figures
from analysis.grasping import figures as grasp_figures
from analysis.stick import figures as stick_figures
from analysis.catching.run import load_run
from analysis.grasping.run import load_run as load_grasp
from replay.log import LogReader
from replay.runner import Runner
from replay.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[2]
SCENARIOS = ROOT / "scenarios"


@pytest.fixture(scope="module")
def logs(tmp_path_factory) -> dict[str, LogReader]:
    out = tmp_path_factory.mktemp("layout")
    readers = {}
    for name in ("catch_optimised", "catch_initial", "stick_3step", "stick_2step"):
        Runner(load_scenario(SCENARIOS / f"{name}.yaml")).run(out / f"{name}.mcap")
        readers[name] = LogReader(out / f"{name}.mcap")
    return readers


def _renderer(fig):
    fig.set_dpi(150)  # as figure_files.save writes the PNG (text metrics differ with the dpi)
    fig.canvas.draw()
    return fig.canvas.get_renderer()


def _texts(fig) -> list[Text]:
    """The figure's own texts: footers, titles, axis labels, annotations and legends (tick
    labels are matplotlib's, kept to the ticks in view)."""
    out = list(fig.texts)
    if fig._suptitle is not None:
        out.append(fig._suptitle)
    for ax in fig.axes:
        out += [ax.title, ax.xaxis.label, ax.yaxis.label, *ax.texts]
        for leg in (c for c in ax.get_children() if c.__class__.__name__ == "Legend"):
            out += [*leg.get_texts(), leg.get_title()]
    return [t for t in out if t.get_visible() and t.get_text().strip()]


def assert_readable(fig) -> list[Annotation]:
    """Every text inside the figure; the line labels (annotations) inside their axes and
    apart from each other and from the legends. Returns the line labels."""
    r = _renderer(fig)
    page = fig.bbox
    for t in _texts(fig):
        box = t.get_window_extent(r)
        assert (
            box.x0 >= page.x0 - 1
            and box.x1 <= page.x1 + 1
            and box.y0 >= page.y0 - 1
            and box.y1 <= page.y1 + 1
        ), f"{t.get_text()!r} leaves the figure: {box} of {page}"
    labels = []
    for ax in fig.axes:
        inside = ax.get_window_extent(r)
        anns = [t for t in ax.texts if isinstance(t, Annotation) and t.get_visible()]
        legends = [c for c in ax.get_children() if c.__class__.__name__ == "Legend"]
        boxes = [a.get_window_extent(r) for a in anns]
        for a, b in zip(anns, boxes):
            assert inside.x0 - 1 <= b.x0 and b.x1 <= inside.x1 + 1, f"{a.get_text()!r} outside"
            assert inside.y0 - 1 <= b.y0 and b.y1 <= inside.y1 + 1, f"{a.get_text()!r} outside"
            for leg in legends:
                assert not b.overlaps(leg.get_window_extent(r)), f"{a.get_text()!r} on a legend"
        for i in range(len(boxes)):
            for j in range(i + 1, len(boxes)):
                assert not boxes[i].overlaps(boxes[j]), (
                    f"{anns[i].get_text()!r} overlaps {anns[j].get_text()!r}"
                )
        labels += anns
    return labels


@pytest.fixture
def pair(logs):
    return [load_run(logs[n], n) for n in ("catch_optimised", "catch_initial")]


def test_fig6_footer_is_inside_the_figure(pair):
    fig = catch_figures.fig6(*pair)
    try:
        assert_readable(fig)
        assert any("ω_max" in t.get_text() for t in fig.texts)
        for ax in fig.axes:  # each run named, as in Figs. 7-9
            said = [t.get_text() for t in ax.get_legend().get_texts()]
            assert said == [
                "catch_optimised: optimisation (eq. 25)",
                "catch_initial: initial parameters",
            ]
    finally:
        plt.close(fig)


def test_fig7_labels_apart_and_every_legend_entry_matches_a_curve(pair):
    fig = catch_figures.fig7(pair, "Catching trajectory (cf. Fig. 7)")
    try:
        names = {a.get_text() for a in assert_readable(fig)}
        assert {"t₀", "t_c", "contact"} <= names
        side = fig.axes[3]
        lines = [ln for ln in side.get_lines() if len(ln.get_xdata())]
        legends = [c for c in side.get_children() if c.__class__.__name__ == "Legend"]
        assert len(legends) == 2
        colours = next(g for g in legends if g.get_title().get_text() == "colour")
        styles = next(g for g in legends if g is not colours)
        drawn_colours = {ln.get_color() for ln in lines}
        drawn_styles = {ln.get_linestyle() for ln in lines}
        for h in colours.legend_handles:
            assert h.get_color() in drawn_colours, h.get_label()
        for h in styles.legend_handles:
            assert h.get_linestyle() in drawn_styles, h.get_label()
        footer = fig.texts[-1].get_text()
        assert "t₀" in footer and "first contact" in footer
    finally:
        plt.close(fig)


@pytest.mark.parametrize("what", ["angles", "torques"])
def test_fig8_9_labels_inside_and_q1_on_a_sensible_scale(pair, what):
    fig = catch_figures._joint_figure(pair, f"Joints ({what})", what)
    try:
        names = {a.get_text() for a in assert_readable(fig)}
        assert "contact" in names  # at the right edge: turned to the line's left
        lo, hi = fig.axes[0].get_ylim()
        if what == "angles":
            assert hi - lo >= catch_figures.MIN_SPAN - 1e-12
            assert any("planar throw" in t.get_text() for t in fig.axes[0].texts)
            assert fig.axes[1].get_ylim()[1] - fig.axes[1].get_ylim()[0] < 1.0  # q2: its own
        footer = fig.texts[-1].get_text()
        assert "t_c" not in footer.split("vertical lines:")[1]  # (the window ends at contact)
    finally:
        plt.close(fig)


def test_min_span_leaves_a_moving_joint_alone():
    fig, ax = plt.subplots()
    try:
        ax.plot([0, 1], [0.2, 0.9])
        before = ax.get_ylim()
        catch_figures._min_span(ax, "q2")
        assert ax.get_ylim() == before and not ax.texts
    finally:
        plt.close(fig)


@pytest.mark.parametrize("name", ["stick_3step", "stick_2step"])
def test_stick_fig7_collision_labels_apart(logs, name):
    fig = stick_figures.fig7(logs[name], name)
    try:
        labels = assert_readable(fig)
        n = sum(e["kind"] == "collision" for e in logs[name].events())
        assert sorted(a.get_text() for a in labels) == [f"#{i}" for i in range(1, n + 1)]
    finally:
        plt.close(fig)


def test_grasp_fig9_footer_explains_only_what_is_drawn():
    run = load_grasp(LogReader(ROOT / "data" / "golden" / "grasp_hexahedron.mcap"))
    fig = grasp_figures.fig9(run)
    try:
        assert_readable(fig)
        footer = fig.texts[-1].get_text()
        assert "no slip event" in footer and "red ticks" not in footer
        assert ("red: releasing" in footer) == any(p.name == "release" for p in run.phases)
    finally:
        plt.close(fig)
    run.events = [*run.events, {"t": 1.2, "kind": "slip", "data": {}}]
    fig = grasp_figures.fig9(run)
    try:
        assert "red ticks at the bottom: slip events" in fig.texts[-1].get_text()
        ticks = [ln for ln in fig.axes[0].get_lines() if ln.get_marker() == "|"]
        assert ticks and list(ticks[0].get_xdata()) == [1.2]
    finally:
        plt.close(fig)


# -- the ablation plots: rates as k/n with Wilson 95 % intervals -------------------------------

ABLATIONS = [
    ("analysis.catching.ablations", "plot_rate", "catch_rate"),
    ("analysis.catching.ablations", "plot_throw_speed", "catch_throw_speed"),
    ("analysis.catching.ablations", "plot_arm_limits", "catch_arm_limits"),
    ("analysis.stick.ablations", "plot_vision", "stick_vision"),
    ("analysis.grasping.ablations", "plot_loops", "grasp_loops"),
]


@pytest.mark.parametrize("module, func, table", ABLATIONS)
def test_ablation_rates_have_n_and_wilson_error_bars(module, func, table, monkeypatch, tmp_path):
    import importlib

    from matplotlib.container import ErrorbarContainer

    from analysis.catching.ablations import wilson
    from replay.sweep.table import read_table

    mod = importlib.import_module(module)
    drawn = []
    monkeypatch.setattr(mod, "save", lambda fig, out, stem: drawn.append(fig) or [])
    rows = read_table(ROOT / "data" / "ablations" / f"{table}.csv")
    getattr(mod, func)(rows, tmp_path, table)
    (fig,) = drawn
    try:
        assert_readable(fig)
        ax = fig.axes[0]
        bars = [c for c in ax.containers if isinstance(c, ErrorbarContainer)]
        assert bars, "no error bars"
        n_rows = 0
        for c in bars:
            assert "n = " in c.get_label(), c.get_label()
            line, _, (segments,) = c.lines[0], c.lines[1], c.lines[2]
            ys = line.get_ydata()
            n = int(c.get_label().split("n = ")[1].split("-")[0].rstrip(")"))
            for y, seg in zip(ys, segments.get_segments()):
                if "-" in c.get_label().split("n = ")[1]:
                    break  # (n differs between points: checked by the count below)
                lo, hi = wilson(round(y * n), n)
                assert seg[:, 1].min() == pytest.approx(lo) and seg[:, 1].max() == pytest.approx(hi)
            n_rows += len(ys)
        assert n_rows >= 2
        for a in fig.axes:  # (mathtext is off: no '$\\mathdefault{10^{2}}$' tick labels)
            fig.canvas.draw()
            assert not any("$" in t.get_text() for t in a.get_xticklabels())
    finally:
        plt.close(fig)


PLOTTED = sorted(
    p.stem for p in (ROOT / "sweeps").glob("*.yaml") if "\nplot: " in p.read_text(encoding="utf-8")
)


@pytest.mark.parametrize("sweep", PLOTTED)
def test_every_ablation_plot_keeps_its_text_inside(sweep, monkeypatch, tmp_path):
    """Each sweep's plot from its stored table: no title, label or legend runs off the figure
    (grasp_components' title over axes pushed right by long part names did)."""
    import importlib

    import yaml

    from replay.sweep.table import read_table

    spec = yaml.safe_load((ROOT / "sweeps" / f"{sweep}.yaml").read_text(encoding="utf-8"))
    module, func = spec["plot"].split(":")
    mod = importlib.import_module(module)
    drawn = []
    monkeypatch.setattr(mod, "save", lambda fig, out, stem: drawn.append(fig) or [])
    getattr(mod, func)(read_table(ROOT / "data" / "ablations" / f"{sweep}.csv"), tmp_path, sweep)
    assert drawn
    for fig in drawn:
        try:
            assert_readable(fig)
        finally:
            plt.close(fig)
