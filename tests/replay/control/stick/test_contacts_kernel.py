"""The compiled contact solver (``_contacts.options`` behind collision.contact_options) against
its Python reference (collision.contact_options_reference): on seeded random sticks, velocities,
orientations and targets, both sides or one, by spin or by speed, e = 0 included, the same
solutions to the bit (the planner's closed loop is sensitive to the last bit of a root)."""

import math

import numpy as np

from replay.control.stick import collision as sc


def random_case(rng):
    m = float(rng.uniform(0.005, 0.1))
    inertia = float(m * rng.uniform(0.02, 0.2) ** 2 / 12.0)
    e = float(rng.choice([0.0, 1.0, rng.uniform(0.0, 1.0)]))
    u = [float(v) for v in rng.normal(0.0, 1.0, 3) * (1.0, 1.0, 10.0)]
    for i in range(3):  # now and then a component exactly 0 (a stick at rest: all three)
        if rng.uniform() < 0.07:
            u[i] = 0.0
    theta = (
        sc.alpha(u[:2]) if rng.uniform() < 0.7 else float(rng.uniform(-math.pi, math.pi))
    )  # mostly friction independent, as the strategies use it
    kw = {"length": float(rng.uniform(0.05, 0.2))} if rng.uniform() < 0.8 else {}
    if rng.uniform() < 0.5:
        kw["omega"] = float(rng.choice([0.0, rng.normal(0.0, 10.0)]))
    else:
        kw["speed"] = float(rng.choice([0.0, abs(rng.normal(0.0, 1.0))]))
    if rng.uniform() < 0.3:
        kw["sides"] = (int(rng.choice([1, -1])),)
    return (m, inertia, e, theta, tuple(u)), kw


def test_contact_options_equal_the_reference_over_random_cases():
    rng = np.random.default_rng(17)
    n, solved, pairs = 3000, 0, 0
    for _ in range(n):
        args, kw = random_case(rng)
        got = sc.contact_options(*args, **kw)
        ref = sc.contact_options_reference(*args, **kw)
        assert got == ref, (args, kw)
        for a, b in zip(got, ref):  # the same floats, bit for bit (== takes -0.0 as 0.0)
            assert repr(a) == repr(b)
        solved += bool(ref)
        pairs += len(ref) == 2
    print(f"contact_options = reference in {n}/{n} cases ({solved} with solutions, {pairs} pairs)")
    assert solved > 0.5 * n and pairs > 0.1 * n


def test_contact_options_argument_errors_are_the_references():
    for kw in ({}, {"omega": 0.0, "speed": 0.0}):
        for f in (sc.contact_options, sc.contact_options_reference):
            try:
                f(0.02, 3e-5, 0.2, 0.0, (0.0, -1.0, 1.0), **kw)
            except ValueError as exc:
                assert "exactly one" in str(exc)
            else:
                raise AssertionError("no error")
