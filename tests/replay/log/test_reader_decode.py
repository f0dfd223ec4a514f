"""A log's message reads as ``json.loads`` reads it, whichever decoder reads it (orjson first,
the standard one for what orjson refuses or reads otherwise)."""

from __future__ import annotations

import json

import pytest

from replay.log.reader import _decode


def _reference(data: bytes):
    try:
        value = json.loads(data)
    except (ValueError, UnicodeDecodeError, RecursionError):
        return None
    return value if isinstance(value, dict) else None


@pytest.mark.parametrize(
    "data",
    [
        b'{"t":0.001,"q":[1,2,3e-7],"kind":"contact","n":-0.0}',
        b'{"big":123456789012345678901234567890}',  # (orjson would make it a float)
        b'{"u64":18446744073709551615,"i64":-9223372036854775808}',
        b'{"a":[0,-123456789012345678901],"b":{"c":123456789012345678901.5}}',
        b'{"small":0.000050523696124472624,"f":-1.23456789012345678901234e-5}',  # (orjson)
        b'{"s":"x123456789012345678901"}',
        b'{"x":NaN,"y":-Infinity}',
        '{"a":"\u00e9"}'.encode("utf-16"),
        b'{"a":"\\ud800"}',
        b'{"a":1,"a":2}',
        b'{"a":1e400}',
        b"\xef\xbb\xbf{}",
        b"[1]",
        b"{" * 5000,
        b'{"a":1} x',
        b"\xff",
    ],
)
def test_a_message_reads_as_the_standard_decoder_reads_it(data):
    got, want = _decode(data), _reference(data)
    assert repr(got) == repr(want)  # (repr: NaN, -0.0 and the types alike)
