"""Reading scenario YAML safely into node trees: bounded, strict, and with a place for every error.

Everything a hostile file can do to a YAML reader ends here as one :class:`ScenarioError` naming
``file:line:column``:

- a text over the ``scenario_bytes`` limit (:mod:`replay.limits`: a file, a ``--set`` value or a
  log's stored scenario, checked before it is read or parsed);
- not UTF-8 (binary, UTF-16, Latin-1) or with characters YAML forbids (NUL);
- nesting deeper than ``MAX_DEPTH`` (the composer recurses) and alias bombs (``MAX_NODES``
  counted with every alias expanded) or a recursive alias;
- keys that are not plain names (``? [a, b]``), tags other than YAML's own (``!!python/...``).

Only node trees come out (``yaml.compose``): values are built from them by the loader, so a
scenario is data, never code.
"""

from __future__ import annotations

import io
import os
import re
from collections import OrderedDict
from pathlib import Path

import yaml

from replay.limits import LimitError, check, limit

MAX_DEPTH = 32  # mappings and lists nested at most this deep
MAX_NODES = 100_000  # YAML nodes, aliases expanded (an alias bomb stays small)
_YAML_TAG = "tag:yaml.org,2002:"
_SCALAR_TAGS = {_YAML_TAG + t for t in ("str", "int", "float", "bool", "null", "timestamp")}
_MAP, _SEQ = _YAML_TAG + "map", _YAML_TAG + "seq"


class ScenarioError(Exception):
    """Bad input: ``where`` is ``file:line:column`` (or the file, or ``<--set>``), ``path`` the
    field; ``str()`` is one line."""

    def __init__(
        self,
        message: str,
        *,
        node: yaml.Node | None = None,
        path: str = "",
        file: str | None = None,
        mark: yaml.Mark | None = None,
    ) -> None:
        self.message = one_line(message)
        self.path = one_line(path)
        mark = mark if mark is not None else (node.start_mark if node is not None else None)
        if mark is not None:
            self.where = f"{mark.name}:{mark.line + 1}:{mark.column + 1}"
        else:
            self.where = file or "<scenario>"
        self.where = one_line(self.where)
        super().__init__(f"{self.where}: {self.path + ': ' if self.path else ''}{self.message}")


# what a terminal must not be handed raw: control characters (C0, DEL, C1), line and paragraph
# separators, lone surrogates, and the format characters (Unicode category Cf: bidi overrides
# and isolates such as U+202E, zero-width characters, soft hyphen, tags), which reorder or hide
# what is shown; the Cf ranges are Unicode 15's (tests check them against unicodedata)
_CONTROL = re.compile(
    "[\x00-\x1f\x7f-\x9f\u2028\u2029\ud800-\udfff"
    "\u00ad\u0600-\u0605\u061c\u06dd\u070f\u0890\u0891\u08e2\u180e\u200b-\u200f"
    "\u202a-\u202e\u2060-\u2064\u2066-\u206f\ufeff\ufff9-\ufffb\U000110bd\U000110cd"
    "\U00013430-\U0001343f\U0001bca0-\U0001bca3\U0001d173-\U0001d17a\U000e0001"
    "\U000e0020-\U000e007f]"
)


def one_line(text: str) -> str:
    """``text`` with line breaks, control and format characters escaped (``\\u202e``): an
    error is one line, and a log's text cannot reorder, hide or restyle what a terminal shows."""
    return _CONTROL.sub(lambda m: repr(m.group())[1:-1], str(text))


def show(value, limit: int = 40) -> str:
    """A user's value for an error message: repr, shortened."""
    text = value if isinstance(value, str) else repr(value)
    if len(text) > limit:
        text = f"{text[: limit // 2]}...({len(text)} characters)"
    return repr(text) if isinstance(value, str) else text


# -- text ------------------------------------------------------------------------------------


def _tag(tag: str) -> str:
    return show(tag.replace(_YAML_TAG, "!!"), 60)


def _line_col(data: bytes | str, pos: int) -> tuple[int, int]:
    head = data[:pos]
    text = head.decode("latin-1") if isinstance(head, bytes) else head  # 1 byte = 1 char
    return text.count("\n") + 1, pos - (text.rfind("\n") + 1) + 1


def check_size(size: int, name: str, what: str = "a scenario") -> None:
    """Refuse a text of ``size`` bytes over the ``scenario_bytes`` limit (``name``: where it comes
    from), before it is read or parsed (PyYAML's pure-Python scanner: ~0.25 s a MB)."""
    try:
        check("scenario_bytes", size, f"the text of {what}")
    except LimitError as exc:
        raise ScenarioError(str(exc), file=name) from None


