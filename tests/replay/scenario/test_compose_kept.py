"""A text composed again (a sweep's scenario file and --set values, once per variant) is
parsed once: each caller gets its own tree, as if parsed again, and the size limit still
holds for a text kept from before it was lowered."""

from __future__ import annotations

import pytest
import yaml

from replay.scenario import yamlio
from replay.scenario.yamlio import ScenarioError, compose

TEXT = "name: kept\nplant: {type: toy, params: {mass: 2.0}}\nlist: [1, 2, {a: b}]\n"


def _plain(node):
    return yaml.SafeLoader("").construct_document(node)


def test_a_text_is_parsed_once_and_each_caller_gets_its_own_tree(monkeypatch):
    calls = []
    real = yaml.compose
    monkeypatch.setattr(yaml, "compose", lambda *a, **k: calls.append(1) or real(*a, **k))
    name = "<test_compose_kept>"
    first = compose(TEXT, name)
    first.value.pop()  # a caller edits its tree (the loader pops extends, migrates fields)
    first.value[0][1].value = "edited"
    second, third = compose(TEXT, name), compose(TEXT, name)
    assert len(calls) == 1
    assert _plain(second) == _plain(third) == yaml.safe_load(TEXT)
    assert second is not third and second.value[2][1] is not third.value[2][1]
    assert second.start_mark.line == 0 and second.value[1][0].start_mark.line == 1  # its marks


def test_a_kept_text_is_still_held_to_the_limit(monkeypatch):
    compose(TEXT, "<test_compose_limit>")
    monkeypatch.setenv("REPLAY_LIMIT_SCENARIO_BYTES", "10")
    with pytest.raises(ScenarioError, match="scenario_bytes|limit|bytes"):
        compose(TEXT, "<test_compose_limit>")


def test_the_kept_trees_are_bounded():
    for i in range(yamlio._COMPOSED_ENTRIES + 10):
        compose(f"n: {i}\n", "<test_compose_bound>")
    assert len(yamlio._COMPOSED) <= yamlio._COMPOSED_ENTRIES
    big = "x: '" + "a" * (yamlio._COMPOSED_CHARS + 1) + "'\n"
    compose(big, "<test_compose_big>")
    assert all(key[0] != big for key in yamlio._COMPOSED)
