"""Loading scenarios strictly: YAML (safe) -> typed dataclasses, errors with file, line and field.

- ``extends: other.yaml`` (relative to the file) starts from that file; mappings merge key by
  key, anything else is replaced, and a plug-in section whose ``type:`` changes is replaced
  whole.
- ``--set key.path=value`` overrides one field (the value is read as YAML).
- Every plug-in's ``params`` are checked against its ``Params`` dataclass.
- Unknown keys, wrong types, missing fields and out-of-range values raise :class:`ScenarioError`
  naming ``file:line:column``, the field path and what was expected.
"""

from __future__ import annotations

import dataclasses
import types
import typing
from pathlib import Path
from typing import Any

import yaml

from replay import registry
from replay.scenario.schema import Scenario

_SET_SOURCE = "<--set>"


class ScenarioError(Exception):
    def __init__(self, message: str, *, node: yaml.Node | None = None, path: str = "",
                 file: str | None = None) -> None:
        self.message = message
        self.path = path
        if node is not None:
            mark = node.start_mark
            self.where = f"{mark.name}:{mark.line + 1}:{mark.column + 1}"
        else:
            self.where = file or "<scenario>"
        super().__init__(f"{self.where}: {path + ': ' if path else ''}{message}")


# -- reading YAML into node trees ----------------------------------------------------------------

def _compose(text: str, name: str) -> yaml.Node:
    try:
        node = yaml.compose(text, Loader=_NamedLoader.with_name(name))
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark
        where = f"{name}:{mark.line + 1}:{mark.column + 1}" if mark else name
        raise ScenarioError(f"not valid YAML: {exc.problem}", file=where) from None
    if node is None:
        raise ScenarioError("empty scenario", file=name)
    if not isinstance(node, yaml.MappingNode):
        raise ScenarioError("a scenario is a mapping of fields", node=node)
    return node


class _NamedLoader(yaml.SafeLoader):
    source_name = "<string>"

    def __init__(self, stream):
        super().__init__(stream)
        self.name = self.source_name

    @classmethod
    def with_name(cls, name: str):
        return type("NamedLoader", (cls,), {"source_name": name})


def _compose_file(path: Path, seen: tuple[Path, ...] = ()) -> yaml.MappingNode:
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ScenarioError(f"cannot read scenario: {exc.strerror}", file=str(path)) from None
    node = _compose(text, str(path))
    base_node = _pop(node, "extends")
    if base_node is None:
        return node
    if not (isinstance(base_node, yaml.ScalarNode) and base_node.tag.endswith(":str")):
        raise ScenarioError("expected a file name", node=base_node, path="extends")
    base_path = (path.parent / base_node.value).resolve()
    if base_path in seen:
        raise ScenarioError(f"extends loop through {base_path.name}", node=base_node,
                            path="extends")
    if not base_path.is_file():
        raise ScenarioError(f"no such scenario file {base_node.value!r}", node=base_node,
                            path="extends")
    return _merge(_compose_file(base_path, seen + (path.resolve(),)), node)


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
        raise ScenarioError(f"--set expects key.path=value, got {assignment!r}", file=_SET_SOURCE)
    key_path, text = assignment.split("=", 1)
    keys = [k for k in key_path.strip().split(".")]
    if not all(keys):
        raise ScenarioError(f"--set: bad key path {key_path!r}", file=_SET_SOURCE)
    try:
        value = yaml.compose(text if text.strip() else "''",
                             Loader=_NamedLoader.with_name(f"<--set {key_path}>"))
    except yaml.YAMLError:
        raise ScenarioError(f"--set {key_path}: value {text!r} is not valid YAML",
                            file=_SET_SOURCE) from None
    node = root
    for depth, key in enumerate(keys):
        last = depth == len(keys) - 1
        found = _get(node, key)
        if last:
            if found:
                node.value[node.value.index(found)] = (found[0], value)
            else:
                node.value.append((yaml.ScalarNode("tag:yaml.org,2002:str", key,
                                                   value.start_mark, value.end_mark), value))
            return
        if found is None:
            child = yaml.MappingNode("tag:yaml.org,2002:map", [], value.start_mark,
                                     value.end_mark)
            node.value.append((yaml.ScalarNode("tag:yaml.org,2002:str", key, value.start_mark,
                                               value.end_mark), child))
            node = child
        elif isinstance(found[1], yaml.MappingNode):
            node = found[1]
        else:
            raise ScenarioError(f"--set {key_path}: {'.'.join(keys[:depth + 1])} is not a "
                                "mapping", file=_SET_SOURCE)


# -- node trees into typed values ------------------------------------------------------------

