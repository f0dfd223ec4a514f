"""The scenario format as a JSON Schema (``replay schema``), for editors that complete and check
YAML (VS Code's YAML extension, any yaml-language-server client; docs/cli.md says how).

Made from the same dataclasses the loader validates against (:mod:`replay.scenario.schema` and
each plug-in's ``Params``): every field with its type, unit, range, default and meaning; the
plug-in ``type:`` names as enums; a plug-in's ``params:`` checked against that plug-in's own
``Params`` once its ``type:`` is known. A file with ``extends:`` is checked with nothing
required (it overrides only what changes). Draft 7, which editors support best.

The loader stays the authority: it also checks what a JSON Schema cannot say (a rate that divides
the physics rate, a list as long as the arm, the ports between plug-ins). What the loader accepts
validates here too (a test runs every shipped scenario through both).
"""

from __future__ import annotations

import dataclasses
import math
import types
import typing
from typing import Any

from replay import registry
from replay.params import MAX_CHARS, MAX_FLOAT, MAX_INT, MAX_ITEMS
from replay.scenario.loader import _KEY
from replay.scenario.schema import ControllerSpec, PlantSpec, Scenario, SensorSpec, TaskSpec

DRAFT = "http://json-schema.org/draft-07/schema#"
SCHEMA_ID = "https://paper-replay.invalid/scenario.schema.json"  # a name, not fetched
MAX_MAPPING = 32  # names in a mapping such as sensors: (the loader's limit)
_SCALAR = {"type": ["number", "string", "boolean", "null"]}  # an item of a bare ``list``
_PLUGIN_KIND = {PlantSpec: "plant", SensorSpec: "sensor", ControllerSpec: "controller"}
_PLUGIN_KIND[TaskSpec] = "controller"  # a task is a controller plug-in


def scenario_schema() -> dict[str, Any]:
    """The JSON Schema of a scenario file, with every installed plug-in's params."""
    gen = _Generator()
    full = gen.dataclass(Scenario, required=True)
    full["anyOf"] = [{"required": ["controller"]}, {"required": ["tasks"]}]
    partial = gen.dataclass(Scenario, required=False)
    for variant in (full, partial):
        variant["properties"]["extends"] = {
            "type": "string",
            "minLength": 1,
            "description": "a scenario file (relative to this one) to start from: mappings "
            "merge key by key, a plug-in section whose type: changes is replaced whole",
        }
    return {
        "$schema": DRAFT,
        "$id": SCHEMA_ID,
        "title": "paper-replay scenario",
        "description": "A scenario: the plant, its sensors and the paper's method "
        "(docs/scenarios.md lists every field). SI units.",
        "type": "object",
        "if": {"required": ["extends"]},
        "then": {"$ref": "#/definitions/extending"},
        "else": {"$ref": "#/definitions/scenario"},
        "definitions": {"scenario": full, "extending": partial, **gen.definitions},
    }


