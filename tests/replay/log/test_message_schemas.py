"""Message schemas come from the payload types (replay.messages.json_schema): precise (arrays
with items and lengths, optional fields, enums, nested dataclasses), never empty, and every
message of a real run of each paper validates against its channel's schema."""

from __future__ import annotations

import enum
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, Literal

import jsonschema
import pytest
from mcap.reader import make_reader

from replay.messages import TOPICS, Length, OneOf, Vec3, json_schema, type_schema
from replay.runner import Runner
from replay.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[3]
# one run of each paper, cut short but long enough that every topic appears (the catch: vision
# and the mapping's state from ~0.05 s; the grasp: the object found, the loops running)
RUNS = {
    "stick_3step": ["timing.duration=0.3"],
    "catch_optimised": ["timing.duration=0.3", "timing.state_log_rate=250"],
    "grasp_hexahedron": ["timing.duration=0.4"],
}


def loose_parts(schema: Any, where: str = "") -> list[str]:
    """Where a schema says nothing: an empty schema, an array without item types, an object
    without properties (unless it says that any property is allowed)."""
    if schema is True or schema == {}:
        return [where or "(root)"]
    if not isinstance(schema, dict):
        return []
    out = []
    if schema.get("type") == "array" and "items" not in schema and "prefixItems" not in schema:
        out.append(f"{where}: array without items")
    if (
        schema.get("type") == "object"
        and not schema.get("properties")
        and "additionalProperties" not in schema
    ):
        out.append(f"{where}: object without properties")
    for name, sub in schema.get("properties", {}).items():
        out += loose_parts(sub, f"{where}.{name}")
    for key in ("items", "additionalProperties"):
        if isinstance(schema.get(key), dict) and schema[key]:
            out += loose_parts(schema[key], f"{where}[]")
    for key in ("anyOf", "prefixItems"):
        for i, sub in enumerate(schema.get(key, [])):
            if sub.get("type") != "null" and set(sub) - {"minItems", "maxItems"}:
                out += loose_parts(sub, f"{where}<{i}>")
    return out


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    out = {}
    for name, sets in RUNS.items():
        path = tmp_path_factory.mktemp("schemas") / f"{name}.mcap"
        Runner(load_scenario(ROOT / f"scenarios/{name}.yaml", sets=sets)).run(path)
        out[name] = path
    return out


@pytest.mark.parametrize("paper_run", list(RUNS))
def test_every_message_of_a_run_validates_and_no_schema_is_loose(logs, paper_run):
    validators, counts, failures = {}, {}, []
    with open(logs[paper_run], "rb") as f:
        for schema, channel, message in make_reader(f).iter_messages():
            topic = channel.topic
            if channel.message_encoding != "json":
                continue  # well-known schemas (e.g. Foxglove's, as Protobuf) decode themselves
            if topic not in validators:
                assert schema.encoding == "jsonschema", topic
                doc = json.loads(schema.data)
                jsonschema.Draft202012Validator.check_schema(doc)
                assert doc.get("properties"), f"{topic}: empty schema {doc}"
                assert not loose_parts(doc), f"{topic}: {loose_parts(doc)}"
                validators[topic] = jsonschema.Draft202012Validator(doc)
            counts[topic] = counts.get(topic, 0) + 1
            err = jsonschema.exceptions.best_match(
                validators[topic].iter_errors(json.loads(message.data))
            )
            if err is not None and len(failures) < 5:
                failures.append(f"{topic} at {message.log_time} ns: {err.message} {err.json_path}")
    assert not failures, failures
    # the topics that used to have empty schemas are there (and checked above)
    expected = {
        "stick_3step": {"/control/stick_estimate", "/hand/state", "/fingers/state"},
        "catch_optimised": {"/vision/object", "/catching/state", "/object/contacts"},
        "grasp_hexahedron": {"/grasping/object", "/grasping/arm", "/tasks/loops", "/vision/chip"},
    }[paper_run]
    assert expected <= set(counts), sorted(counts)


def test_contract_types_give_precise_schemas():
    for topic, cls in TOPICS.items():
        doc = json_schema(cls)
        jsonschema.Draft202012Validator.check_schema(doc)
        assert doc["properties"] and not loose_parts(doc), (topic, loose_parts(doc))


class Mode(enum.Enum):
    A = "a"
    B = "b"


@dataclass
class Inner:
    p: Vec3
    label: Literal["x", "y"]


@dataclass
class Outer:
    t: float
    inner: Inner
    inners: list[Inner]
    pair: tuple[int, str]
    maybe: float | None
    mode: Mode
    pose: Annotated[list[float], Length(6, empty=True)]
    gains: dict[str, list[float]]
    extra: dict[str, Any]
    kind: Annotated[str, OneOf("p", "q")]
    note: str = ""


def test_type_schema_shapes():
    doc = json_schema(Outer)
    assert doc["required"] == [
        "t",
        "inner",
        "inners",
        "pair",
        "maybe",
        "mode",
        "pose",
        "gains",
        "extra",
        "kind",
    ]
    props = doc["properties"]
    assert props["inner"]["properties"]["p"] == {
        "type": "array",
        "items": {"type": "number"},
        "minItems": 3,
        "maxItems": 3,
    }
    assert props["inner"]["properties"]["label"] == {"enum": ["x", "y"]}
    assert props["inners"]["items"]["title"] == "Inner"
    assert props["pair"]["prefixItems"] == [{"type": "integer"}, {"type": "string"}]
    assert props["mode"] == {"enum": ["a", "b"]}
    v = jsonschema.Draft202012Validator(doc)
    good = {
        "t": 0.5,
        "inner": {"p": [1, 2, 3.5], "label": "x"},
        "inners": [],
        "pair": [1, "a"],
        "maybe": None,
        "mode": "b",
        "pose": [],
        "gains": {"kp": [1.0, 2.0]},
        "extra": {"anything": [1, "two"]},
        "kind": "q",
    }
    assert v.is_valid(good)
    for key, bad in (
        ("inner", {"p": [1, 2], "label": "x"}),  # a 3-vector of 2
        ("inner", {"p": [1, 2, 3], "label": "z"}),  # not one of the literals
        ("pair", [1, 2]),
        ("maybe", "1.0"),
        ("mode", "c"),
        ("pose", [0.0, 1.0]),  # neither [] nor 6 numbers
        ("gains", {"kp": ["1"]}),
        ("t", True),
        ("kind", "r"),
    ):
        assert not v.is_valid({**good, key: bad}), (key, bad)
    assert not v.is_valid({k: x for k, x in good.items() if k != "inner"})
    assert v.is_valid({**good, "pose": [0.0] * 6})


def test_a_bare_list_is_loose_and_the_check_says_so():
    assert type_schema(list) == {"type": "array"}
    assert loose_parts({"type": "object", "properties": {"x": type_schema(list)}}) == [
        ".x: array without items"
    ]
    assert loose_parts({"title": "t", "type": "object"}) == [": object without properties"]