def check_text(text: str, name: str, what: str = "a scenario") -> None:
    """:func:`check_size` of ``text`` in UTF-8 (e.g. a log's stored scenario, before parsing)."""
    check_size(len(text), name, what)  # (its characters: a lower bound, before encoding it)
    check_size(len(text.encode("utf-8", "surrogatepass")), name, what)


def _cap(name: str) -> int:
    try:
        return limit("scenario_bytes")
    except LimitError as exc:  # a bad REPLAY_LIMIT_SCENARIO_BYTES
        raise ScenarioError(str(exc), file=name) from None


def read_text(path: Path) -> str:
    """The file's text: UTF-8 (a BOM is allowed), within the ``scenario_bytes`` limit (read
    bounded: a device or a file growing while read cannot make it bigger)."""
    name = str(path)
    try:
        with path.open("rb") as f:
            check_size(os.fstat(f.fileno()).st_size, name)
            data = f.read(_cap(name) + 1)
        check_size(len(data), name)
    except OSError as exc:
        raise ScenarioError(f"cannot read scenario: {exc.strerror or exc}", file=name) from None
    if data.startswith((b"\xff\xfe", b"\xfe\xff")):
        raise ScenarioError("the file is UTF-16: save it as UTF-8", file=f"{name}:1:1")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line, col = _line_col(data, exc.start)
        raise ScenarioError(
            "not UTF-8 text; a scenario is UTF-8 YAML", file=f"{name}:{line}:{col}"
        ) from None
    return text


# -- composing ---------------------------------------------------------------------------------


class _BoundedLoader(yaml.SafeLoader):
    """A SafeLoader whose composer refuses to nest deeper than ``MAX_DEPTH``."""

    source_name = "<string>"

    def __init__(self, stream) -> None:
        super().__init__(stream)
        self.name = self.source_name
        self._depth = 0

    def compose_node(self, parent, index):
        self._depth += 1
        try:
            if self._depth > MAX_DEPTH:
                raise ScenarioError(
                    f"nested deeper than {MAX_DEPTH} levels", mark=self.peek_event().start_mark
                )
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1


def _loader(name: str):
    return type("NamedLoader", (_BoundedLoader,), {"source_name": name})


# the node trees of the texts composed last, by (text, name, what): a sweep loads its scenario
# file and the same --set values once per variant (catch_rate's 840 variants: ~10 composes
# each, 12 of 18 s of its expansion); a caller gets a copy, as if parsed again
_COMPOSED: OrderedDict[tuple[str, str, str], yaml.Node] = OrderedDict()
_COMPOSED_ENTRIES = 128
_COMPOSED_CHARS = 256 * 1024  # a longer text is composed each time, not kept


def _copy(node: yaml.Node) -> yaml.Node:
    """A node tree's copy: new nodes and lists (the loader edits them), the same marks and
    scalar strings (never edited)."""
    if isinstance(node, yaml.MappingNode):
        pairs = [(_copy(k), _copy(v)) for k, v in node.value]
        return yaml.MappingNode(node.tag, pairs, node.start_mark, node.end_mark, node.flow_style)
    if isinstance(node, yaml.SequenceNode):
        items = [_copy(v) for v in node.value]
        return yaml.SequenceNode(node.tag, items, node.start_mark, node.end_mark, node.flow_style)
    return yaml.ScalarNode(node.tag, node.value, node.start_mark, node.end_mark, node.style)


def compose(text: str, name: str, *, what: str = "a scenario") -> yaml.Node | None:
    """``text`` as a checked node tree (None for an empty document)."""
    check_text(text, name, what)  # (each time: the limit may have changed since)
    key = (text, name, what)
    kept = _COMPOSED.get(key)
    if kept is not None:
        _COMPOSED.move_to_end(key)
        return _copy(kept)
    node = _compose(text, name, what)
    if node is not None and len(text) <= _COMPOSED_CHARS:
        _COMPOSED[key] = _copy(node)
        if len(_COMPOSED) > _COMPOSED_ENTRIES:
            _COMPOSED.popitem(last=False)
    return node


