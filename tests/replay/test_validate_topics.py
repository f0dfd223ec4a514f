"""``replay validate`` warns when a scenario will not publish what its paper's figures and
claims read (analysis/published.py: a brief trial run against its experiment's)."""

from __future__ import annotations

from pathlib import Path

import pytest

from analysis import published
from replay.resources import scenario_dir
from replay.scenario import load_scenario

from cli_checks import invoke

EXAMPLE = Path(__file__).parents[2] / "examples" / "my_controller.yaml"


def warnings_of(r) -> list[str]:
    return [line for line in r.stderr.splitlines() if line.startswith("warning: ")]


def test_a_controller_from_a_file_that_publishes_less_is_warned_about():
    r = invoke("validate", EXAMPLE)
    assert r.exit_code == 0, r.output
    assert f"ok: {EXAMPLE}" in r.stdout
    (line,) = warnings_of(r)
    assert "/effector/state" in line and "/arm/joint_command" in line
    assert "Fig. 7" in line and "claims rows" in line  # (what reads them)
    assert "/object/state" not in line  # (the plant publishes it)


def test_a_swapped_controller_is_warned_about_only_what_it_lacks():
    r = invoke("validate", "catch_optimised", "--set", "controller.type=feedback")
    assert r.exit_code == 0, r.output
    (line,) = warnings_of(r)
    assert "/optimization/cost" in line and "Fig. 6" in line
    assert "/effector/state" not in line and "Fig. 7" not in line


def test_a_variant_that_publishes_alike_and_static_are_quiet():
    r = invoke("validate", "stick_3step", "--set", "plant.params.stick.friction=1.0")
    assert r.exit_code == 0 and not warnings_of(r), r.output
    r = invoke("validate", "--static", EXAMPLE)
    assert r.exit_code == 0 and not warnings_of(r), r.output


@pytest.mark.parametrize("path", sorted(scenario_dir().glob("*.yaml")), ids=lambda p: p.stem)
def test_a_shipped_scenario_is_its_own_experiment(path, monkeypatch):
    def no_trial(sc):
        raise AssertionError("a shipped scenario needs no trial run")

    monkeypatch.setattr(published, "trial_topics", no_trial)
    assert published.unmet(load_scenario(path)) is None


def test_every_paper_lists_what_its_analysis_reads():
    for paper in ("namiki2003", "higashimori2007", "namiki1999"):
        table = published.reads(paper)
        assert any(w.startswith("claims") for w in table), table
        assert any(w.startswith("Fig.") for w in table), table
