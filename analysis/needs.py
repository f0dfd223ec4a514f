"""What a figure, panel or claims row reads, checked before it is drawn or evaluated.

A log that lacks a topic (a plug-in controller that does not publish ``/effector/state``) skips
what reads it, with a note naming the topic (a :class:`Skipped` warning), never a crash. The
figure and claims modules list what each figure and row reads (their ``TOPICS``), the contract
a new controller fulfils (docs/catching.md, docs/grasping.md, README's stick section).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Iterable, Iterator, Mapping
from contextlib import contextmanager
from typing import Any, TypeVar

T = TypeVar("T")


class Skipped(UserWarning):
    """A figure, panel or claims row left out: a log lacks a topic it reads."""


def missing(log: Any, topics: Iterable[str]) -> list[str]:
    """The ``topics`` of which ``log`` holds no message."""
    try:
        counts = log.topic_counts()
    except AttributeError:  # (a stand-in log without counts: nothing known to be missing)
        return []
    return [t for t in topics if not counts.get(t)]


def skip(text: str) -> None:
    warnings.warn(text, Skipped, stacklevel=3)


def has(logs: Mapping[str, Any], topics: Iterable[str], what: str) -> bool:
    """Whether every log of ``logs`` (key -> reader) holds every topic; if not, one note per
    log saying which ``what`` (a figure, a row) is left out for want of which topic."""
    topics = tuple(topics)
    ok = True
    for key, log in logs.items():
        gone = missing(log, topics)
        if gone:
            skip(f"{key}: {what} left out: the log has no {', '.join(gone)}")
            ok = False
    return ok


def guarded(
    logs: Mapping[str, Any], topics: Iterable[str], what: str, make: Callable[[], list[T]]
) -> list[T]:
    """``make()`` if the logs hold ``topics``, else ``[]`` with a note (:func:`has`)."""
    return make() if has(logs, topics, what) else []


@contextmanager
def skipped_notes() -> Iterator[list[str]]:
    """The :class:`Skipped` notes raised meanwhile, collected (once each) in the list given;
    other warnings pass on."""
    notes: list[str] = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        yield notes
    for w in caught:
        if issubclass(w.category, Skipped):
            if str(w.message) not in notes:
                notes.append(str(w.message))
        else:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)


def figure_notes(keys: Iterable[str], shown: Iterable[str], notes: list[str]) -> list[str]:
    """What to say after a paper's figures: each run (key) in no figure in one line with why
    (its notes, else that no figure draws it), then the notes about the runs that are shown."""
    shown, out, said = set(shown), [], set()
    for key in keys:
        if key in shown:
            continue
        mine = [n for n in notes if n.startswith(f"{key}: ")]
        said.update(mine)
        why = "; ".join(n[len(key) + 2 :] for n in mine) or "no figure of its paper draws it"
        out.append(f"{key}: in no figure ({why})")
    return out + [n for n in notes if n not in said]
