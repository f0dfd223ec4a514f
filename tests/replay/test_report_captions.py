"""The report captions each figure with the runs it shows (issue #37): not the first run whose
name begins the file's name (MuJoCo figures were captioned as the PyBullet runs,
``stick_3step_mu0`` as ``stick_3step``). Short runs of default scenarios whose names prefix one
another."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from analysis.figure_files import file_stem
from replay.cli import main
from analysis.report.builder import build_report

SCENARIOS = {
    "stick_3step": (),
    "stick_3step_mu0": (),
    "stick_2step": (),
    "catch_optimised": (),
    "catch_initial": (),
    "catch_optimised_mujoco": (),
    "grasp_sphere": ("timing.duration=1.0",),
}
PAIR = {"catch_optimised", "catch_initial"}


@pytest.fixture(scope="module")
def logs(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("logs")
    for name, sets in SCENARIOS.items():
        args = ["run", name, "-q", "-o", str(out / f"{name}.mcap")]
        for s in sets:
            args += ["--set", s]
        r = CliRunner().invoke(main, args)
        assert r.exit_code == 0, r.output
    return out


def _expected(stem: str) -> set[str]:
    """The runs a figure file of the default scenarios shows, from its file name alone."""
    if re.fullmatch(r"catch_fig\d", stem):
        return PAIR if stem != "catch_fig6" else {"catch_optimised", "catch_initial"}
    if stem.endswith("_friction"):
        return {"stick_3step", "stick_3step_mu0"}
    for name in sorted(SCENARIOS, key=len, reverse=True):
        if re.fullmatch(re.escape(file_stem(name)) + r"_(fig\d|filmstrip)", stem):
            return {name}
    raise AssertionError(f"unexpected figure {stem}")


def test_every_caption_names_the_runs_its_figure_shows(logs, tmp_path):
    index = build_report(tmp_path / "report", logs)
    md = index.with_name("index.md").read_text(encoding="utf-8")
    figures = re.findall(r"!\[([^\]]*)\]\(figures/([^)]+)\.png\)", md)
    stems = {stem for _, stem in figures}
    assert {"catch_fig7", "catch_optimised_mujoco_fig7", "stick_3step_mu0_fig7"} <= stems
    assert {"stick_3step_fig7", "stick_2step_fig7", "grasp_sphere_fig9"} <= stems
    for caption, stem in figures:
        named = set(re.findall(r"'([^']+)'", caption.replace("\\_", "_")))
        assert named == _expected(stem), (stem, caption)
    assert "in no figure" not in md  # every log is in a figure
    for caption, stem in figures:  # a figure of no one figure of the paper says what it shows
        assert not caption.replace("\\_", "_").startswith(stem), caption
    said = {stem: caption for caption, stem in figures}
    assert said["stick_3step_friction"].startswith("Friction independence: the velocities")
    assert said["grasp_sphere_filmstrip"].startswith("The run as a filmstrip of close-ups")
    # the paper's Fig. 7 is drawn for the 3-step strategy: a 2-step run's is a "cf."
    two = next(c for c, stem in figures if stem == "stick_2step_fig7").replace("\\_", "_")
    three = next(c for c, stem in figures if stem == "stick_3step_fig7")
    assert two.startswith("Cf. Fig. 7, which the paper draws for stick_3step"), two
    assert "this figure shows stick_2step" in two, two
    assert three.startswith("Fig. 7 (paper:"), three


def test_a_plugin_returning_bare_paths_is_captioned_by_the_longest_name():
    from analysis.figure_files import runs_of

    readers = dict.fromkeys(["stick_3step", "stick_3step_mu0"])
    assert runs_of(Path("x/stick_3step_mu0_fig7.png"), readers) == ("stick_3step_mu0",)
    assert runs_of(Path("x/stick_3step_fig7.png"), readers) == ("stick_3step",)
    assert runs_of(Path("x/other.png"), readers) == ()


def test_a_variant_is_captioned_with_its_label_and_no_log_is_lost(logs, tmp_path):
    """A second stick_3step log (μ = 1) is its own run, captioned with what differs; a file
    that is not a run log is named in the report, not skipped silently."""
    import shutil

    d = tmp_path / "logs"
    d.mkdir()
    for name in ("stick_3step", "catch_optimised", "catch_initial"):
        shutil.copy(logs / f"{name}.mcap", d / f"{name}.mcap")
    r = CliRunner().invoke(
        main,
        ["run", "stick_3step", "-q", "-o", str(d / "mu1.mcap"), "--set", "timing.duration=0.3"]
        + ["--set", "plant.params.stick.friction=1.0"],
    )
    assert r.exit_code == 0, r.output
    (d / "junk.mcap").write_bytes(b"not a log")
    md = build_report(tmp_path / "report", d).with_name("index.md").read_text(encoding="utf-8")
    captions = re.findall(r"!\[([^\]]*)\]\(figures/([^)]+)\.png\)", md)
    variant = [c for c, stem in captions if "friction 1" in c and "_fig7" in stem]
    assert len(variant) == 1 and "'stick_3step (friction 1, duration 300 ms)'" in variant[0]
    assert "Log left out: junk.mcap" in md


def test_the_commands_run_a_shipped_scenario_and_say_what_differs():
    """A run whose scenario name is not shipped (a user's file ``extends: catch_optimised``) is
    re-run from its nearest shipped scenario, never by a name ``replay run`` cannot find."""
    from types import SimpleNamespace

    from analysis.report.builder import _commands

    sec = SimpleNamespace(
        key="namiki2003",
        runs=[(k, 0, "") for k in ("catch_optimised", "catch_lat", "catch_mine", "catch_x", "z")],
        scenarios={
            "catch_optimised": ("catch_optimised", "", "catch_optimised"),
            "catch_lat": ("catch_optimised", "stereo latency 10 ms", "catch_optimised"),
            "catch_mine": ("catch_mine", "controller my_module:Mine", "catch_optimised"),
            "catch_x": ("catch_x", "", "catch_optimised"),
            "z": ("z", "", ""),
        },
        falsifiers=(),
        ablations=[],
        claims=[],
    )
    runs = [c for c in _commands([sec], []) if c.startswith("replay run")]
    assert runs == [
        "replay run catch_optimised --seed 0 -o out/logs/catch_optimised.mcap",
        "replay run catch_optimised --seed 0 -o out/logs/catch_lat.mcap"
        "   # differs from the shipped catch_optimised: stereo latency 10 ms",
        "replay run catch_optimised --seed 0 -o out/logs/catch_mine.mcap   # catch_mine is not"
        " shipped, its nearest is catch_optimised; it differs from it: controller my_module:Mine",
        "replay run catch_optimised --seed 0 -o out/logs/catch_x.mcap   # catch_x is not"
        " shipped, its nearest is catch_optimised; it sets nothing differently",
        "replay run z --seed 0 -o out/logs/z.mcap   # z is not shipped; its scenario is in its"
        " log (replay info)",
    ]


def test_a_line_break_in_a_name_or_label_never_ends_the_commands_comment():
    """The comment after a command quotes a log's name and values: a line break there would make
    the rest of it a shell command of its own when the block is pasted (in the command itself
    it is quoted, one shell word)."""
    from types import SimpleNamespace

    from analysis.report.builder import _commands

    evil = "catch\nrm -rf ~"
    sec = SimpleNamespace(
        key="namiki2003",
        runs=[("a", 0, ""), ("b", 0, "")],
        scenarios={
            "a": (evil, "", ""),
            "b": ("catch_optimised", "friction 1\ncurl x | sh", "catch_optimised"),
        },
        falsifiers=(),
        ablations=[],
        claims=[],
    )
    import shlex

    for command in _commands([sec], []):
        head, _, comment = command.partition("   # ")
        assert "\n" not in comment, command  # (a quoted line break in the name is one word)
        assert shlex.split(head)[0] == "replay" and len(shlex.split(head)) < 8, command
