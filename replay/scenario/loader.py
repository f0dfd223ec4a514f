"""Loading scenarios strictly: YAML (safe) -> typed dataclasses, errors with file, line and field.

- ``extends: other.yaml`` (relative to the file) starts from that file; mappings merge key by
  key, anything else is replaced, and a plug-in section whose ``type:`` changes is replaced
  whole.
- ``--set key.path=value`` overrides one field (the value is read as YAML); one that changes a
  plug-in's ``type`` drops that section's ``params`` (they belong to the other plug-in), one
  that changes a ``type`` inside params (``plant.params.engine.type``) drops the settings
  beside it.
- A plug-in ``type`` is an installed plug-in's name or an import path ``module:Class``, imported
  from the folder of the file that wrote it (the cwd for ``--set``) when a scenario is loaded
  to run, never when a log's stored scenario is read (``plugins="known-only"``).
- Every value passes one validation layer before a run starts: its type (every list item too,
  and the list's length), finiteness, range, choices, size; then the checks between fields
  (each ``Params.__post_init__``, rates that divide the physics rate) and between plug-ins
  (:mod:`replay.scenario.ports`). So ``replay validate`` accepts exactly what ``replay run``
  can run.
- Any failure raises :class:`ScenarioError` naming ``file:line:column`` of the field's own
  node, the field path and what was expected.

A new scenario section is a field of :class:`~replay.scenario.schema.Scenario`; a section that
holds plug-ins (``type:`` + ``params:``) is also listed in :func:`plugin_sections`.
"""

from __future__ import annotations

import dataclasses
import math
import re
import sys
import types
import typing
from pathlib import Path
from typing import Any, Iterator

import yaml

from replay import registry
from replay.interfaces import Controller, Plant, Sensor
from replay.limits import LimitError, check
from replay.params import MAX_CHARS, MAX_FLOAT, MAX_INT, MAX_ITEMS, ParamError
from replay.scenario.schema import NAME_PATTERN, Scenario
from replay.scenario.yamlio import (
    ScenarioError,
    compose,
    compose_resolved,
    read_text,
    show,
)

__all__ = [
    "ScenarioError",
    "build",
    "build_dataclass",
    "load_scenario",
    "params_from_data",
    "plugin_sections",
    "resolved_yaml",
    "scenario_from_text",
    "to_plain",
]

_SET_SOURCE = "<--set>"
MAX_EXTENDS = 16  # extends chains at most this long
_STR = "tag:yaml.org,2002:str"
_MAP = "tag:yaml.org,2002:map"
_PLAIN_FLOAT = re.compile(r"[-+]?(\d[\d_]*\.?\d*|\.\d+)[eE][-+]?\d+")  # 1e-3: YAML 1.1 says str


# -- reading YAML into node trees ----------------------------------------------------------------


def _compose_root(text: str, name: str, *, resolved: bool = False) -> yaml.MappingNode:
    node = compose_resolved(text, name) if resolved else compose(text, name)
    if node is None:
        raise ScenarioError("empty scenario", file=name)
    if not isinstance(node, yaml.MappingNode):  # (not quoted: the file may be no scenario at all)
        got = "a list" if isinstance(node, yaml.SequenceNode) else "a single value"
        raise ScenarioError(f"a scenario is a mapping of fields, got {got}", node=node)
    return node


def _is_yaml(name: str) -> bool:
    return name.lower().endswith((".yaml", ".yml"))


def _check_base(node: yaml.MappingNode) -> None:
    """A file named by ``extends`` is a scenario: every top-level field one of a scenario's, so
    that no other file's content is quoted back (the field is named by its line only)."""
    fields = [f.name for f in dataclasses.fields(Scenario) if not f.metadata.get("internal")]
    for k, _ in node.value:
        if k.value not in fields and k.value != "extends":
            raise ScenarioError(
                f"not a scenario: a top-level field that is none of {', '.join(fields)}", node=k
            )


def _compose_file(
    path: Path, seen: tuple[Path, ...] = (), *, inputs: list[Path]
) -> yaml.MappingNode:
    """The file's tree merged onto its ``extends`` chain; ``seen``: the files below it,
    ``inputs`` collects every file read."""
    inputs.append(path.resolve())
    node = _compose_root(read_text(path), str(path))
    if seen:
        _check_base(node)
    return _extends(node, path, seen, inputs=inputs)