def _scalar(node: yaml.Node, path: str) -> Any:
    try:
        return yaml.SafeLoader("").construct_object(node, deep=True)
    except yaml.constructor.ConstructorError as exc:
        raise ScenarioError(f"not allowed: {exc.problem} (scenarios are data, not code)",
                            node=node, path=path) from None


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


def _bounds(meta) -> str:
    parts = []
    for key, sym in (("ge", ">="), ("gt", ">"), ("le", "<="), ("lt", "<")):
        if meta.get(key) is not None:
            parts.append(f"{sym} {meta[key]:g}")
    text = " and ".join(parts)
    if meta.get("unit") and meta["unit"] != "1":
        text += f" ({meta['unit']})"
    return text.strip()


def _check_range(value: float, meta, node, path) -> None:
    ok = ((meta.get("ge") is None or value >= meta["ge"]) and
          (meta.get("gt") is None or value > meta["gt"]) and
          (meta.get("le") is None or value <= meta["le"]) and
          (meta.get("lt") is None or value < meta["lt"]))
    if not ok:
        raise ScenarioError(f"expected a number {_bounds(meta)}, got {value:g}", node=node,
                            path=path)


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
    if dataclasses.is_dataclass(tp):
        return build_dataclass(node, tp, path)
    if origin in (list, tuple):
        if not isinstance(node, yaml.SequenceNode):
            raise ScenarioError(f"expected {_describe(tp)}, got {_kind(node)}", node=node,
                                path=path)
        args = typing.get_args(tp) or (Any,)
        n = meta.get("length")
        if n is not None and len(node.value) != n:
            raise ScenarioError(f"expected a list of {n} items, got {len(node.value)}",
                                node=node, path=path)
        if origin is tuple and len(args) > 1 and args[1] is not Ellipsis:
            if len(node.value) != len(args):
                raise ScenarioError(f"expected a list of {len(args)} items, got "
                                    f"{len(node.value)}", node=node, path=path)
            item_types = args
        else:
            item_types = [args[0]] * len(node.value)
        items = [_scalar(v, f"{path}[{i}]") if t is Any else
                 build(v, t, f"{path}[{i}]", {**meta, "length": None})
                 for i, (v, t) in enumerate(zip(node.value, item_types))]
        return tuple(items) if origin is tuple else items
    if origin is dict:
        if not isinstance(node, yaml.MappingNode):
            raise ScenarioError(f"expected a mapping, got {_kind(node)}", node=node, path=path)
        _, vt = typing.get_args(tp) or (str, Any)
        if vt is Any:
            return node
        return {k.value: build(v, vt, f"{path}.{k.value}") for k, v in node.value}
    if not isinstance(node, yaml.ScalarNode):
        raise ScenarioError(f"expected {_describe(tp)}, got {_kind(node)}", node=node, path=path)
    value = _scalar(node, path)
    if tp is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ScenarioError(f"expected a number{' ' + _bounds(meta) if _bounds(meta) else ''}"
                                f", got {node.value!r}", node=node, path=path)
        value = float(value)
        _check_range(value, meta, node, path)
    elif tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ScenarioError(f"expected a whole number, got {node.value!r}", node=node,
                                path=path)
        _check_range(value, meta, node, path)
    elif tp is bool:
        if not isinstance(value, bool):
            raise ScenarioError(f"expected true or false, got {node.value!r}", node=node,
                                path=path)
    elif tp is str:
        if not isinstance(value, str):
            raise ScenarioError(f"expected a string, got {node.value!r}", node=node, path=path)
    if meta.get("choices") and value not in meta["choices"]:
        raise ScenarioError(f"expected one of {', '.join(map(str, meta['choices']))}, got "
                            f"{value!r}", node=node, path=path)
    return value


def _kind(node: yaml.Node) -> str:
    if isinstance(node, yaml.MappingNode):
        return "a mapping"
    if isinstance(node, yaml.SequenceNode):
        return "a list"
    return repr(node.value)


def build_dataclass(node: yaml.Node, cls: type, path: str) -> Any:
    if not isinstance(node, yaml.MappingNode):
        raise ScenarioError(f"expected a mapping of {cls.__name__} fields, got {_kind(node)}",
                            node=node, path=path)
    hints = typing.get_type_hints(cls)
    fields = {f.name: f for f in dataclasses.fields(cls) if not f.metadata.get("internal")}
    values: dict[str, Any] = {}
    for k, v in node.value:
        key = k.value
        sub = f"{path}.{key}" if path else str(key)
        if key not in fields:
            raise ScenarioError(f"unknown field {key!r} (expected one of: "
                                f"{', '.join(fields)})", node=k, path=sub)
        if key in values:
            raise ScenarioError("field given twice", node=k, path=sub)
        values[key] = build(v, hints[key], sub, dict(fields[key].metadata))
    for name, f in fields.items():
        required = (f.default is dataclasses.MISSING and
                    f.default_factory is dataclasses.MISSING)  # type: ignore[misc]
        if required and name not in values:
            unit = f.metadata.get("unit")
            raise ScenarioError(f"missing field {name!r}"
                                f"{' (' + unit + ')' if unit and unit != '1' else ''}",
                                node=node, path=path or "(top level)")
    try:
        return cls(**values)
    except (ValueError, TypeError) as exc:  # a Params __post_init__ check
        raise ScenarioError(str(exc), node=node, path=path) from None


