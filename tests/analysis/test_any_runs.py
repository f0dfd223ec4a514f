"""Analysis over any set of logs (issue #37): two logs of one scenario name are two runs, each
labelled by what differs from its shipped scenario; variants are overlaid on the paper's pair;
a log lacking a topic a figure or claims row reads skips it with a note, never a crash."""

from __future__ import annotations

from pathlib import Path

import pytest

from analysis import runs
from analysis.figure_files import FigureFile
from replay.log import LogReader, LogWriter
from replay.messages import TOPIC_EFFECTOR_STATE, TOPIC_SCENARIO, TOPIC_STICK_STATE

from cli_checks import invoke


def run(out: Path, scenario: str, *sets: str) -> Path:
    args = ["run", scenario, "-q", "-o", out]
    for s in sets:
        args += ["--set", s]
    r = invoke(*args)
    assert r.exit_code == 0, r.output
    return out


def forge(base: Path, out: Path, drop: str, name: str) -> Path:
    """A copy of ``base`` without the topic ``drop``, its scenario named ``name``."""
    with LogWriter(out) as w:
        for m in LogReader(base).messages():
            if m.topic == drop:
                continue
            data = dict(m.data, name=name) if m.topic == TOPIC_SCENARIO else m.data
            w.write(m.topic, data, m.t_ns)
    return out


@pytest.fixture(scope="module")
def catch(tmp_path_factory) -> dict[str, Path]:
    d = tmp_path_factory.mktemp("catch")
    logs = {
        "opt": run(d / "opt.mcap", "catch_optimised"),
        "ini": run(d / "ini.mcap", "catch_initial"),
        "lat": run(d / "lat.mcap", "catch_optimised", "sensors.stereo.latency=0.01"),
        "renamed": run(
            d / "lat10.mcap", "catch_optimised", "name=catch_lat10", "sensors.stereo.latency=0.01"
        ),
    }
    logs["mine"] = forge(logs["opt"], d / "mine.mcap", TOPIC_EFFECTOR_STATE, "catch_mine")
    return logs


@pytest.fixture(scope="module")
def stick(tmp_path_factory) -> dict[str, Path]:
    d = tmp_path_factory.mktemp("stick")
    short = "timing.duration=0.3"
    logs = {
        "mu03": run(d / "a.mcap", "stick_3step", short),
        "mu1": run(d / "b.mcap", "stick_3step", short, "plant.params.stick.friction=1.0"),
    }
    logs["bare"] = forge(logs["mu03"], d / "bare.mcap", TOPIC_STICK_STATE, "stick_bare")
    return logs


def test_two_logs_of_one_name_are_two_labelled_runs(stick):
    keyed = runs.keyed([LogReader(stick["mu03"]), LogReader(stick["mu1"])])
    keys = list(keyed)
    assert keys[0] == "stick_3step" and keys[1].startswith("stick_3step (")
    labels = [runs.describe(r).label for r in keyed.values()]
    assert "friction 1" in labels[1] and "friction" not in labels[0]
    assert "duration 300 ms" in labels[0]  # what differs from the shipped stick_3step


def test_stick_runs_of_one_name_each_get_a_figure_and_the_overlay(stick, tmp_path):
    r = invoke("figures", stick["mu03"], stick["mu1"], "-o", tmp_path)
    assert r.exit_code == 0, r.output
    pngs = sorted(p.name for p in tmp_path.glob("*.png"))
    assert len([p for p in pngs if "_fig7" in p]) == 2, pngs
    assert "stick_3step_friction.png" in pngs
    assert "stick_3step_variants.png" in pngs  # Fig. 7's velocities, each run labelled
    svg = (tmp_path / "stick_3step_variants.svg").read_text()
    assert "friction 1" in svg and "duration 300 ms" in svg
    assert "stick_3step (duration 300 ms)" in svg  # as every run is named: name (label)
    assert "warning" not in r.stderr, r.stderr


def test_catch_variants_are_overlaid_on_the_pair_and_labelled(catch, tmp_path):
    from analysis.catching.figures import make_figures

    logs = runs.keyed(LogReader(catch[k]) for k in ("opt", "ini", "lat", "renamed"))
    paths = make_figures(logs, tmp_path)
    fig7 = next(p for p in paths if p.name == "catch_fig7.png")
    assert isinstance(fig7, FigureFile)
    assert set(fig7.runs) == set(logs) and len(logs) == 4  # every run in the pair's figure
    for k in (6, 8, 9):
        assert any(p.name == f"catch_fig{k}.png" and len(p.runs) >= 2 for p in paths)
    assert runs.describe(logs["catch_lat10"]).label == "stereo latency 10 ms"
    assert runs.describe(logs["catch_lat10"]).experiment == "catch_optimised"
    svg = fig7.with_suffix(".svg").read_text()
    assert "stereo latency 10 ms" in svg  # the legend says what differs


