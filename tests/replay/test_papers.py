"""A paper is registered once (issue #40): its ``replay.papers.Paper`` names its plug-ins, its
figures, claims, layout and captions, and the registry finds them there."""

from __future__ import annotations

import inspect

import pytest

from replay import registry
from replay.papers import Paper, papers, resolve

# the Paper fields that name plug-ins of a kind (the registry's kinds)
KINDS = {
    "controllers": "controller",
    "plants": "plant",
    "sensors": "sensor",
    "viewer_scenes": "viewer_scene",
}


def _named():
    return [
        (key, field, name, ref)
        for key, paper in papers().items()
        for field in KINDS
        for name, ref in getattr(paper, field).items()
    ]


def test_every_scenario_paper_is_registered():
    from replay.resources import scenario_dir
    from replay.scenario import load_scenario

    used = {load_scenario(p).paper for p in scenario_dir().glob("*.yaml")}
    assert used <= set(papers())
    assert all(key == p.key for key, p in papers().items())


@pytest.mark.parametrize("key, field, name, ref", _named())
def test_every_named_plugin_is_found_by_the_registry(key, field, name, ref):
    assert registry.load(KINDS[field], name) is resolve(ref), (key, name)


@pytest.mark.parametrize("key", sorted(papers()))
def test_a_paper_names_callables_and_captions_of_figures(key):
    paper = papers()[key]
    for ref in (paper.figures, paper.claims, paper.layout):
        assert callable(resolve(ref)), ref
    assert registry.load("figures", key) is resolve(paper.figures)
    assert registry.load("claims", key) is resolve(paper.claims)
    assert all(isinstance(n, int) and n > 0 and text for n, text in paper.captions.items())
    assert set(paper.drawn_for) <= set(paper.captions)
    assert set(paper.drawn_for.values()) <= set(paper.controllers)


def test_a_paper_registered_in_process_adds_its_plugins(monkeypatch):
    monkeypatch.setitem(registry._registered, "paper", {})
    toy = Paper(
        "toy2026",
        "A toy",
        "Nobody",
        "",
        9,
        controllers={"toy_hold": "replay.control.stick.strategy:TwoStepController"},
        figures="replay.papers:papers",  # (any callable: the registry only finds it)
    )
    registry.register("paper", "toy2026", toy)
    assert "toy_hold" in registry.names("controller")
    assert registry.load("controller", "toy_hold").__name__ == "TwoStepController"
    assert registry.load("figures", "toy2026") is papers
    assert list(papers())[-1] == "toy2026"  # (order 9: after the three papers)
    with pytest.raises(registry.UnknownPlugin, match="toy2026"):
        registry.load("claims", "toy2026")  # (it has none: the known ones are named)


def test_a_group_entry_wins_over_a_paper_of_the_same_name(monkeypatch):
    class Mine:
        pass

    monkeypatch.setitem(registry._registered, "controller", {"stick_2step": Mine})
    assert registry.load("controller", "stick_2step") is Mine
    assert inspect.isclass(registry.load("controller", "stick_3step"))
