"""What reaches a terminal from a log or a file name is one line of inert text (issue #36):
``one_line`` escapes control characters and also the format characters (Unicode category Cf:
bidi overrides and isolates, zero-width characters) that reorder or hide what is shown."""

from __future__ import annotations

import shutil
import sys
import unicodedata
from pathlib import Path

from click.testing import CliRunner

from replay.cli import main
from replay.log import LogWriter
from replay.messages import TOPIC_EVENTS, TOPIC_SCENARIO, Event, ScenarioInfo
from replay.scenario.yamlio import _CONTROL, one_line

HIDDEN = {"Cc", "Cf", "Zl", "Zp", "Cs"}  # what one_line escapes, by Unicode category
TRICKS = "\u202e\u2066\u2067\u2068\u2069\u200e\u200f\u200b\u061c\ufeff\u00ad\U000e0041\x1b\r"


def _hidden(text: str) -> list[str]:
    """The characters of ``text`` (newlines aside) a terminal must not be handed raw."""
    return [c for c in text.replace("\n", "") if unicodedata.category(c) in HIDDEN]


def test_one_line_escapes_every_control_and_format_character():
    every = "".join(map(chr, range(sys.maxunicode + 1)))
    escaped = set(_CONTROL.findall(every))
    hidden = {c for c in every if unicodedata.category(c) in HIDDEN}
    assert hidden <= escaped, sorted(f"U+{ord(c):04X}" for c in hidden - escaped)
    # (besides: code points unassigned in this Python's Unicode, format characters in newer ones)
    assert {unicodedata.category(c) for c in escaped - hidden} <= {"Cn"}


def test_one_line_leaves_text_and_names_bidi_controls():
    text = "θ = 0.5 rad, ω ≤ 3 rad/s, café, 日本語, ✓ 🤖 ‘quoted’ — ok"
    assert one_line(text) == text
    out = one_line(f"name{TRICKS}end\nnext")
    assert _hidden(out) == [] and "\n" not in out
    assert "\\u202e" in out and "\\u2066" in out and "\\u200f" in out and "\\U000e0041" in out
    assert out.startswith("name") and out.endswith("end\\nnext")
    assert one_line("\ud800") == "\\ud800"  # (a lone surrogate: from a log's JSON)


def test_info_prints_a_logs_bidi_controls_escaped(tmp_path):
    path = tmp_path / "bidi.mcap"
    with LogWriter(path) as log:
        log.write(TOPIC_SCENARIO, ScenarioInfo(0.0, f"run{TRICKS}", "p", "a: 1\n", 1, "v"), 0)
        log.write(f"/topic{TRICKS}", {"t": 0.0, "v": 1.0}, 0)
        log.write(TOPIC_EVENTS, Event(0.1, f"kind{TRICKS}", {f"k{TRICKS}": TRICKS}), 10**8)
        log.write(
            TOPIC_EVENTS, Event(0.2, "outcome", {"success": True, "reason": TRICKS}), 2 * 10**8
        )
    r = CliRunner().invoke(main, ["info", str(path)], prog_name="replay")
    assert r.exit_code == 0, r.output
    assert _hidden(r.output) == [], r.output
    assert r.output.count("\\u202e") >= 4  # name, topic, event kind, outcome reason


def test_validate_prints_a_file_name_escaped(tmp_path, project_root):
    base = Path(project_root) / "scenarios" / "stick_3step.yaml"
    folder = tmp_path / "s"
    folder.mkdir()
    name = folder / "a\x1b]0;PWNED\x07\x1b[2Jb\u202ec\u2066d.yaml"
    shutil.copy(base, name)
    r = CliRunner().invoke(main, ["validate", "--static", str(name)], prog_name="replay")
    assert r.exit_code == 0, r.output
    assert _hidden(r.output) == [] and r.output.count("\n") == 1, r.output
    assert r.output.startswith("ok: ") and "\\u202e" in r.output


def test_validate_prints_a_file_name_with_a_newline_on_one_line(tmp_path, project_root):
    base = Path(project_root) / "scenarios" / "stick_3step.yaml"
    name = tmp_path / "a\nok: forged.yaml"
    shutil.copy(base, name)
    r = CliRunner().invoke(main, ["validate", "--static", str(name)], prog_name="replay")
    assert r.exit_code == 0 and r.output.count("\n") == 1, r.output


def test_info_figures_and_claims_print_a_log_file_name_escaped(tmp_path, stick_3step_log):
    """A log *file* named with an OSC title, a bell, a line break and bidi controls: every
    command that names the file prints it inert (the file name is the user's, but a colleague
    may have chosen it)."""
    path = tmp_path / f"evil\x1b]0;T\x07\n{TRICKS}.mcap"
    shutil.copy(stick_3step_log, path)
    for args in (["info"], ["figures", "-o", str(tmp_path / "figs")], ["claims"]):
        r = CliRunner().invoke(main, [*args, str(path)], prog_name="replay")
        assert r.exit_code in (0, 1), r.output  # (claims: 1 when a claim fails)
        assert _hidden(r.output) == [], (args, r.output)
