"""The core is the right way up (docs/DESIGN.md, Layout): nothing under replay/ imports the
analysis or a plant (they reach the core through entry points), and no method imports a
simulator."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SIMULATORS = {"pybullet", "pybullet_data", "mujoco", "pymunk", "pydrake"}


def _imports(path: Path) -> set[str]:
    """The top-level package of every import in ``path`` (module level or inside functions)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found |= {a.name.split(".")[0] for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            found.add(node.module.split(".")[0])
    return found


def test_the_core_imports_no_analysis_and_no_plant():
    bad = {
        str(p.relative_to(ROOT)): sorted(_imports(p) & {"analysis", "plants"})
        for p in (ROOT / "replay").rglob("*.py")
    }
    assert not {k: v for k, v in bad.items() if v}


def _modules(path: Path) -> set[str]:
    """The full name of every module ``path`` imports (module level or inside functions)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            found |= {node.module} | {f"{node.module}.{a.name}" for a in node.names}
    return found


def test_the_core_imports_no_paper():
    """Outside the methods (replay/control/), the core reaches a paper only through its
    registration (replay.papers, entry point paper_replay.papers)."""
    control = ROOT / "replay" / "control"
    bad = {
        str(p.relative_to(ROOT)): sorted(m for m in _modules(p) if m.startswith("replay.control"))
        for p in (ROOT / "replay").rglob("*.py")
        if control not in p.parents
    }
    assert not {k: v for k, v in bad.items() if v}


def test_the_paper_scan_sees_a_method_import(tmp_path):
    probe = tmp_path / "probe.py"
    probe.write_text("def f():\n    from replay import control\n    import replay.control.stick\n")
    assert {"replay.control", "replay.control.stick"} <= _modules(probe)


def test_methods_import_no_simulator():
    bad = {
        str(p.relative_to(ROOT)): sorted(_imports(p) & SIMULATORS)
        for p in (ROOT / "replay" / "control").rglob("*.py")
    }
    assert not {k: v for k, v in bad.items() if v}


def test_the_scan_sees_a_function_level_import(tmp_path):
    probe = tmp_path / "probe.py"
    probe.write_text(
        "def f():\n    from analysis.runs import by_paper\n    import plants.airtable\n"
    )
    assert {"analysis", "plants"} <= _imports(probe)
