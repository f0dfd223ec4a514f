"""Shipped scenarios as building blocks, layouts, and no data path built from ``__file__``."""

from __future__ import annotations

import ast
import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from replay.cli import main
from replay.control.catching.controller import alpha_path
from replay.foxglove.layouts import layout
from replay.papers import papers
from replay.resources import scenario_dir
from replay.scenario import ScenarioError, load_scenario

ROOT = Path(__file__).resolve().parents[2]


def cli(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


@pytest.mark.parametrize("ref", ["stick_3step", "stick_3step.yaml"])
def test_a_user_file_extends_a_shipped_scenario_by_name(tmp_path, ref):
    f = tmp_path / "mine.yaml"
    f.write_text(f"extends: {ref}\nseed: 7\n")
    sc = load_scenario(f)
    shipped = load_scenario(scenario_dir() / "stick_3step.yaml")
    assert sc.seed == 7 and shipped.seed != 7
    assert sc.plant == shipped.plant and sc.controller == shipped.controller


def test_a_local_file_wins_over_the_shipped_one(tmp_path):
    (tmp_path / "stick_3step.yaml").write_text("extends: stick_3step\nseed: 11\n")
    (tmp_path / "mine.yaml").write_text("extends: stick_3step\n")
    assert load_scenario(tmp_path / "mine.yaml").seed == 11  # the file beside it, which ...
    assert load_scenario(tmp_path / "stick_3step.yaml").seed == 11  # ... builds on the shipped


def test_a_missing_base_names_both_places(tmp_path):
    (tmp_path / "bad.yaml").write_text("extends: no_such_scenario\n")
    with pytest.raises(ScenarioError, match="shipped scenario") as e:
        load_scenario(tmp_path / "bad.yaml")
    assert "bad.yaml:1:" in str(e.value)


def test_data_files_resolve_against_the_file_that_names_them(tmp_path):
    """A user's catch variant in another folder keeps the shipped scenario's alpha file."""
    (tmp_path / "c.yaml").write_text("extends: catch_optimised\nseed: 3\n")
    path = alpha_path(load_scenario(tmp_path / "c.yaml").controller.params)
    assert path is not None and path.is_file()
    assert (
        path.resolve()
        == alpha_path(
            load_scenario(scenario_dir() / "catch_optimised.yaml").controller.params
        ).resolve()
    )


def test_show_prints_and_copies_a_shipped_scenario(tmp_path):
    r = cli("show", "stick_3step")
    assert r.exit_code == 0
    assert r.output == (scenario_dir() / "stick_3step.yaml").read_text()
    out = tmp_path / "my.yaml"
    r = cli("show", "stick_3step", "-o", out)
    assert r.exit_code == 0 and out.read_text() == (scenario_dir() / "stick_3step.yaml").read_text()
    r = cli("show", "stick_3step", "-o", out)  # never over an existing file
    assert r.exit_code == 2 and "will not overwrite" in r.output
    r = cli("show", "no_such_scenario")
    assert r.exit_code == 2 and "replay list" in r.output


def test_show_copies_of_extending_scenarios_still_load(tmp_path):
    out = tmp_path / "mu1.yaml"
    assert cli("show", "stick_3step_mu1", "-o", out).exit_code == 0
    assert load_scenario(out).plant == load_scenario(scenario_dir() / "stick_3step_mu1.yaml").plant


def test_layouts_for_every_paper(tmp_path):
    for paper in papers():
        out = tmp_path / f"{paper}.json"
        r = cli("layout", paper, "-o", out)
        assert r.exit_code == 0, r.output
        data = json.loads(out.read_text())
        assert data == layout(paper) and data["version"] == 1
        text = out.read_text()
        assert '"/log"' in text and '"/scene"' in text
    # the catch layout is the one the Foxglove SDK's typed API wrote (docs/foxglove/)
    docs = ROOT / "docs" / "foxglove" / "catch_layout.json"
    assert layout("namiki2003") == json.loads(docs.read_text())
    assert cli("layout", "nope").exit_code == 2


def test_list_plugins_names_kinds_once_plural():
    r = cli("list", "--plugins")
    assert r.exit_code == 0
    assert "figuress" not in r.output and "claimss" not in r.output
    assert "figures:" in r.output and "claims:" in r.output and "plants:" in r.output


def _file_data_paths(path: Path) -> list[int]:
    """Lines where an expression uses ``__file__`` and names data/, scenarios/ or sweeps/."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    bad = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.stmt) or isinstance(
            node, (ast.FunctionDef, ast.ClassDef, ast.If, ast.For, ast.With, ast.Try)
        ):
            continue
        names = {n.id for n in ast.walk(node) if isinstance(n, ast.Name)}
        strings = {
            n.value
            for n in ast.walk(node)
            if isinstance(n, ast.Constant) and isinstance(n.value, str)
        }
        if "__file__" in names and strings & {"data", "scenarios", "sweeps"}:
            bad.append(node.lineno)
    return bad


def test_no_module_builds_a_data_path_from_its_own_file():
    """Shipped files are found through replay.resources (a wheel has no checkout around it)."""
    offenders = []
    for top in ("replay", "plants", "analysis"):
        for f in sorted((ROOT / top).rglob("*.py")):
            if f.name == "resources.py" and f.parent.name == "replay":
                continue
            offenders += [f"{f.relative_to(ROOT)}:{n}" for n in _file_data_paths(f)]
    assert not offenders, offenders


def test_the_path_check_catches_the_pattern(tmp_path):
    f = tmp_path / "m.py"
    f.write_text('from pathlib import Path\nP = Path(__file__).parents[1] / "data" / "x.yaml"\n')
    assert _file_data_paths(f) == [2]