def test_a_lone_variant_is_named_by_what_it_changes(catch, tmp_path):
    """Without the shipped run among the logs a variant keeps the plain key (the paper's rows
    find it), but its figures say what it changes: titles and legends, catch and grasp."""
    from analysis.catching.figures import make_figures

    paths = make_figures(runs.keyed([LogReader(catch["lat"])]), tmp_path)
    assert {p.name for p in paths} >= {f"catch_fig{k}.svg" for k in (6, 7, 8, 9)}
    for k in (6, 7, 8, 9):
        svg = (tmp_path / f"catch_fig{k}.svg").read_text()
        assert "catch_optimised (stereo latency 10 ms)" in svg, k
    g = run(
        tmp_path / "g.mcap", "grasp_sphere", "timing.duration=0.1", "plant.params.human_speed=0.3"
    )
    r = invoke("figures", g, "-o", tmp_path / "g")
    assert r.exit_code == 0, r.output
    for svg in (tmp_path / "g").glob("*.svg"):
        assert "grasp_sphere (human speed 0.3, duration 100 ms)" in svg.read_text(), svg.name


def test_the_claims_say_when_the_papers_run_is_a_variant(catch, tmp_path):
    """A variant alone takes its scenario's plain name, so the paper's rows read it as the
    paper's run: the claims say so (stderr and the Markdown table); beside the shipped run
    the variant has a key of its own and nothing is said."""
    md = tmp_path / "claims.md"
    r = invoke("claims", catch["lat"], "--markdown", md)
    assert r.exit_code == 0, r.output
    said = [line for line in r.stderr.splitlines() if "stereo latency 10 ms" in line]
    assert len(said) == 1 and said[0].startswith("warning: catch_optimised"), r.stderr
    assert "not the shipped scenario" in said[0]
    assert "not the shipped scenario" in md.read_text()
    both = invoke("claims", catch["opt"], catch["lat"], catch["renamed"])  # catch_lat10: named
    assert both.exit_code == 0 and "not the shipped scenario" not in both.stderr, both.stderr


def test_a_catch_cut_before_the_ball_arrives_decides_no_arrival_row(tmp_path):
    """A run that ends before the ball reaches the hand (a short duration, a truncated log, a
    throw that misses) has no arrival speed: the rows that compare the paper's numbers with it
    say so, and the acceleration row is no verdict ("consistent" read a NaN before)."""
    from analysis.catching.claims import evaluate

    log = run(tmp_path / "short.mcap", "catch_optimised", "timing.duration=0.15")
    rows = {r.quantity: r for r in evaluate({"catch_optimised": LogReader(log)})}
    acc = rows["end-effector maximum acceleration"]
    assert acc.status == "not run" and "nan" not in acc.measured, acc
    assert "did not reach the hand" in acc.measured
    speed = rows["hand speed eq. 4 demands at t_c vs the arm's 5 m/s"]
    assert "nan" not in speed.measured and "did not reach the hand" in speed.measured, speed
    early = run(tmp_path / "early.mcap", "catch_optimised", "timing.duration=0.05")
    rows = {r.quantity: r for r in evaluate({"catch_optimised": LogReader(early)})}
    throws = rows["catch over the stated throws, 8 ~ 10 m/s"]  # (ended before t0: never seen)
    assert "nan" not in throws.measured and "never seen" in throws.measured, throws


def test_a_stick_throw_the_plan_never_reached_names_no_nan(tmp_path):
    """With no spin (ω_0 = 0) the 3-step finds no reachable contact, its collisions come by
    chance and no plan of the second is logged: the r_x,2 row says so (it read "nan mm")."""
    from analysis.stick.claims import evaluate

    log = run(tmp_path / "w0.mcap", "stick_3step", "plant.params.initial.omega=0")
    rows = {r.quantity: r for r in evaluate({"stick_3step": LogReader(log)})}
    row = rows["fingertip position r_x,2"]
    assert "nan" not in row.note and "no plan of collision 2" in row.note, row


