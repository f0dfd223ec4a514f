"""The docs say what the code does: the field reference is generated and kept in step."""

from pathlib import Path

from replay.cli import params_markdown

ROOT = Path(__file__).resolve().parents[2]


def test_scenario_reference_is_current():
    assert (ROOT / "docs" / "scenarios.md").read_text() == params_markdown(), (
        "docs/scenarios.md is stale: run `replay describe > docs/scenarios.md`"
    )


def test_readme_opens_with_the_two_commands():
    head = (ROOT / "README.md").read_text().splitlines()[:8]
    assert any(line.startswith("make run") for line in head)
    assert any(line.startswith("make test") for line in head)
    assert "make test" in (ROOT / ".ci" / "run").read_text()
