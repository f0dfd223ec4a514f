"""Frozen dataclasses whose __init__ is written by hand for speed (the generated one sets each
field through object.__setattr__, ~1 us a field on Python 3.11): the stick planner's Motion here;
the stick controller's StickEstimate, ContactSolution and Config in
tests/replay/control/stick/test_stick_fast_paths.py. (replay.scene's primitives and frames and the
stick hand's HandCommand went back to the generated __init__: a whole run differed by 0.2-0.5 %
in instructions.) Each must be what dataclasses generates:
the same signature (names, order, defaults), the same instance, equal and hashing alike, still
frozen, and dataclasses.replace works."""

import dataclasses
import inspect

import numpy as np
import pytest

from replay.control.stick.coverage import Motion


def assert_generated_init(cls, rng, n: int = 20) -> None:
    """``cls.__init__`` against the one dataclasses makes for the same fields (float values)."""
    fields = dataclasses.fields(cls)
    ref = dataclasses.make_dataclass(
        "Ref",
        [
            (f.name, f.type)
            if f.default is dataclasses.MISSING
            else (f.name, f.type, dataclasses.field(default=f.default))
            for f in fields
        ],
        frozen=True,
    )
    params = list(inspect.signature(cls.__init__).parameters.values())[1:]
    assert [p.name for p in params] == [f.name for f in fields]
    assert [p.default for p in params] == [
        inspect.Parameter.empty if f.default is dataclasses.MISSING else f.default for f in fields
    ]
    for _ in range(n):
        values = [float(v) for v in rng.normal(size=len(fields))]
        a, b = cls(*values), ref(*values)
        assert vars(a) == vars(b) and a == cls(**vars(b)) and hash(a) == hash(cls(*values))
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(a, fields[0].name, 1.0)
        assert dataclasses.replace(a, **{fields[0].name: 2.0}) == cls(2.0, *values[1:])
        if len(fields) > 1 and fields[-1].default is not dataclasses.MISSING:
            assert vars(cls(*values[:-1])) == vars(ref(*values[:-1]))  # the default


@pytest.mark.parametrize("cls", [Motion])
def test_hand_written_inits_are_the_generated_ones(cls):
    assert_generated_init(cls, np.random.default_rng(3))
