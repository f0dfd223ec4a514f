"""The CLI as the tests call it: ``invoke`` (as ``replay ARGS``) and ``one_error`` (the one
``error:`` line a refused command prints)."""

from __future__ import annotations

from click.testing import CliRunner, Result

from replay.cli import main


def invoke(*args) -> Result:
    return CliRunner().invoke(main, [str(a) for a in args], prog_name="replay")


def one_error(r: Result) -> str:
    """The command exited 2 with one ``error:`` line on stderr and no traceback; that line."""
    lines = [line for line in r.stderr.splitlines() if line.strip()]
    assert r.exit_code == 2, (r.exit_code, r.output)
    assert len(lines) == 1 and lines[0].startswith("error: "), r.stderr
    assert "Traceback" not in r.output
    return lines[0]