def _compose(text: str, name: str, what: str) -> yaml.Node | None:
    try:
        node = yaml.compose(text, Loader=_loader(name))
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        problem = exc.problem or exc.context or "syntax error"
        raise ScenarioError(f"not valid YAML: {problem}", mark=mark, file=name) from None
    except yaml.reader.ReaderError as exc:
        line, col = _line_col(text, exc.position)
        raise ScenarioError(
            f"not valid YAML: character {exc.character!r} is not allowed in {what}",
            file=f"{name}:{line}:{col}",
        ) from None
    except yaml.YAMLError as exc:
        raise ScenarioError(f"not valid YAML: {exc}", file=name) from None
    if node is not None:
        check_shape(node)
    return node


_C_LOADER = getattr(yaml, "CSafeLoader", None)  # libyaml's, where PyYAML was built with it
_NESTING = {
    yaml.MappingStartEvent: 1,
    yaml.SequenceStartEvent: 1,
    yaml.MappingEndEvent: -1,
    yaml.SequenceEndEvent: -1,
}


class _NamedText(io.StringIO):
    """A text with a name: what libyaml's parser puts in its marks (``file:line:col``)."""

    def __init__(self, text: str, name: str) -> None:
        super().__init__(text)
        self.name = name


def compose_resolved(text: str, name: str) -> yaml.Node | None:
    """:func:`compose` of a text that :func:`replay.scenario.resolved_yaml` wrote (a sweep's
    variant, handed to its worker), by libyaml where PyYAML has it: the same nodes and marks,
    ~30x faster (a catch variant: 10 -> 0.3 ms). Its nesting is counted from libyaml's events
    first (its composer recurses in C, with no depth check of its own); a text that is too deep,
    or not YAML, goes to :func:`compose`, which says what is wrong as for any text."""
    if _C_LOADER is None:
        return compose(text, name)
    check_text(text, name)
    try:
        depth = 0
        for event in yaml.parse(_NamedText(text, name), Loader=_C_LOADER):
            depth += _NESTING.get(type(event), 0)
            if depth > MAX_DEPTH:
                return compose(text, name)
        node = yaml.compose(_NamedText(text, name), Loader=_C_LOADER)
    except yaml.YAMLError:
        return compose(text, name)
    if node is not None:
        _plain_style(node)
        check_shape(node)
    return node


def _plain_style(node: yaml.Node) -> None:
    """A plain scalar's style as the pure-Python composer gives it (None; libyaml's is ""):
    the loader reads a plain ``1e-3`` by it."""
    if isinstance(node, yaml.ScalarNode):
        if node.style == "":
            node.style = None
    elif isinstance(node, yaml.SequenceNode):
        for item in node.value:
            _plain_style(item)
    elif isinstance(node, yaml.MappingNode):
        for key, value in node.value:
            _plain_style(key)
            _plain_style(value)


def check_shape(root: yaml.Node) -> None:
    """Keys are plain scalars, tags YAML's own, and the tree with aliases expanded has at most
    ``MAX_NODES`` nodes and no cycle."""
    size: dict[int, int] = {}
    active: set[int] = set()

    def count(node: yaml.Node, depth: int) -> int:
        key = id(node)
        if key in size:
            return size[key]
        if key in active or depth > 2 * MAX_DEPTH:
            raise ScenarioError("a recursive alias (a node that contains itself)", node=node)
        allowed = (
            {_MAP}
            if isinstance(node, yaml.MappingNode)
            else {_SEQ}
            if isinstance(node, yaml.SequenceNode)
            else _SCALAR_TAGS
        )
        if node.tag not in allowed:
            raise ScenarioError(
                f"tag {_tag(node.tag)} not allowed (scenarios are data, not code)", node=node
            )
        active.add(key)
        n = 1
        if isinstance(node, yaml.MappingNode):
            for k, v in node.value:
                if not isinstance(k, yaml.ScalarNode):
                    raise ScenarioError(
                        "a key must be a plain name, not a list or a mapping", node=k
                    )
                if k.tag == _YAML_TAG + "merge":
                    raise ScenarioError(
                        "merge keys (<<) are not supported: use extends: FILE", node=k
                    )
                if k.tag not in _SCALAR_TAGS:
                    raise ScenarioError(f"tag {_tag(k.tag)} not allowed on a key", node=k)
                n += 1 + count(v, depth + 1)
        elif isinstance(node, yaml.SequenceNode):
            for v in node.value:
                n += count(v, depth + 1)
        active.discard(key)
        if n > MAX_NODES:
            raise ScenarioError(
                f"too many values ({n} with aliases expanded; at most {MAX_NODES}): an alias bomb?",
                node=node,
            )
        size[key] = n
        return n

    count(root, 0)
