"""LogWriter's JSON messages on seeded random payloads and topics: refusals of non-finite
numbers that write nothing, sequence numbers per channel, and ``write_all`` writing what a loop of
``write`` does."""

import math

import numpy as np
import pytest
from mcap.reader import make_reader

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


def test_a_refused_payload_writes_nothing_and_sequences_count_per_channel(tmp_path):
    """Seeded random payloads of what runs log: each is written or refused whole (a refusal
    leaves the count as it was), and each channel's messages are numbered 1, 2, 3, ..."""
    rng = np.random.default_rng(3)
    topics = [f"/t{i}" for i in range(6)] + ["/stick/state", "/events"]
    written: dict[str, int] = {}
    refused = 0
    with LogWriter(tmp_path / "a.mcap", chunk_size=4096) as log:
        for i in range(1500):
            topic = topics[int(rng.integers(0, len(topics)))]
            count = log.count
            try:
                log.write(topic, _payload(rng), 1_000_000 * i)
                written[topic] = written.get(topic, 0) + 1
            except NonFiniteValueError:
                refused += 1
                assert log.count == count
    assert 0 < refused < 1500 and log.count == 1500 - refused
    with open(tmp_path / "a.mcap", "rb") as f:
        seqs: dict[str, list[int]] = {}
        for _, channel, message in make_reader(f).iter_messages(log_time_order=False):
            seqs.setdefault(channel.topic, []).append(message.sequence)
    assert {t: len(v) for t, v in seqs.items()} == written
    assert all(v == list(range(1, len(v) + 1)) for v in seqs.values())


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
    """A dict's messages in one call: new topics, lists, payloads only the standard encoder
    takes and non-finite refusals where they come, the same records in the same order."""
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


def test_write_all_of_nothing_writes_nothing(tmp_path):
    with LogWriter(tmp_path / "x.mcap") as log:
        log.write_all({}, 0)
    assert log.count == 0
