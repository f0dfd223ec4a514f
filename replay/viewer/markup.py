"""Text from a log, made safe for the viewer's GUI.

A log is someone else's data: its scenario name, paper, event kinds and notes are shown as plain
text, never as markup. Viser renders ``gui.add_markdown`` with raw HTML passed through to the
page (an ``<iframe srcdoc>`` runs script), so every piece of log data that goes into markdown
passes through :func:`plain`; labels, buttons and dropdowns are React text and only need
:func:`clean`.
"""

from __future__ import annotations

import re

LABEL_CHARS = 120  # a run's label or an event kind, as shown
TEXT_CHARS = 400  # any other text from a log (a note)

_CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f\u2028\u2029]+")
# every ASCII punctuation character: CommonMark lets a backslash make each one literal, which
# takes away HTML (<), entities (&), links ([ ] ( ) < >), autolinks (: . @), emphasis and the
# rest; but for an underscore inside a word (``catch_a``), which can neither open nor close
# emphasis and is left as it is
_PUNCTUATION = re.compile(r"[!-/:-@\[-^`{-~]|(?<![0-9A-Za-z])_|_(?![0-9A-Za-z])")


def clean(value: object, limit: int = LABEL_CHARS) -> str:
    """``value`` as one line of text: control characters and line breaks become a space, and
    it is cut to ``limit`` characters (an ellipsis marks the cut)."""
    text = _CONTROL.sub(" ", str(value))
    return text if len(text) <= limit else text[: limit - 1] + "…"


def plain(value: object, limit: int = TEXT_CHARS) -> str:
    """``value`` for markdown, shown literally: :func:`clean`, then ASCII punctuation
    backslash-escaped (no HTML, link, autolink or emphasis can form)."""
    return _PUNCTUATION.sub(r"\\\g<0>", clean(value, limit))