def _extends(
    node: yaml.MappingNode, path: Path, seen: tuple[Path, ...] = (), *, inputs: list[Path]
) -> yaml.MappingNode:
    """``node`` (read from ``path``; for a text, a name in the folder it resolves against)
    merged onto the scenario its ``extends`` names, if any."""
    base_node = _pop(node, "extends")
    if base_node is None:
        return node
    if not (isinstance(base_node, yaml.ScalarNode) and base_node.tag == _STR and base_node.value):
        raise ScenarioError("expected a file name", node=base_node, path="extends")
    value = base_node.value
    if not (_is_yaml(value) or ("/" not in value and "\\" not in value)):
        raise ScenarioError(
            f"expected a shipped scenario's name or a .yaml file, got {show(value)}",
            node=base_node,
            path="extends",
        )
    try:
        base_path = _base_file(path, base_node.value, seen)
    except (OSError, RuntimeError, ValueError):
        raise ScenarioError(
            f"bad file name {show(base_node.value)}", node=base_node, path="extends"
        ) from None
    if base_path in seen or base_path == path.resolve():
        raise ScenarioError(
            f"extends loop through {show(base_path.name)}", node=base_node, path="extends"
        )
    if len(seen) >= MAX_EXTENDS:
        raise ScenarioError(
            f"extends chain longer than {MAX_EXTENDS} files", node=base_node, path="extends"
        )
    if not base_path.is_file():
        raise ScenarioError(
            f"no such scenario file {show(base_node.value)} (neither beside this file nor a "
            "shipped scenario: `replay list` names them)",
            node=base_node,
            path="extends",
        )
    if not _is_yaml(base_path.resolve().name):  # (a link from NAME.yaml to another file)
        raise ScenarioError(f"{show(value)} is not a .yaml file", node=base_node, path="extends")
    return _merge(_compose_file(base_path, seen + (path.resolve(),), inputs=inputs), node)


def _base_file(path: Path, value: str, seen: tuple[Path, ...]) -> Path:
    """What ``extends: value`` in ``path`` names: a file beside ``path`` wins (for a bare name,
    ``NAME.yaml``), unless it is ``path`` itself or already in the chain; else a
    bare name (``stick_3step`` or ``stick_3step.yaml``) is the shipped scenario of that name, so
    a user's own file can build on one after ``pip install``."""
    local = (path.parent / value).resolve()
    bare = "/" not in value and "\\" not in value and not _is_yaml(value)
    for candidate in ((path.parent / f"{value}.yaml").resolve(),) if bare else (local,):
        if candidate.is_file() and candidate != path.resolve() and candidate not in seen:
            return candidate
    if "/" not in value and "\\" not in value:
        from replay.resources import scenario_dir

        name = value if value.endswith((".yaml", ".yml")) else f"{value}.yaml"
        shipped = (scenario_dir() / name).resolve()
        if shipped.is_file() and shipped != path.resolve():
            return shipped
    return local


def _pop(mapping: yaml.MappingNode, key: str) -> yaml.Node | None:
    for i, (k, v) in enumerate(mapping.value):
        if k.value == key:
            del mapping.value[i]
            return v
    return None


def _get(mapping: yaml.MappingNode, key: str):
    for k, v in mapping.value:
        if k.value == key:
            return k, v
    return None


def _merge(base: yaml.Node, over: yaml.Node) -> yaml.Node:
    """``over`` on top of ``base``: mappings merge key by key, anything else is replaced. A
    plug-in section whose ``type:`` changes is replaced whole (its params belong to another
    plug-in)."""
    if not (isinstance(base, yaml.MappingNode) and isinstance(over, yaml.MappingNode)):
        return over
    base_type, over_type = _get(base, "type"), _get(over, "type")
    if base_type and over_type and base_type[1].value != over_type[1].value:
        return over
    merged = list(base.value)
    for k, v in over.value:
        for i, (bk, bv) in enumerate(merged):
            if bk.value == k.value:
                merged[i] = (bk, _merge(bv, v))
                break
        else:
            merged.append((k, v))
    return yaml.MappingNode(base.tag, merged, base.start_mark, base.end_mark)


