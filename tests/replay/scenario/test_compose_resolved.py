"""A sweep variant's resolved text is parsed by libyaml in its worker (compose_resolved): the same
nodes, marks and scenario as the pure-Python composer gives, and what is not a resolved text
(too deep, not YAML) is refused with compose's own error."""

from __future__ import annotations

import pytest
import yaml

from conftest import ROOT
from replay.scenario import ScenarioError, load_scenario, resolved_yaml
from replay.scenario.loader import scenario_from_text
from replay.scenario.yamlio import MAX_DEPTH, compose, compose_resolved

SHIPPED = sorted(p.stem for p in (ROOT / "scenarios").glob("*.yaml"))


def _nodes(node):
    """A node tree as comparable data: tag, value, style and where each node starts."""
    mark = (node.start_mark.name, node.start_mark.line, node.start_mark.column)
    if isinstance(node, yaml.ScalarNode):
        return (node.tag, node.value, node.style, mark)
    if isinstance(node, yaml.SequenceNode):
        return (node.tag, [_nodes(n) for n in node.value], mark)
    return (node.tag, [(_nodes(k), _nodes(v)) for k, v in node.value], mark)


@pytest.mark.parametrize("name", SHIPPED)
def test_a_resolved_text_reads_the_same_either_way(name):
    text = resolved_yaml(load_scenario(ROOT / "scenarios" / f"{name}.yaml"))
    assert _nodes(compose_resolved(text, "<v>")) == _nodes(compose(text, "<v>"))
    fast = scenario_from_text(text, name="<v>", resolved=True)
    assert fast == scenario_from_text(text, name="<v>")
    assert resolved_yaml(fast) == text


@pytest.mark.parametrize(
    "text,words",
    [
        ("a: " + "[" * (MAX_DEPTH + 5) + "]" * (MAX_DEPTH + 5), f"nested deeper than {MAX_DEPTH}"),
        ("a: [1, 2\nb: 3", "not valid YAML"),
        ("a: *nowhere", "not valid YAML"),
    ],
)
def test_what_is_no_resolved_text_gets_compose_s_error(text, words):
    with pytest.raises(ScenarioError) as fast:
        compose_resolved(text, "<v>")
    with pytest.raises(ScenarioError) as slow:
        compose(text, "<v>")
    assert str(fast.value) == str(slow.value) and words in str(fast.value)