def test_a_log_lacking_a_topic_skips_what_reads_it(catch, stick, tmp_path):
    """A controller that publishes no /effector/state: Figs. 7-9 and the claims rows that read
    it are left out for that run with a note naming the topic; the rest is made."""
    r = invoke("figures", catch["opt"], catch["ini"], catch["mine"], "-o", tmp_path / "f")
    assert r.exit_code == 0, r.output
    assert "Traceback" not in r.output
    notes = [line for line in r.stderr.splitlines() if "catch_mine" in line]
    assert notes and all("/effector/state" in n for n in notes), r.stderr
    assert (tmp_path / "f" / "catch_fig8.png").is_file()
    r = invoke("claims", catch["opt"], catch["mine"], "--markdown", tmp_path / "c.md")
    assert r.exit_code == 0, r.output
    table = (tmp_path / "c.md").read_text(encoding="utf-8")
    assert "> catch\\_mine: claims" in table or "> catch_mine: claims" in table
    assert "catch_mine" in r.stderr and "/effector/state" in r.stderr
    assert "catch_mine: ball caught" not in r.stdout
    assert "| catch over the stated throws, 8 ~ 10 m/s |" in r.stdout
    # a log in no figure at all is said once, with why
    r = invoke("figures", stick["bare"], "-o", tmp_path / "g")
    assert r.exit_code == 0, r.output
    lines = [line for line in r.stderr.splitlines() if line.startswith("warning: ")]
    assert len(lines) == 1 and "stick_bare: in no figure" in lines[0], r.stderr
    assert TOPIC_STICK_STATE in lines[0]
    r = invoke("claims", stick["bare"])
    assert r.exit_code == 0 and TOPIC_STICK_STATE in r.stderr, r.output


def _doc_rows(doc: str) -> dict[str, str]:
    text = (Path(__file__).resolve().parents[2] / "docs" / doc).read_text(encoding="utf-8")
    rows = [line.split("|")[1:3] for line in text.splitlines() if line.startswith("| ")]
    return {a.strip(): b for a, b in rows}


@pytest.mark.parametrize(
    "doc, module",
    [
        ("catching.md", "catching.figures"),
        ("catching.md", "catching.claims"),
        ("grasping.md", "grasping.figures"),
        ("grasping.md", "grasping.claims"),
        ("stick.md", "stick.figures"),
        ("stick.md", "stick.claims"),
    ],
)
def test_the_docs_list_what_each_figure_and_row_reads(doc, module):
    """The contract a controller fulfils: each paper's doc names every topic each figure and
    claims row reads (the modules' TOPICS)."""
    import importlib

    topics = importlib.import_module(f"analysis.{module}").TOPICS
    groups = topics if isinstance(topics, dict) else {"every claims row": topics}
    rows = _doc_rows(doc)
    for group, needed in groups.items():
        row = next((v for k, v in rows.items() if k.startswith(group)), None)
        assert row is not None, (doc, group)
        for topic in needed:
            assert f"`{topic}`" in row, (doc, group, topic)


def test_variants_beyond_the_cap_get_a_figure_of_their_own_and_a_note(catch, tmp_path, monkeypatch):
    from analysis.catching import figures as catch_figures
    from analysis.needs import skipped_notes

    monkeypatch.setattr(catch_figures, "MAX_VARIANTS", 1)
    logs = runs.keyed(LogReader(catch[k]) for k in ("opt", "ini", "lat", "renamed"))
    with skipped_notes() as notes:
        paths = catch_figures.make_figures(logs, tmp_path)
    fig7 = next(p for p in paths if p.name == "catch_fig7.png")
    assert len(fig7.runs) == 3
    (left,) = set(logs) - set(fig7.runs)
    assert any(n.startswith(f"{left}: not overlaid") and "at most 1" in n for n in notes), notes
    assert any(p.runs == (left,) and p.suffix == ".png" for p in paths)  # its own Fig. 7


READ = (
    "/effector/state",
    "/arm/joint_command",
    "/arm/joint_state",
    "/object/state",
    "/effector/motion",
    "/hand/joint_state",
    "/catching/state",
    "/optimization/cost",
    "/vision/object",
    "/events",
)


@pytest.mark.parametrize("topic", READ)
def test_catch_figures_and_claims_survive_any_topic_missing(catch, tmp_path, topic):
    """Each topic the catch analysis reads, dropped from the optimised run: figures and claims
    are made from the rest; a topic a figure or row needs is named in a note."""
    from analysis.catching.claims import TOPICS as ROWS
    from analysis.catching.claims import evaluate
    from analysis.catching.figures import TOPICS as FIGS
    from analysis.catching.figures import make_figures
    from analysis.needs import skipped_notes

    log = LogReader(forge(catch["opt"], tmp_path / "a.mcap", topic, "catch_optimised"))
    logs = {"catch_optimised": log, "catch_initial": LogReader(catch["ini"])}
    with skipped_notes() as notes:
        make_figures(logs, tmp_path / "figs")
        rows = evaluate(logs)
    assert rows
    needed = any(topic in t for t in (*FIGS.values(), *ROWS.values()))
    assert needed == any(topic in n for n in notes), notes


def test_a_logs_name_never_makes_a_path_and_a_label_stays_one_bounded_line(stick, tmp_path):
    assert runs._shipped("../scenarios/stick_3step") is None
    assert runs._shipped("stick_3step") is not None
    hostile = "\x1b]0;PWNED\x07" + "x" * 500
    log = LogReader(forge(stick["mu03"], tmp_path / "h.mcap", "/nothing", "stick_h"))
    stored = runs._flat(log.scenario_config())
    stored["controller.type"] = hostile
    label = runs._label(runs.differences(stored, runs._shipped("stick_3step") or {}))
    assert "\x1b" not in label and "\n" not in label and len(label) <= runs.LABEL_LENGTH
    assert label.startswith("controller \\x1b]0;PWNED")


