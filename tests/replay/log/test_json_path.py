"""The compiled JSON message path (replay/log/_chunk.c ``json``, LogWriter.write's first try):
the same file as the Python path (encode, the channel, the record) for the same writes, and the
same non-finite refusals, on seeded random payloads and topics."""

import math

import numpy as np
import pytest

from replay.log import LogWriter, NonFiniteValueError
from replay.messages import Event, JointState, StickState

from tests.replay.log.test_log_encode import _random_payload


def _payload(rng):
    """What runs log, and what only the Python path takes: dataclasses, dicts (int keys, NumPy
    floats: orjson's TypeError), nulls beside finite numbers, sometimes NaN or infinity."""
    kind = int(rng.integers(0, 6))
    bad = float(rng.choice([math.nan, math.inf, -math.inf])) if rng.random() < 0.05 else 0.25
    if kind == 0:
        return StickState(0.1, 1.0, bad, float(rng.normal()), 1e300, -0.0, 7)
    if kind == 1:
        return JointState(0.2, ["J1", "J2"], [0.1, bad], [1e-12, -3.0], [0.0, float(rng.random())])
    if kind == 2:
        return {"t": 0.4, "numpy": np.float64(bad), 3: "int key"}
    if kind == 3:
        return Event(0.3, "x", {"none": None, "v": (1.0, [None, bad]), "s": "null"})
    return {"t": 0.5, "v": _random_payload(rng)}


def _write_all(path, writes, compiled: bool):
    """The writes' outcome (written or refused, by field) and the file's bytes."""
    refused = []
    with LogWriter(path, chunk_size=4096) as log:
        if not compiled:
            log._json = lambda topic, payload, t_ns: False  # the Python path alone
        for topic, payload, t_ns in writes:
            try:
                log.write(topic, payload, t_ns)
                refused.append(None)
            except NonFiniteValueError as exc:
                refused.append((exc.topic, exc.fields))
    return refused, path.read_bytes()


@pytest.mark.parametrize("seed", [3, 4])
def test_compiled_json_path_writes_the_python_paths_bytes(tmp_path, seed):
    rng = np.random.default_rng(seed)
    topics = [f"/t{i}" for i in range(6)] + ["/stick/state", "/events"]
    writes = [
        (topics[int(rng.integers(0, len(topics)))], _payload(rng), 1_000_000 * i)
        for i in range(1500)
    ]
    fast_log, slow_log = tmp_path / "fast.mcap", tmp_path / "slow.mcap"
    counted = {"compiled": 0}
    refused, data = _write_all(fast_log, writes, compiled=True)
    refused_ref, data_ref = _write_all(slow_log, writes, compiled=False)
    # how many writes the compiled call took whole (the rest fell back to Python)
    with LogWriter(tmp_path / "count.mcap") as log:
        json = log._json
        for topic, payload, t_ns in writes:
            try:
                if json(topic, payload, t_ns):
                    counted["compiled"] += 1
                else:
                    log.write(topic, payload, t_ns)
            except NonFiniteValueError:
                pass
    n_refused = sum(r is not None for r in refused)
    print(
        f"seed {seed}: {counted['compiled']}/{len(writes)} writes compiled whole, "
        f"{n_refused} refused as non-finite; files equal: {data == data_ref}"
    )
    assert refused == refused_ref and 0 < n_refused < len(writes)
    assert data == data_ref
    assert len(writes) // 4 < counted["compiled"] < len(writes)


def test_compiled_json_path_leaves_a_new_topic_and_a_bad_payload_to_python(tmp_path):
    with LogWriter(tmp_path / "a.mcap") as log:
        assert log._json("/x", {"t": 1.0}, 0) is False  # no channel yet
        log.write("/x", {"t": 1.0}, 0)
        assert log._json("/x", {"t": 2.0}, 1) is True
        assert log._json("/x", {"t": np.float64(2.0)}, 2) is False  # orjson's TypeError
        assert log._json("/x", {"t": math.nan}, 3) is False  # null: finite() says no
        assert log._json("/x", {"t": None}, 4) is True  # a real null
        count = log.count
        with pytest.raises(NonFiniteValueError):
            log.write("/x", {"t": math.inf}, 5)
        assert log.count == count
        with pytest.raises(OverflowError):
            log._json("/x", {"t": 1.0}, -1)


def _write_dicts(path, groups, compiled: bool):
    """Each group (a dict of topic -> payload or list of payloads, one time) written by
    write_all (compiled) or by write one message at a time; the refusals and the file."""
    refused = []
    with LogWriter(path, chunk_size=4096) as log:
        for messages, t_ns in groups:
            try:
                if compiled:
                    log.write_all(messages, t_ns)
                else:
                    for topic, payload in messages.items():
                        for item in payload if isinstance(payload, list) else [payload]:
                            log.write(topic, item, t_ns)
                refused.append(None)
            except NonFiniteValueError as exc:  # the rest of that group is not written
                refused.append((exc.topic, exc.fields))
    return refused, path.read_bytes()


@pytest.mark.parametrize("seed", [5, 6])
def test_write_all_writes_what_a_loop_of_write_does(tmp_path, seed):
    """A dict's messages in one compiled call: new topics, lists, payloads only Python takes and
    non-finite refusals where they come, the same records in the same order."""
    rng = np.random.default_rng(seed)
    topics = [f"/t{i}" for i in range(8)] + ["/stick/state", "/events"]
    groups = []
    for i in range(600):
        messages = {}
        for topic in rng.choice(topics, size=int(rng.integers(1, 6)), replace=False):
            n = int(rng.integers(0, 4))
            messages[str(topic)] = (
                [_payload(rng) for _ in range(n)] if rng.random() < 0.2 else _payload(rng)
            )
        groups.append((messages, 1_000_000 * i))
    refused, data = _write_dicts(tmp_path / "all.mcap", groups, compiled=True)
    refused_ref, data_ref = _write_dicts(tmp_path / "loop.mcap", groups, compiled=False)
    assert refused == refused_ref and any(r is not None for r in refused)
    assert data == data_ref


def test_write_all_rejects_what_is_not_a_dict(tmp_path):
    with LogWriter(tmp_path / "x.mcap") as log:
        with pytest.raises(TypeError, match="json_all"):
            log._json_all([("/x", {"t": 1.0})], 0, 0)
        log.write_all({}, 0)  # nothing to write
    assert log.count == 0