def _apply_set(root: yaml.MappingNode, assignment: str) -> None:
    if "=" not in assignment:
        raise ScenarioError(
            f"--set expects key.path=value, got {show(assignment)}", file=_SET_SOURCE
        )
    key_path, text = assignment.split("=", 1)
    keys = [k.strip() for k in key_path.strip().split(".")]
    if not all(keys):
        raise ScenarioError(f"--set: bad key path {show(key_path)}", file=_SET_SOURCE)
    value = compose(text if text.strip() else "''", f"<--set {key_path}>", what="a value")
    if value is None:  # "key=" followed by a comment only
        value = compose("''", f"<--set {key_path}>")
    assert value is not None  # ('' composes to an empty scalar)
    node = root
    for depth, key in enumerate(keys):
        last = depth == len(keys) - 1
        found = _get(node, key)
        if last:
            if found and key == "type" and not _same_scalar(found[1], value):
                _drop_settings(node, inside_params="params" in keys[:-1])
                found = _get(node, key)
            if found:
                node.value[node.value.index(found)] = (found[0], value)
            else:
                node.value.append(
                    (yaml.ScalarNode(_STR, key, value.start_mark, value.end_mark), value)
                )
            return
        if found is None:
            child = yaml.MappingNode(_MAP, [], value.start_mark, value.end_mark)
            node.value.append((yaml.ScalarNode(_STR, key, value.start_mark, value.end_mark), child))
            node = child
        elif isinstance(found[1], yaml.MappingNode):
            node = found[1]
        elif isinstance(found[1], yaml.ScalarNode) and found[1].tag.endswith(":null"):
            child = yaml.MappingNode(_MAP, [], value.start_mark, value.end_mark)
            node.value[node.value.index(found)] = (found[0], child)
            node = child
        else:
            raise ScenarioError(
                f"--set {key_path}: {'.'.join(keys[: depth + 1])} is not a mapping",
                file=_SET_SOURCE,
            )


def _drop_settings(node: yaml.MappingNode, inside_params: bool) -> None:
    """What belonged to the ``type`` a ``--set`` replaces: a plug-in section's ``params`` (its
    rate and wiring stay the runner's), or, for a typed mapping inside params (the engine's
    ``{type: drake, dk_...}``), every setting beside the type, as ``extends:`` replaces it."""
    if not inside_params:
        _pop(node, "params")
        return
    node.value[:] = [(k, v) for k, v in node.value if k.value == "type"]


def _same_scalar(a: yaml.Node, b: yaml.Node) -> bool:
    return isinstance(a, yaml.ScalarNode) and isinstance(b, yaml.ScalarNode) and a.value == b.value


def _type_sets_first(sets) -> list[str]:
    """``--set`` assignments with those of a ``type`` first, so that one changing a plug-in
    (which drops its params) never drops params another ``--set`` gives."""
    return sorted(sets, key=lambda s: s.split("=", 1)[0].strip().rsplit(".", 1)[-1] != "type")


# -- node trees into typed values ------------------------------------------------------------


def _scalar(node: yaml.ScalarNode, path: str) -> Any:
    try:
        return yaml.SafeLoader("").construct_object(node, deep=True)
    except (yaml.constructor.ConstructorError, ValueError, OverflowError) as exc:
        problem = getattr(exc, "problem", None) or str(exc)
        raise ScenarioError(
            f"not allowed: {problem} (scenarios are data, not code)", node=node, path=path
        ) from None


def _describe(tp) -> str:
    origin = typing.get_origin(tp)
    if tp is float:
        return "a number"
    if tp is int:
        return "a whole number"
    if tp is bool:
        return "true or false"
    if tp is str:
        return "a string"
    if origin in (list, tuple):
        return "a list"
    if origin is dict or dataclasses.is_dataclass(tp):
        return "a mapping"
    return str(tp)


def _limits(meta: dict, default: float) -> tuple[float, float]:
    """The effective (low, high) of a number: its own bounds, else +-default."""
    low = next((meta[k] for k in ("ge", "gt") if meta.get(k) is not None), -default)
    high = next((meta[k] for k in ("le", "lt") if meta.get(k) is not None), default)
    return low, high


def _bounds(meta: dict, default: float | None = None) -> str:
    parts = []
    for key, sym in (("ge", ">="), ("gt", ">"), ("le", "<="), ("lt", "<")):
        if meta.get(key) is not None:
            parts.append(f"{sym} {meta[key]:g}")
    if default is not None:
        if not any(meta.get(k) is not None for k in ("ge", "gt")):
            parts.insert(0, f">= {-default:g}")
        if not any(meta.get(k) is not None for k in ("le", "lt")):
            parts.append(f"<= {default:g}")
    text = " and ".join(parts)
    if meta.get("unit") and meta["unit"] != "1":
        text += f" ({meta['unit']})"
    return text.strip()