# -- scenarios --------------------------------------------------------------------------------

def _node_at(root: yaml.Node, path: str) -> yaml.Node | None:
    node = root
    for key in path.split("."):
        if not isinstance(node, yaml.MappingNode):
            return None
        found = _get(node, key)
        if found is None:
            return None
        node = found[1]
    return node


def _resolve_plugins(sc: Scenario, root: yaml.MappingNode) -> Scenario:
    """Replace each plug-in's raw ``params`` node by its validated ``Params`` instance."""
    def params_of(kind: str, spec, path: str):
        try:
            cls = registry.load(kind, spec.type)
        except registry.UnknownPlugin as exc:
            raise ScenarioError(str(exc), node=_node_at(root, f"{path}.type"),
                                path=f"{path}.type") from None
        raw = spec.params
        if not isinstance(raw, yaml.Node):  # no params given: all defaults
            raw = yaml.MappingNode("tag:yaml.org,2002:map", [],
                                   (_node_at(root, path) or root).start_mark, None)
        return build_dataclass(raw, cls.Params, f"{path}.params")

    sc.plant.params = params_of("plant", sc.plant, "plant")
    sc.controller.params = params_of("controller", sc.controller, "controller")
    for name, s in sc.sensors.items():
        s.params = params_of("sensor", s, f"sensors.{name}")
    return sc


def check_rates(sc: Scenario, node: yaml.Node | None = None) -> None:
    rate = sc.timing.physics_rate
    tasks = [("controller.rate", sc.controller.rate)]
    tasks += [(f"sensors.{n}.rate", s.rate) for n, s in sc.sensors.items()]
    if sc.timing.state_log_rate:
        tasks.append(("timing.state_log_rate", sc.timing.state_log_rate))
    for path, r in tasks:
        ratio = rate / r
        if abs(ratio - round(ratio)) > 1e-9 or round(ratio) < 1:
            raise ScenarioError(f"expected a rate that divides timing.physics_rate = {rate} Hz, "
                                f"got {r:g} Hz", node=node, path=path)


def _load_node(root: yaml.MappingNode, source: str, sets=(), seed: int | None = None) -> Scenario:
    for s in sets:
        _apply_set(root, s)
    sc = build_dataclass(root, Scenario, "")
    sc.source = source
    if seed is not None:
        if seed < 0:
            raise ScenarioError(f"expected a seed >= 0, got {seed}", path="seed")
        sc.seed = seed
    check_rates(sc, root)
    return _resolve_plugins(sc, root)


def load_scenario(path: str | Path, sets: list[str] | tuple = (), seed: int | None = None
                  ) -> Scenario:
    """Read, merge, override and validate a scenario file."""
    path = Path(path)
    if not path.is_file():
        raise ScenarioError("no such scenario file", file=str(path))
    return _load_node(_compose_file(path), str(path), sets, seed)


def scenario_from_text(text: str, name: str = "<log>", sets=(), seed: int | None = None
                       ) -> Scenario:
    """A resolved scenario text (e.g. from a log's /scenario message) back into a Scenario."""
    root = _compose(text, name)
    _pop(root, "extends")
    return _load_node(root, name, sets, seed)


def params_from_data(cls: type, data: dict | None, path: str, source: str = "<log>") -> Any:
    """A plug-in's typed ``Params`` (``cls``) from plain data, e.g. ``plant.params`` of a log's
    resolved scenario, checked field by field as a scenario file is. Raises ScenarioError."""
    node = _compose(yaml.safe_dump(data or {}), source)
    return build_dataclass(node, cls, path)


def to_plain(value: Any) -> Any:
    """Dataclasses, tuples and lists as plain YAML-ready values, every default filled in."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: to_plain(getattr(value, f.name)) for f in dataclasses.fields(value)
                if not f.metadata.get("internal")}
    if isinstance(value, (list, tuple)):
        return [to_plain(v) for v in value]
    if isinstance(value, dict):
        return {k: to_plain(v) for k, v in value.items()}
    return value


def resolved_yaml(sc: Scenario) -> str:
    """The scenario as it ran: every default filled in (saved in each log)."""
    return yaml.safe_dump(to_plain(sc), sort_keys=False, default_flow_style=None, width=100)
