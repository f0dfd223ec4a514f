"""The log's JSON encoding (replay/log/writer.py ``encode``): the standard encoder's values, the
same bytes for the same payload, and non-finite numbers refused."""

import json
import math

import numpy as np
import pytest

from replay.log import NonFiniteValueError
from replay.log.writer import encode
from replay.messages import Event, JointState, StickState, to_dict


PAYLOADS = [
    StickState(0.1, 1.0, -2.5e-5, 3.141592653589793, 1e300, -0.0, 7),
    JointState(0.2, ["J1", "J2"], [0.1, 0.2], [1e-12, -3.0], [0.0, 5.5]),
    Event(
        0.3,
        "collision",
        {
            "index": 1,
            "planned": {"r_x": 0.0257},
            "ok": True,
            "none": None,
            "tuple": (1, 2.5),
            7: "int key",
        },
    ),
    {"t": 0.4, "base": [0.1, 0.2], "numpy": np.float64(0.3), "text": 'é "q" \n'},
]


@pytest.mark.parametrize("payload", PAYLOADS, ids=lambda p: type(p).__name__)
def test_encode_decodes_to_the_standard_encoders_values(payload):
    data = encode("/x", payload)
    standard = json.dumps(to_dict(payload), allow_nan=False, separators=(",", ":"))
    assert json.loads(data) == json.loads(standard)
    assert encode("/x", payload) == data  # deterministic bytes


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf, np.float64("nan")])
def test_non_finite_values_are_refused_with_their_field(bad):
    with pytest.raises(NonFiniteValueError) as err:
        encode("/stick/state", StickState(0.0, 1.0, bad, 0.0, 0.0, 0.0, 0.0))
    assert err.value.fields == ["y"]
    with pytest.raises(NonFiniteValueError):
        encode("/events", Event(0.0, "x", {"deep": [1.0, {"v": bad}]}))


@pytest.mark.parametrize("bad", [math.nan, math.inf])
def test_non_finite_values_beside_nulls_and_in_nested_payloads_are_refused(bad):
    """orjson writes NaN as null: a message that holds real nulls too is still checked."""
    inner = StickState(0.0, 1.0, 2.0, 0.0, 0.0, 0.0, bad)
    for payload in (
        {"t": 0.0, "none": None, "inner": inner},
        Event(0.0, "x", {"none": None, "v": (1.0, [None, bad])}),
    ):
        with pytest.raises(NonFiniteValueError):
            encode("/x", payload)
    fine = Event(0.0, "x", {"none": None, "v": (1.0, [None, 2.0]), "s": "null"})
    assert json.loads(encode("/x", fine))["data"]["none"] is None


def _random_payload(rng, depth=0):
    """A random payload of what messages hold: floats (sometimes NaN or infinite), ints, bools,
    None, strings, lists, tuples, dicts and payload dataclasses."""
    kind = int(rng.integers(0, 9 if depth < 3 else 5))
    if kind == 0:
        return float(rng.choice([math.nan, math.inf, -math.inf])) if rng.random() < 0.1 else 0.5
    if kind == 1:
        return int(rng.integers(-5, 5))
    if kind == 2:
        return bool(rng.random() < 0.5)
    if kind == 3:
        return None
    if kind == 4:
        return "text"
    items = [_random_payload(rng, depth + 1) for _ in range(int(rng.integers(0, 5)))]
    if kind == 5:
        return items
    if kind == 6:
        return tuple(items)
    if kind == 7:
        return {f"k{i}": v for i, v in enumerate(items)}
    return Event(0.1, "x", {"v": items})