def _check_range(value: float, meta: dict, node, path, default: float, what: str) -> None:
    """Refuse ``value`` outside its bounds, naming what the field takes (``what``: "a number"
    for a float field, even when the value was written as a whole number)."""
    low, high = _limits(meta, default)
    ok = (value > low if meta.get("gt") is not None else value >= low) and (
        value < high if meta.get("lt") is not None else value <= high
    )
    if not ok:
        got = show(value, 24) if isinstance(value, int) else f"{value:g}"
        raise ScenarioError(
            f"expected {what} {_bounds(meta, default)}, got {got}", node=node, path=path
        )


def _number(node: yaml.ScalarNode, path: str, meta: dict) -> float:
    if node.tag == _STR and node.style is None and _PLAIN_FLOAT.fullmatch(node.value):
        value: Any = float(node.value.replace("_", ""))  # 1e-3 (YAML 1.1 reads a string)
    else:
        value = _scalar(node, path)
    bounds = _bounds(meta, MAX_FLOAT)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ScenarioError(
            f"expected a number {bounds}, got {show(node.value)}", node=node, path=path
        )
    if isinstance(value, float) and math.isnan(value):
        raise ScenarioError(f"expected a number {bounds}, got NaN", node=node, path=path)
    if isinstance(value, float) and math.isinf(value):
        if not meta.get("allow_inf"):
            raise ScenarioError(
                f"expected a finite number {bounds}, got {value}", node=node, path=path
            )
        low, high = _limits(meta, math.inf)
        if not low <= value <= high:
            raise ScenarioError(
                f"expected a number {_bounds(meta)}, got {value}", node=node, path=path
            )
        return value
    _check_representable(value, node, path, f"a number {bounds}")
    _check_range(value, meta, node, path, MAX_FLOAT, "a number")  # exact for huge ints: no overflow
    return float(value)


def _check_representable(value: Any, node: yaml.ScalarNode, path: str, what: str) -> None:
    """Refuse a float written nonzero that is not a normal float: subnormal (1e-320: a
    simulator dividing by it gets infinity) or read as 0 (1e-400)."""
    if isinstance(value, float) and abs(value) < sys.float_info.min:
        if any(c in "123456789" for c in re.split("[eE]", node.value)[0]):
            raise ScenarioError(
                f"expected {what}, got {show(node.value)}: too small, not representable "
                f"(a nonzero magnitude is at least {sys.float_info.min:.4g})",
                node=node,
                path=path,
            )


def _check_length(n: int, meta: dict, node, path, what: str) -> None:
    exact = meta.get("length")
    if exact is not None:
        if n != exact:
            raise ScenarioError(f"expected {what} of {exact}, got {n}", node=node, path=path)
        return
    low = meta.get("min_length") or 0
    high = meta.get("max_length") or (MAX_CHARS if what == "a string" else MAX_ITEMS)
    if not low <= n <= high:
        raise ScenarioError(f"expected {what} of {low} to {high}, got {n}", node=node, path=path)


def build(node: yaml.Node, tp: Any, path: str, meta: dict | None = None) -> Any:
    """Turn a YAML node into a value of type ``tp`` (dataclass, scalar, list, dict)."""
    meta = meta or {}
    if tp is list or tp is tuple:
        tp = list[Any] if tp is list else tuple[Any, ...]
    origin = typing.get_origin(tp)
    if tp is Any:
        return node  # validated later (plug-in params)
    if origin in (typing.Union, types.UnionType):
        args = typing.get_args(tp)
        if type(None) in args and isinstance(node, yaml.ScalarNode) and node.tag.endswith(":null"):
            return None
        tp = next(a for a in args if a is not type(None))
        return build(node, tp, path, meta)
    if isinstance(tp, type) and dataclasses.is_dataclass(tp):
        return build_dataclass(node, tp, path)
    if origin in (list, tuple):
        return _build_list(node, tp, path, meta)
    if origin is dict:
        return _build_dict(node, tp, path, meta)
    if not isinstance(node, yaml.ScalarNode):
        raise ScenarioError(f"expected {_describe(tp)}, got {_kind(node)}", node=node, path=path)
    if tp is float:
        value = _number(node, path, meta)
    else:
        value = _scalar(node, path)
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ScenarioError(
                f"expected a whole number, got {show(node.value)}", node=node, path=path
            )
        _check_range(value, meta, node, path, MAX_INT, "a whole number")
        if meta.get("limit"):
            try:
                check(meta["limit"], value, "the value")
            except LimitError as exc:
                raise ScenarioError(str(exc), node=node, path=path) from None
    elif tp is bool:
        if not isinstance(value, bool):
            raise ScenarioError(
                f"expected true or false, got {show(node.value)}", node=node, path=path
            )
    elif tp is str:
        if not isinstance(value, str):
            raise ScenarioError(f"expected a string, got {show(node.value)}", node=node, path=path)
        _check_length(len(value), meta, node, path, "a string")
        pattern = meta.get("pattern")
        if pattern and not re.fullmatch(pattern, value):
            raise ScenarioError(
                f"expected a name matching {pattern}, got {show(value)}", node=node, path=path
            )
    elif tp is Any or tp is object:
        if isinstance(value, float) and not math.isfinite(value):
            raise ScenarioError(f"expected a finite value, got {value}", node=node, path=path)
        _check_representable(value, node, path, "a finite value")
    if meta.get("choices") and value not in meta["choices"]:
        raise ScenarioError(
            f"expected one of {', '.join(map(str, meta['choices']))}, got {show(value)}",
            node=node,
            path=path,
        )
    return value


