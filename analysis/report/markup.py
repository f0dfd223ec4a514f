"""Text from a log (a scenario's name, its seed, a caption quoting it) as data in the report's
HTML and Markdown, never as markup: escaped, on one line, links only to the report's own files."""

from __future__ import annotations

import html
import re
from urllib.parse import quote

from replay.scenario.yamlio import one_line

_MD_SPECIAL = re.compile(r"[\\`\[\]<>&|]")  # (emphasis left: it cannot inject)
_MD_ENTITY = {"<": "&lt;", ">": "&gt;", "&": "&amp;"}


def e(text) -> str:
    """HTML text or a double-quoted attribute value: ``& < > " '`` escaped, and every control
    or format character but the line break shown escaped (``\\x1b``, ``\\u202e``: a log's
    name cannot reorder or hide the text around it, nor reach a terminal that prints the page)."""
    return html.escape("\n".join(map(one_line, str(text).split("\n"))), quote=True)


def url(path: str) -> str:
    """A link to a file of the report (a relative POSIX path): percent-encoded (so no
    ``javascript:`` or other scheme, no query), then escaped for a double-quoted attribute."""
    return e(quote(path, safe="/"))


def md(text) -> str:
    """Markdown text: one line, no raw HTML (``< > &`` as entities), no link, code or table
    syntax (backslash-escaped), and no autolink where GitHub renders it (GFM's extension links
    bare ``https://...``, ``www.x`` and ``a@b.c``): :func:`no_autolink`."""
    text = _MD_SPECIAL.sub(
        lambda m: _MD_ENTITY.get(m.group(), "\\" + m.group()), one_line(str(text))
    )
    text = text.replace("\\](", "\\]\\(")  # (no "](" left to read as a link's target)
    return no_autolink(text)


_WWW = re.compile(r"(?<![A-Za-z0-9])(www)\.", re.IGNORECASE)


def no_autolink(text: str) -> str:
    """Markdown ``text`` in which GitHub's autolink extension finds no link (checked with
    cmark-gfm, GitHub's parser): the ``:`` of ``://`` and the ``.`` of ``www.``
    backslash-escaped (the extension looks for them in the source, not in escapes); after
    ``@`` a zero-width space (``&#8203;``), since e-mail autolinks (``a@b.c``, ``mailto:``,
    ``xmpp:``) are found in the parsed text, where an escape of ``@`` no longer shows (it also
    keeps ``@name`` from reading as a GitHub mention). The rendered text reads the same."""
    text = text.replace("://", "\\://")
    text = _WWW.sub(lambda m: m.group(1) + "\\.", text)
    return text.replace("@", "@&#8203;")


def pre(lines) -> str:
    """An HTML ``<pre>`` block of ``lines`` (commands), each on its one line (line breaks and
    control characters in it escaped as ``\\n``...: a name holding a line break never shows
    as a command line of its own), HTML-escaped."""
    return "<pre>" + e("\n".join(one_line(str(line)) for line in lines)) + "</pre>"


def md_code(text) -> str:
    """A Markdown code span of ``text`` on one line, its fence longer than any backtick run."""
    text = one_line(str(text))
    fence = "`" * (max((len(r) for r in re.findall("`+", text)), default=0) + 1)
    pad = " " if text.startswith("`") or text.endswith("`") else ""
    return f"{fence}{pad}{text}{pad}{fence}"


def md_fence(lines: list[str]) -> str:
    """A fenced block's opening/closing fence, longer than any backtick run in ``lines``."""
    longest = max((len(r) for line in lines for r in re.findall("`+", line)), default=0)
    return "`" * max(3, longest + 1)