def test_each_log_gets_its_key_and_label(stick, catch):
    logs = [LogReader(stick["mu03"]), LogReader(stick["mu1"]), LogReader(catch["renamed"])]
    labels = {key: runs.describe(r, key).label for key, r in runs.keyed(logs).items()}
    assert list(labels) == [
        "stick_3step",
        "stick_3step (friction 1, duration 300 ms)",
        "catch_lat10",
    ]
    assert labels["catch_lat10"] == "stereo latency 10 ms"
    assert runs.titled("catch_lat10", logs[2]) == "catch_lat10 (stereo latency 10 ms)"


def test_two_logs_of_one_variant_are_named_apart(stick, tmp_path):
    """Two logs of the same variant (a copy, a truncated one) without the shipped run: the
    first keeps the plain key and is titled with its label, so the second's key must differ
    from that title (compare's warnings name the second by its key)."""
    import shutil

    copy = tmp_path / "copy.mcap"
    shutil.copy(stick["mu1"], copy)
    keyed = runs.keyed([LogReader(stick["mu1"]), LogReader(copy)])
    titles = [runs.titled(k, r) for k, r in keyed.items()]
    assert len(set(titles)) == 2, titles
    assert titles[0] == "stick_3step (friction 1, duration 300 ms)"
    assert titles[1] == "stick_3step (friction 1, duration 300 ms) #2"


def test_a_label_gives_seconds_their_unit():
    """A time in s is written in ms below 1 s and in s from 1 s ("duration 1" said no unit)."""
    ref = {"timing.duration": 2.0, "sensors.chip.latency": 0.001, "stop.after": 0.1}
    assert runs.differences(
        {"timing.duration": 1.0, "sensors.chip.latency": 0.0025, "stop.after": 12}, ref
    ) == ["chip latency 2.5 ms", "after 12 s", "duration 1 s"]


def test_a_renamed_run_with_another_controller_is_a_variant_of_the_papers_own():
    """A user's scenario ``extends: catch_optimised`` with its own controller is as far from
    every catch scenario that differs only in controller params: it is compared with the
    paper's own (fewest ``extends:`` steps), not the first such name in the alphabet."""
    stored = {
        k: v
        for k, v in (runs._shipped("catch_optimised") or {}).items()
        if not k.startswith("controller.params.")
    }
    stored.update({"name": "catch_mine", "controller.type": "my_module:MyController"})
    assert runs._compare(stored, "catch_mine", "namiki2003") == (
        "catch_optimised",
        ["controller my_module:MyController"],
    )
    stick = dict(runs._shipped("stick_3step") or {}, name="stick_mine")
    assert runs._compare(stick, "stick_mine", "higashimori2007") == ("stick_3step", [])
    assert runs._depth("catch_optimised") == 0 and runs._depth("catch_initial") == 1
    assert runs._depth("stick_3step_width10_long") == 2 and runs._depth("no_such") == 0


def test_a_log_is_read_into_a_run_once_per_reader_and_its_arrays_are_read_only(catch):
    from analysis.catching.run import load_run

    reader = LogReader(catch["opt"])
    a = load_run(reader, "catch_optimised")
    assert load_run(reader, "catch_optimised") is a  # (the claims, figures, falsifiers: once)
    assert load_run(reader, "other").name == "other"  # a run per name asked
    assert load_run(log=reader, name="catch_optimised") is a  # (as its signature says)
    fresh = load_run(LogReader(catch["opt"]), "catch_optimised")
    assert fresh is not a and (fresh.q_desired == a.q_desired).all()  # another reader: read again
    with pytest.raises(ValueError, match="read-only"):
        a.q_desired[0, 0] = 1.0  # what is shared is not changed by one of its readers


def test_figures_drawn_alone_after_make_figures_show_no_label_of_those_runs(catch, tmp_path):
    from analysis.catching import figures
    from analysis.catching.run import load_run

    logs = runs.keyed(LogReader(catch[k]) for k in ("lat", "ini"))
    figures.make_figures(logs, tmp_path)  # catch_optimised here is the 10 ms latency variant
    pair = [
        load_run(LogReader(catch[k]), n)
        for k, n in (("opt", "catch_optimised"), ("ini", "catch_initial"))
    ]
    fig = figures.fig6(*pair)
    try:
        said = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
        assert said[0] == "catch_optimised: optimisation (eq. 25)", said
    finally:
        import matplotlib.pyplot as plt

        plt.close(fig)