def _build_list(node: yaml.Node, tp: Any, path: str, meta: dict) -> list | tuple:
    origin = typing.get_origin(tp)
    if not isinstance(node, yaml.SequenceNode):
        raise ScenarioError(f"expected {_describe(tp)}, got {_kind(node)}", node=node, path=path)
    args = typing.get_args(tp) or (Any,)
    if origin is tuple and len(args) > 1 and args[1] is not Ellipsis:
        meta = {**meta, "length": len(args)}
        item_types = list(args)
    else:
        item_types = [args[0]] * len(node.value)
    _check_length(len(node.value), meta, node, path, "a list")
    item_meta = {k: v for k, v in meta.items() if k not in ("length", "min_length", "max_length")}
    items = []
    for i, (v, t) in enumerate(zip(node.value, item_types)):
        sub = f"{path}[{i}]"
        if t is Any:
            if not isinstance(v, yaml.ScalarNode):
                raise ScenarioError(
                    f"expected a number, string or true/false, got {_kind(v)}", node=v, path=sub
                )
            t = object
        items.append(build(v, t, sub, item_meta))
    return tuple(items) if origin is tuple else items


_KEY = re.compile(r"[A-Za-z_][A-Za-z0-9_-]{0,63}")


def _build_dict(node: yaml.Node, tp: Any, path: str, meta: dict) -> Any:
    if not isinstance(node, yaml.MappingNode):
        raise ScenarioError(f"expected a mapping, got {_kind(node)}", node=node, path=path)
    _, vt = typing.get_args(tp) or (str, Any)
    if vt is Any:
        return node
    _check_length(
        len(node.value), {"max_length": meta.get("max_length") or 32}, node, path, "a mapping"
    )
    out = {}
    for k, v in node.value:
        if not _KEY.fullmatch(k.value):
            raise ScenarioError(
                f"expected a name (letters, digits, _ and -), got {show(k.value)}",
                node=k,
                path=f"{path}.{k.value}",
            )
        if k.value in out:
            raise ScenarioError("given twice", node=k, path=f"{path}.{k.value}")
        out[k.value] = build(v, vt, f"{path}.{k.value}")
    return out


def _kind(node: yaml.Node) -> str:
    if isinstance(node, yaml.MappingNode):
        return "a mapping"
    if isinstance(node, yaml.SequenceNode):
        return "a list"
    if node.tag.endswith(":null"):
        return "nothing (null)"
    return show(node.value)


def build_dataclass(node: yaml.Node, cls: type, path: str) -> Any:
    if isinstance(node, yaml.ScalarNode) and node.tag.endswith(":null"):
        node = yaml.MappingNode(_MAP, [], node.start_mark, node.end_mark)  # "key:" = defaults
    if not isinstance(node, yaml.MappingNode):
        raise ScenarioError(
            f"expected a mapping of {cls.__name__} fields, got {_kind(node)}", node=node, path=path
        )
    hints = typing.get_type_hints(cls)
    fields = {f.name: f for f in dataclasses.fields(cls) if not f.metadata.get("internal")}
    values: dict[str, Any] = {}
    for k, v in node.value:
        key = k.value
        sub = f"{path}.{key}" if path else str(key)
        if key not in fields:
            named = _KEY.fullmatch(str(key))  # else not quoted: another file's text?
            raise ScenarioError(
                f"unknown field {show(key) if named else '(not a name)'} "
                f"(expected one of: {', '.join(fields)})",
                node=k,
                path=sub if named else path or "(top level)",
            )
        if key in values:
            raise ScenarioError("field given twice", node=k, path=sub)
        values[key] = build(v, hints[key], sub, dict(fields[key].metadata))
    for name, f in fields.items():
        required = f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING  # type: ignore[misc]
        if required and name not in values:
            unit = f.metadata.get("unit")
            raise ScenarioError(
                f"missing field {name!r}{' (' + unit + ')' if unit and unit != '1' else ''}",
                node=node,
                path=path or "(top level)",
            )
    try:
        return cls(**values)
    except ParamError as exc:  # a Params __post_init__ check naming its field
        sub = f"{path}.{exc.field}" if path else exc.field
        raise ScenarioError(exc.message, node=node_at(node, exc.field) or node, path=sub) from None
    except (ValueError, TypeError, ArithmeticError) as exc:  # any other Params check
        raise ScenarioError(str(exc), node=node, path=path) from None


