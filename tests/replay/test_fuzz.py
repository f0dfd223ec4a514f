"""Property-based fuzzing of what a user hands the platform: scenario values, YAML shapes and
log bytes. Each example must end in exactly one of two ways: a one-line ScenarioError (LogError
for logs) naming a place, or a clean result. Seeded (derandomize) and bounded in time."""

import re

import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

from replay.log import LogError, LogReader
from replay.runner import Runner
from replay.scenario import ScenarioError, load_scenario

FUZZ = settings(
    derandomize=True,
    deadline=None,
    database=None,  # seeded, and bounded:
    phases=[Phase.explicit, Phase.generate],  # no shrinking
    suppress_health_check=list(HealthCheck),
)
WHERE = re.compile(r"^(<--set[^>]*>|[^ ]+)(:\d+:\d+)?: ")  # file:line:col first

FIELDS = [
    "plant.params.mass",
    "plant.params.x0",
    "plant.params.wall",
    "sensors.cam.rate",
    "sensors.cam.latency",
    "sensors.cam.params.noise",
    "controller.rate",
    "controller.params.kp",
    "controller.params.target",
    "timing.duration",
    "timing.physics_rate",
    "timing.state_log_rate",
    "log.level",
    "log.state_rate",
    "log",
    "stop.after",
    "stop.on_events",
    "seed",
    "name",
    "plant.type",
    "sensors.cam",
    "sensors",
    "controller",
]

SCALARS = st.one_of(
    st.sampled_from(
        [
            ".nan",
            ".inf",
            "-.inf",
            "1" + "0" * 400,
            "-1",
            "0",
            "1e-300",
            "1.0e300",
            "7",
            "~",
            "true",
            "''",
            "abc",
            "0x10",
            "1_000",
            "1:30",
            "2024-01-01",
            "../../x",
            "!!binary aGk=",
            "&a 1",
            "*a",
            "[1, 2]",
            "{a: 1}",
            "[]",
            "{}",
            "[[[[1]]]]",
            "? [a, b]\n: 1",
            "'\x00'",
            '"\\x00"',
            "!!python/none ''",
        ]
    ),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(min_value=-(10**30), max_value=10**30).map(str),
    st.text(max_size=20).map(lambda t: repr(t)),
)
VALUES = st.recursive(
    SCALARS,
    lambda inner: st.one_of(
        st.lists(inner, max_size=4).map(lambda xs: "[" + ", ".join(xs) + "]"),
        st.dictionaries(
            st.sampled_from(["a", "mass", "type", "rate", "params"]), inner, max_size=3
        ).map(lambda d: "{" + ", ".join(f"{k}: {v}" for k, v in d.items()) + "}"),
    ),
    max_leaves=8,
)


def _one_line(exc: Exception) -> str:
    text = str(exc)
    assert "\n" not in text and "\r" not in text, text
    assert WHERE.match(text), text
    return text


@settings(FUZZ, max_examples=120)
@given(
    field=st.sampled_from(FIELDS),
    value=VALUES,
    second=st.sampled_from(FIELDS + [None]),
    value2=VALUES,
)
def test_scenario_values(toy_yaml_text, tmp_path_factory, field, value, second, value2):
    path = tmp_path_factory.mktemp("v") / "toy.yaml"
    path.write_text(toy_yaml_text)
    sets = [f"{field}={value}"] + ([f"{second}={value2}"] if second else [])
    try:
        sc = load_scenario(path, sets=sets)
    except ScenarioError as exc:
        _one_line(exc)
        return
    # accepted: it must run (briefly) to a clean end, with a log
    sc.timing.duration = min(sc.timing.duration, 0.05)
    if sc.timing.duration * sc.timing.physics_rate < 1:
        return
    result = Runner(sc).run(path.parent / "run.mcap")
    assert result.path.is_file()
    assert result.outcome.get("reason")


FRAGMENTS = st.sampled_from(
    [
        "name: x\n",
        "paper: p\n",
        "plant: {type: toy}\n",
        "controller: {type: toy_pd}\n",
        "sensors:\n  cam: {type: toy_sensor, rate: 100}\n",
        "timing: {duration: 0.01}\n",
        "? [a, b]\n: 1\n",
        "&a [1, 2]\n",
        "x: *a\n",
        "y: &b [*b]\n",
        "- 1\n",
        "[" * 60,
        "]" * 60,
        "{" * 40,
        "\x00",
        "\ufeff",
        "\t",
        "!!python/object:os.system {}\n",
        "<<: {a: 1}\n",
        "extends: toy.yaml\n",
        "extends: .\n",
        "extends: [a]\n",
        "notes: |\n  multi\n  line\n",
        "seed: 1" + "0" * 300 + "\n",
        "'unclosed\n",
        "%YAML 1.1\n---\n",
        "--- !!map\n",
        "plant:\n  params: {mass: .nan}\n",
        "\u2028",
        "\x85",
        "caf\xe9: 1\n",
    ]
)


@settings(FUZZ, max_examples=150)
@given(
    parts=st.lists(FRAGMENTS, max_size=12),
    encoding=st.sampled_from(["utf-8", "utf-16", "latin-1", "utf-8-sig"]),
    junk=st.binary(max_size=40),
)
def test_yaml_shapes_and_encodings(toy_yaml_text, tmp_path_factory, parts, encoding, junk):
    d = tmp_path_factory.mktemp("y")
    (d / "toy.yaml").write_text(toy_yaml_text)
    path = d / "fuzz.yaml"
    try:
        data = "".join(parts).encode(encoding)
    except UnicodeEncodeError:
        data = "".join(parts).encode("utf-8")
    path.write_bytes(data + junk)
    try:
        load_scenario(path)
    except ScenarioError as exc:
        _one_line(exc)


@pytest.fixture(scope="module")
def small_log(tmp_path_factory):
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    import conftest

    d = tmp_path_factory.mktemp("log")
    (d / "toy.yaml").write_text(conftest.TOY)
    sc = load_scenario(d / "toy.yaml", sets=["timing.duration=0.3"])
    return Runner(sc).run(d / "toy.mcap").path.read_bytes()


@pytest.fixture(scope="module")
def toy_yaml_text():
    import conftest

    return conftest.TOY


@settings(FUZZ, max_examples=120)
@given(
    cut=st.floats(0.0, 1.0),
    flips=st.lists(st.tuples(st.floats(0.0, 1.0), st.integers(1, 255)), max_size=64),
    insert=st.binary(max_size=16),
)
def test_log_bytes(small_log, tmp_path_factory, cut, flips, insert):
    data = bytearray(small_log)
    for where, mask in flips:
        i = int(where * (len(data) - 1))
        data[i] ^= mask
    n = int(cut * len(data))
    data = bytes(data[:n]) + insert + bytes(data[n:]) if insert else bytes(data[: max(n, 1)])
    path = tmp_path_factory.mktemp("b") / "x.mcap"
    path.write_bytes(data)
    try:
        r = LogReader(path).check()
        list(r.messages())
        r.events()
        r.topic_counts()
        r.time_range()
        r.metadata()
        notes = r.describe_problems()
    except LogError as exc:
        assert "\n" not in str(exc)
        return
    if bytes(data) != small_log:
        # anything read from changed bytes is either identical to the run or flagged
        same = [m.data for m in LogReader(path).messages()] == [
            m.data for m in _reader_of(small_log, tmp_path_factory).messages()
        ]
        assert same or notes or r.status != "complete", "changed bytes read as a clean run"


def _reader_of(data: bytes, factory) -> LogReader:
    p = factory.mktemp("g") / "good.mcap"
    p.write_bytes(data)
    return LogReader(p)