class _Generator:
    def __init__(self) -> None:
        self.definitions: dict[str, Any] = {}

    def dataclass(self, cls: type, *, required: bool) -> dict[str, Any]:
        hints = typing.get_type_hints(cls)
        props: dict[str, Any] = {}
        needed = []
        for f in dataclasses.fields(cls):
            if f.metadata.get("internal"):
                continue
            props[f.name] = self.field(hints[f.name], f, required)
            no_default = f.default is dataclasses.MISSING
            if no_default and f.default_factory is dataclasses.MISSING:  # type: ignore[misc]
                needed.append(f.name)
        out: dict[str, Any] = {
            "title": cls.__name__,
            "type": "object",
            "properties": props,
            "additionalProperties": False,
        }
        doc = (cls.__doc__ or "").strip()
        if doc and not doc.startswith(f"{cls.__name__}("):  # not the dataclass's own repr text
            out["description"] = " ".join(doc.split())
        if required and needed:
            out["required"] = needed
        kind = _PLUGIN_KIND.get(cls)
        if kind:
            self._plugin_section(out, kind, required)
        return out

    def _plugin_section(self, out: dict[str, Any], kind: str, required: bool) -> None:
        """``type:`` as the enum of installed plug-ins; ``params:`` by that plug-in's Params."""
        names = registry.names(kind)
        rules, docs = [], []
        for name in names:
            try:
                cls = registry.load(kind, name)
                params_cls = cls.Params
            except Exception:  # noqa: BLE001 - a broken plug-in: its params stay unchecked here
                docs.append("")
                continue
            first = ((cls.__doc__ or "").strip().splitlines() or [""])[0]
            docs.append(getattr(cls, "description", "") or first)
            key = f"{kind}.{name}"
            if key not in self.definitions:
                self.definitions[key] = self.dataclass(params_cls, required=True)
            if not required:  # the same unless some field is required
                partial = self.dataclass(params_cls, required=False)
                if partial != self.definitions[key]:
                    key += ".partial"
                    self.definitions[key] = partial
            rules.append(
                {
                    "if": {"properties": {"type": {"const": name}}, "required": ["type"]},
                    "then": {"properties": {"params": {"$ref": f"#/definitions/{key}"}}},
                }
            )
        # an installed plug-in's name (enumDescriptions: shown by VS Code's YAML extension next
        # to each completion), or a plug-in's import path, module:Class (its params unchecked here)
        out["properties"]["type"] = {
            **out["properties"]["type"],
            "anyOf": [
                {"enum": names, "enumDescriptions": docs},
                {"pattern": f"^{registry.IMPORT_PATH}$", "description": "module:Class"},
            ],
        }
        if rules:
            out["allOf"] = rules

    def field(self, tp: Any, f: dataclasses.Field, required: bool) -> dict[str, Any]:
        meta = dict(f.metadata)
        out = self.type(tp, meta, required)
        text = meta.get("doc", "")
        unit = meta.get("unit", "")
        if unit and unit != "1":
            text = f"{text} [{unit}]" if text else f"[{unit}]"
        if text:
            out["description"] = text
        default = _default(f)
        if default is not dataclasses.MISSING:
            out["default"] = default
        return out

    def type(self, tp: Any, meta: dict, required: bool) -> dict[str, Any]:
        """The schema of a value of type ``tp`` as the loader checks it (replay.scenario.loader.build)."""
        if tp is list or tp is tuple:
            tp = list[Any]
        origin = typing.get_origin(tp)
        args = typing.get_args(tp)
        if origin in (typing.Union, types.UnionType):
            inner = [a for a in args if a is not type(None)]
            schema = self.type(inner[0], meta, required)
            if type(None) in args:
                return {"anyOf": [schema, {"type": "null"}]}
            return schema
        if dataclasses.is_dataclass(tp):
            section = self.dataclass(tp, required=required)  # type: ignore[arg-type]
            section["type"] = ["object", "null"]  # "timing:" alone = every default
            return section
        if origin in (list, tuple):
            return self._list(tp, meta, required)
        if origin is dict:
            value_type = args[1] if args else Any
            if value_type is Any:  # a plug-in's params: checked by the plug-in section
                return {"type": "object"}
            return {
                "type": "object",
                "propertyNames": {"pattern": f"^(?:{_KEY.pattern})$"},
                "maxProperties": meta.get("max_length") or MAX_MAPPING,
                "additionalProperties": self.type(value_type, {}, required),
            }
        out: dict[str, Any]
        if tp is float:
            out = {"type": "number", **_bounds(meta, None if meta.get("allow_inf") else MAX_FLOAT)}
        elif tp is int:
            out = {"type": "integer", **_bounds(meta, MAX_INT)}
        elif tp is bool:
            out = {"type": "boolean"}
        elif tp is str:
            out = {"type": "string", "maxLength": meta.get("max_length") or MAX_CHARS}
            if meta.get("min_length"):
                out["minLength"] = meta["min_length"]
            if meta.get("pattern"):
                out["pattern"] = f"^(?:{meta['pattern']})$"
        else:  # Any / object: a scalar
            out = dict(_SCALAR)
        if meta.get("choices"):
            out["enum"] = list(meta["choices"])
        return out

    def _list(self, tp: Any, meta: dict, required: bool) -> dict[str, Any]:
        origin, args = typing.get_origin(tp), typing.get_args(tp) or (Any,)
        item_meta = {
            k: v for k, v in meta.items() if k not in ("length", "min_length", "max_length")
        }
        out: dict[str, Any] = {"type": "array"}
        if origin is tuple and len(args) > 1 and args[1] is not Ellipsis:
            out["items"] = [self._item(a, item_meta, required) for a in args]
            out["minItems"] = out["maxItems"] = len(args)
            return out
        out["items"] = self._item(args[0], item_meta, required)
        if meta.get("length") is not None:
            out["minItems"] = out["maxItems"] = meta["length"]
        else:
            if meta.get("min_length"):
                out["minItems"] = meta["min_length"]
            out["maxItems"] = meta.get("max_length") or MAX_ITEMS
        return out

    def _item(self, tp: Any, meta: dict, required: bool) -> dict[str, Any]:
        if tp is Any:
            out = dict(_SCALAR)
            if meta.get("choices"):
                out["enum"] = list(meta["choices"])
            return out
        return self.type(tp, meta, required)


def _bounds(meta: dict, default: float | None) -> dict[str, float]:
    """The loader's range of a number: its own bounds, else +-default (draft-7 keywords)."""
    out: dict[str, float] = {}
    for key, word in (
        ("ge", "minimum"),
        ("gt", "exclusiveMinimum"),
        ("le", "maximum"),
        ("lt", "exclusiveMaximum"),
    ):
        if meta.get(key) is not None:
            out[word] = meta[key]
    if default is not None:
        if "minimum" not in out and "exclusiveMinimum" not in out:
            out["minimum"] = -default
        if "maximum" not in out and "exclusiveMaximum" not in out:
            out["maximum"] = default
    return out


def _default(f: dataclasses.Field) -> Any:
    if f.default is not dataclasses.MISSING:
        value = f.default
    elif f.default_factory is not dataclasses.MISSING:  # type: ignore[misc]
        value = f.default_factory()  # type: ignore[misc]
    else:
        return dataclasses.MISSING
    if dataclasses.is_dataclass(value) or not _plain(value):
        return dataclasses.MISSING
    return list(value) if isinstance(value, tuple) else value


def _plain(value: Any) -> bool:
    """JSON-ready (finite numbers, strings, lists and mappings of them)."""
    if value is None or isinstance(value, (bool, int, str)):
        return True
    if isinstance(value, float):
        return math.isfinite(value)
    if isinstance(value, (list, tuple)):
        return all(_plain(v) for v in value)
    if isinstance(value, dict):
        return all(isinstance(k, str) and _plain(v) for k, v in value.items())
    return False