# -- scenarios --------------------------------------------------------------------------------


def node_at(root: yaml.Node, path: str) -> yaml.Node | None:
    """The node of a field path (``a.b[2].c``) under ``root``, or None when it is not given."""
    node = root
    for part in re.findall(r"[^.\[\]]+|\[\d+\]", path):
        if part.startswith("["):
            if not isinstance(node, yaml.SequenceNode) or int(part[1:-1]) >= len(node.value):
                return None
            node = node.value[int(part[1:-1])]
            continue
        if not isinstance(node, yaml.MappingNode):
            return None
        found = _get(node, part)
        if found is None:
            return None
        node = found[1]
    return node


def _nearest(root: yaml.Node, path: str) -> yaml.Node:
    """The node of ``path``, else of its nearest given parent, else the root."""
    parts = path.split(".")
    for n in range(len(parts), 0, -1):
        found = node_at(root, ".".join(parts[:n]))
        if found is not None:
            return found
    return root


def plugin_sections(sc: Scenario) -> Iterator[tuple[str, Any, str]]:
    """(kind, section, path) of every plug-in the scenario names (a section added to the
    schema that holds plug-ins, e.g. ``tasks:`` of controllers, is listed here too)."""
    yield "plant", sc.plant, "plant"
    for name, s in sc.sensors.items():
        yield "sensor", s, f"sensors.{name}"
    if sc.controller is not None:
        yield "controller", sc.controller, "controller"
    for name, task in (getattr(sc, "tasks", None) or {}).items():
        yield "controller", task, f"tasks.{name}"


def file_dirs(sc: Scenario) -> dict[str, str]:
    """{plug-in section path: the directory its ``*_file`` parameters resolve against} (the
    internal ``scenario_dir``, which a resolved text does not carry: a sweep's worker gets it
    with the text, :func:`set_file_dirs`)."""
    return {
        path: spec.params.scenario_dir
        for _, spec, path in plugin_sections(sc)
        if getattr(spec.params, "scenario_dir", "")
    }


def set_file_dirs(sc: Scenario, dirs: dict[str, str]) -> None:
    """Give the plug-in sections of ``sc`` (made from a resolved text) the ``file_dirs`` of the
    scenario the text was resolved from."""
    for _, spec, path in plugin_sections(sc):
        if path in dirs and hasattr(spec.params, "scenario_dir"):
            spec.params.scenario_dir = dirs[path]


PLUGIN_MODES = ("import", "installed", "known-only")


def _plugin_class(
    kind: str, spec: Any, path: str, root: yaml.Node, plugins: str
) -> type[Plant | Sensor | Controller] | None:
    """The class of a plug-in section. ``plugins``: "import" imports a ``module:Class`` type
    from the folder of the file that wrote it (the cwd for ``--set`` or a text); "installed"
    finds installed (and already imported) ones only; "known-only" (reading a log) answers None
    for any other, never importing."""
    node = _nearest(root, f"{path}.type")
    if plugins == "known-only" and not registry.known(kind, spec.type):
        return None
    try:
        if plugins == "import" and registry.is_import_path(spec.type):
            written = Path(getattr(node.start_mark, "name", "") or "")
            folder = written.resolve().parent if written.is_file() else Path.cwd()
            return registry.import_plugin(kind, spec.type, folder)
        return registry.load(kind, spec.type)
    except registry.UnknownPlugin as exc:
        raise ScenarioError(str(exc), node=node, path=f"{path}.type") from None


def _resolve_plugins(sc: Scenario, root: yaml.MappingNode, plugins: str = "import") -> Scenario:
    """Replace each plug-in's raw ``params`` node by its validated ``Params`` instance (by
    plain data for a plug-in "known-only" mode does not know)."""
    if (sc.controller is None) == (not sc.tasks):
        raise ScenarioError(
            "give either controller: or tasks:, not " + ("both" if sc.tasks else "neither"),
            node=root,
            path="controller",
        )
    for kind, spec, path in plugin_sections(sc):
        cls = _plugin_class(kind, spec, path, root, plugins)
        if cls is None:  # kept as the log stored it
            raw = spec.params
            spec.params = _scalar(raw, f"{path}.params") if isinstance(raw, yaml.Node) else {}
            continue
        raw = spec.params
        if not isinstance(raw, yaml.Node):  # no params given: all defaults
            raw = yaml.MappingNode(_MAP, [], _nearest(root, path).start_mark, None)
        spec.params = build_dataclass(raw, cls.Params, f"{path}.params")
    # a plug-in whose Params declare an internal ``scenario_dir`` field gets the directory of the
    # file that wrote its file parameters (fields named ``*_file``), so that they resolve relative
    # to that file, not the cwd: a user's file that extends a shipped scenario keeps the shipped
    # scenario's data files (by default: the scenario file's own directory)
    src = Path(str(sc.source)) if sc.source else None
    if src is not None and src.is_file():
        for _, spec, path in plugin_sections(sc):
            if hasattr(spec.params, "scenario_dir") and not isinstance(spec.params, dict):
                spec.params.scenario_dir = str(_files_dir(root, path, spec.params, src))
    return sc


def _files_dir(root: yaml.Node, path: str, params: Any, src: Path) -> Path:
    """The directory of the file that set ``params``' first ``*_file`` field (else ``src``'s)."""
    for f in dataclasses.fields(params):
        if not f.name.endswith("_file"):
            continue
        node = node_at(root, f"{path}.params.{f.name}")
        name = getattr(getattr(node, "start_mark", None), "name", "")
        if node is not None and name and Path(name).is_file():
            return Path(name).resolve().parent
    return src.resolve().parent


def check_timing(sc: Scenario, root: yaml.Node) -> None:
    """Every task rate divides the physics rate; the run has at least one physics step."""
    rate = sc.timing.physics_rate
    if sc.timing.duration * rate < 1:
        raise ScenarioError(
            f"expected at least one physics step (>= {1 / rate:g} s at "
            f"{rate} Hz), got {sc.timing.duration:g} s",
            node=_nearest(root, "timing.duration"),
            path="timing.duration",
        )
    tasks = [
        (f"{path}.rate", spec.rate)
        for kind, spec, path in plugin_sections(sc)
        if kind in ("controller", "sensor")
    ]
    if sc.timing.state_log_rate:
        tasks.append(("timing.state_log_rate", sc.timing.state_log_rate))
    for path, r in tasks:
        ratio = rate / r
        if abs(ratio - round(ratio)) > 1e-9 * max(1.0, ratio) or round(ratio) < 1:
            raise ScenarioError(
                f"expected a rate that divides timing.physics_rate = {rate} Hz, got {r:g} Hz",
                node=_nearest(root, path),
                path=path,
            )


def _load_node(
    root: yaml.MappingNode,
    source: str,
    sets=(),
    seed: int | None = None,
    plugins: str = "import",
) -> Scenario:
    from replay.scenario.log_size import check_log_size
    from replay.scenario.ports import check_ports

    if plugins not in PLUGIN_MODES:
        raise ValueError(f"plugins: expected one of {PLUGIN_MODES}, got {plugins!r}")
    for s in _type_sets_first(sets):
        _apply_set(root, s)
    sc = build_dataclass(root, Scenario, "")
    sc.source = source
    if seed is not None:
        if not 0 <= seed <= 2**63 - 1:
            raise ScenarioError(
                f"expected a seed from 0 to 2^63 - 1, got {show(seed, 24)}",
                path="seed",
                file="--seed",
            )
        sc.seed = seed
    check_timing(sc, root)
    _resolve_plugins(sc, root, plugins)
    if plugins == "known-only":  # a log read back: it ran as it is (its plug-ins may be absent)
        return sc
    check_ports(sc, lambda path: _nearest(root, path))
    try:
        check_log_size(sc)
    except LimitError as exc:  # (duration scales every topic: its line)
        raise ScenarioError(
            str(exc), node=_nearest(root, "timing.duration"), path="timing.duration"
        ) from None
    return sc


def load_scenario(
    path: str | Path, sets: list[str] | tuple = (), seed: int | None = None
) -> Scenario:
    """Read, merge, override and validate a scenario file, or the shipped scenario of a bare
    name (``stick_3step``: :func:`replay.resources.find_scenario`)."""
    from replay.resources import find_scenario

    path = Path(find_scenario(str(path)))
    if not path.is_file():
        raise ScenarioError(
            "no such scenario file (nor a shipped scenario: `replay list` names them)",
            file=str(path),
        )
    inputs: list[Path] = []
    root = _compose_file(path, inputs=inputs)
    sc = _load_node(root, str(path), sets, seed)
    sc.inputs = tuple(inputs)
    return sc


def _plain_name(root: yaml.MappingNode) -> None:
    """A log's stored ``name`` that no scenario here may have (``<img ...>/../x``, from another
    machine or a forged log) read as ``unnamed``: a name is the log's label, not what its
    analysis needs, and the one the reader hands on is bounded and escaped where shown."""
    for i, (key, value) in enumerate(root.value):
        text = value.value if isinstance(value, yaml.ScalarNode) else None
        if key.value == "name" and not (isinstance(text, str) and re.fullmatch(NAME_PATTERN, text)):
            plain = yaml.ScalarNode(_STR, "unnamed", value.start_mark, value.end_mark)
            root.value[i] = (key, plain)


def scenario_from_text(
    text: str,
    name: str = "<log>",
    sets=(),
    seed: int | None = None,
    base_dir: str | Path | None = None,
    plugins: str = "installed",
    resolved: bool = False,
) -> Scenario:
    """A scenario text (e.g. a log's resolved /scenario message) into a Scenario. Its
    ``extends`` is honoured as a file's is: a bare name is a shipped scenario (or NAME.yaml
    in ``base_dir``), a relative path resolves against ``base_dir`` (default: the cwd).
    ``plugins``: "installed" finds installed plug-ins (and ``module:Class`` ones this process
    imported already), importing nothing; "import" imports a ``module:Class`` from the cwd, for a
    text about to run; "known-only" reads a log: a plug-in not available here keeps its
    ``params`` as plain data, and nothing is imported, port-checked or extended (an
    ``extends`` in a log's text is ignored: docs/security.md). ``resolved``: a text that
    :func:`resolved_yaml` wrote in this sweep (a variant's), parsed by libyaml
    (:func:`~replay.scenario.yamlio.compose_resolved`)."""
    root = _compose_root(text, name, resolved=resolved)
    inputs: list[Path] = []
    if plugins == "known-only":  # a log's text is resolved: reading it reads no other file
        _pop(root, "extends")
        _plain_name(root)
    extends = _get(root, "extends") is not None
    where = Path(base_dir if base_dir is not None else Path.cwd()) / "<text>"
    root = _extends(root, where, inputs=inputs)
    sc = _load_node(root, name, sets, seed, plugins)
    if extends:  # file parameters resolve from the file that set them (as for a file)
        for _, spec, path in plugin_sections(sc):
            if getattr(spec.params, "scenario_dir", None) == "":
                spec.params.scenario_dir = str(_files_dir(root, path, spec.params, where))
    sc.inputs = tuple(inputs)
    return sc


def params_from_data(cls: type, data: dict | None, path: str, source: str = "<log>") -> Any:
    """A plug-in's typed ``Params`` (``cls``) from plain data, e.g. ``plant.params`` of a log's
    resolved scenario, checked field by field as a scenario file is. Raises ScenarioError."""
    node = _compose_root(yaml.safe_dump(data or {}), source)
    return build_dataclass(node, cls, path)


def to_plain(value: Any) -> Any:
    """Dataclasses, tuples and lists as plain YAML-ready values, every default filled in."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {
            f.name: to_plain(getattr(value, f.name))
            for f in dataclasses.fields(value)
            if not f.metadata.get("internal")
            and not (f.metadata.get("omit_empty") and not getattr(value, f.name))
        }
    if isinstance(value, (list, tuple)):
        return [to_plain(v) for v in value]
    if isinstance(value, dict):
        return {k: to_plain(v) for k, v in value.items()}
    return value


# libyaml's emitter where PyYAML has it: ~4x faster (a run's set-up paid 6-13 ms for this), the
# same text for every shipped scenario (tests/replay/test_runner_and_log.py compares them)
_DUMPER = getattr(yaml, "CSafeDumper", yaml.SafeDumper)


def resolved_yaml(sc: Scenario) -> str:
    """The scenario as it ran: every default filled in (saved in each log)."""
    return yaml.dump(
        to_plain(sc), Dumper=_DUMPER, sort_keys=False, default_flow_style=None, width=100
    )
