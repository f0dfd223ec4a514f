"""The runner's timing (multi-rate, latency), events and stop conditions, and the MCAP log contract."""

import json
import random
import os
from pathlib import Path
import signal
import subprocess
import sys

import pytest

from replay.log import LogReader, LogWriter, NotALogError
from replay.messages import Event
from replay.runner import Runner
from replay.scenario import load_scenario


def _run(toy_yaml, tmp_path, sets=(), name="run.mcap"):
    sc = load_scenario(toy_yaml, sets=list(sets))
    runner = Runner(sc)
    result = runner.run(tmp_path / name)
    return runner, result, LogReader(result.path)


def test_rates_and_latency(toy_yaml, tmp_path):
    runner, result, log = _run(toy_yaml, tmp_path)
    counts = log.topic_counts()
    assert counts["/toy/measured"] == 100  # 100 Hz for 1 s
    assert counts["/toy/state"] == 1000 + 1  # every physics step, plus the final state
    assert counts["/scenario"] == 1
    # every measurement reached the controller 20 ms (latency) after capture, at a 500 Hz tick
    seen = runner.controller.seen
    assert seen and all(abs((now - cap) - 0.02) < 1e-9 for now, cap in seen)
    # log time is simulated time
    for m in log.messages("/toy/measured"):
        assert m.t_ns == round(m.data["t"] * 1e9)


def test_readings_reach_the_controller_in_time_order(toy_yaml, tmp_path):
    """A zero-latency reading is delivered at its capture step even when a slower sensor's
    reading, captured at the same step, was queued ahead of it."""
    sc = load_scenario(
        toy_yaml,
        sets=["sensors.fast={type: toy_sensor, rate: 100, latency: 0.0}", "controller.rate=1000"],
    )
    assert list(sc.sensors) == ["cam", "fast"]  # the 20 ms sensor comes first
    runner = Runner(sc)
    runner.run(tmp_path / "order.mcap")
    delays = sorted({round(now - cap, 9) for now, cap in runner.controller.seen})
    assert delays == [0.0, 0.02]


def test_every_run_ends_with_an_outcome(toy_yaml, tmp_path):
    _, result, log = _run(toy_yaml, tmp_path)
    events = log.events()
    assert events[-1]["kind"] == "outcome"
    assert events[-1]["data"] == {"success": True, "reason": "completed"} == result.outcome
    _, result, log = _run(toy_yaml, tmp_path, sets=["plant.params.blow_up_at=0.2"], name="nan.mcap")
    last = log.events()[-1]
    assert last["kind"] == "outcome" and last["data"]["success"] is False
    assert "non-finite" in last["data"]["reason"]


def test_a_diverged_run_says_what_diverged(toy_yaml, tmp_path, monkeypatch):
    """A plant reports its divergence as a ``nan`` event (the arm rig's holds the step, the air
    table's also the fields): the run's error says so, not "non-finite value on /events: ?"."""
    from replay.interfaces import Occurrence

    for said, expected in (
        ({"step": 50}, ["the simulation diverged at step 50"]),
        ({"fields": ["omega", "x"], "step": 50}, ["omega", "x"]),
    ):
        runner = Runner(load_scenario(toy_yaml))
        pop = runner.plant.pop_events
        monkeypatch.setattr(
            runner.plant,
            "pop_events",
            lambda pop=pop, said=said, r=runner: pop() + [Occurrence("nan", said)] * (r.k == 50),
        )
        result = runner.run(tmp_path / "nan.mcap")
        assert result.stopped_by == "error" and "?" not in result.error, result.error
        error = next(e for e in LogReader(result.path).events() if e["kind"] == "error")
        assert error["data"]["fields"] == expected, error


def test_controller_drives_plant(toy_yaml, tmp_path):
    _, _, log = _run(toy_yaml, tmp_path, sets=["timing.duration=3.0"])
    last = log.series("/toy/state")[-1]
    assert abs(last["x"] - 1.0) < 0.05


def test_events_and_stop_condition(toy_yaml, tmp_path):
    _, result, log = _run(
        toy_yaml,
        tmp_path,
        sets=[
            "plant.params.wall=0.5",
            "stop.on_events=[collision]",
            "stop.after=0.1",
            "timing.duration=5",
        ],
    )
    events = log.events()
    assert [e["kind"] for e in events] == ["collision", "outcome"]
    e = events[0]
    assert e["data"]["index"] == 1 and e["data"]["planned"] == {"target": 1.0}
    assert result.stopped_by == "collision"
    assert abs(result.t_end - (e["t"] + 0.1)) < 1.5e-3


def test_same_seed_same_bytes_other_seed_differs(toy_yaml, tmp_path):
    sets = ["sensors.cam.params.noise=0.01"]
    _, a, _ = _run(toy_yaml, tmp_path, sets, "a.mcap")
    _, b, _ = _run(toy_yaml, tmp_path, sets, "b.mcap")
    assert a.path.read_bytes() == b.path.read_bytes()
    sc = load_scenario(toy_yaml, sets=sets, seed=4)
    c = Runner(sc).run(tmp_path / "c.mcap")
    assert c.path.read_bytes() != a.path.read_bytes()


def test_nan_becomes_an_error_event(toy_yaml, tmp_path):
    _, result, log = _run(toy_yaml, tmp_path, sets=["plant.params.blow_up_at=0.3"])
    assert result.stopped_by == "error"
    err, outcome = log.events()[-2:]
    assert outcome["kind"] == "outcome" and outcome["data"]["success"] is False
    assert err["kind"] == "error" and err["data"]["topic"] in ("/toy/state", "/toy/measured")
    assert "x" in err["data"]["fields"]
    assert abs(err["t"] - 0.3) < 2e-3


def test_provenance_in_metadata_and_scenario_topic(toy_yaml, tmp_path):
    _, _, log = _run(toy_yaml, tmp_path)
    meta = log.metadata()
    assert meta["provenance"]["seed"] == "3" and "numpy" in meta["provenance"]
    assert "foxglove-sdk" in meta["provenance"]  # (the log's writer)
    from importlib import metadata

    assert meta["provenance"]["drake"] == metadata.version("drake")  # the third arm engine
    sc = log.scenario()
    assert sc["name"] == "toy" and "kp: 100.0" in sc["yaml"] and sc["seed"] == 3


def test_truncated_log_is_readable_to_its_last_chunk(tmp_path):
    w = LogWriter(tmp_path / "x.mcap", chunk_size=2000)
    for k in range(5000):
        w.write("/events", Event(k * 1e-3, "tick", {"k": k}), k * 1_000_000)
    w.close()
    data = (tmp_path / "x.mcap").read_bytes()
    (tmp_path / "cut.mcap").write_bytes(data[: len(data) // 2])
    r = LogReader(tmp_path / "cut.mcap")
    assert r.truncated
    ks = [m.data["data"]["k"] for m in r.messages()]
    assert 1000 < len(ks) < 5000 and ks == list(range(len(ks)))


def test_not_a_log(tmp_path):
    p = tmp_path / "x.mcap"
    p.write_text("hello")
    with pytest.raises(NotALogError):
        LogReader(p)


KILLED_RUN = r"""
import sys, time
sys.path.insert(0, {tests!r})
import toy_plugins; toy_plugins.install()
from replay.scenario import load_scenario
from replay.runner import Runner
sc = load_scenario({yaml!r}, sets=["timing.duration=600", "timing.physics_rate=1000"])
class Slow:
    def __call__(self, t, d):
        if t > 10.0:
            print("ready", flush=True); time.sleep(60)
Runner(sc, progress=Slow()).run({out!r})
"""


def test_killed_run_leaves_a_readable_part_file(toy_yaml, tmp_path):
    out = tmp_path / "killed.mcap"
    code = KILLED_RUN.format(
        tests=str(Path(__file__).resolve().parents[1]), yaml=str(toy_yaml), out=str(out)
    )
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout.readline().strip() == "ready"
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=30)
    assert not out.exists()
    part = tmp_path / f"killed.mcap.{proc.pid}.part"  # the run's own name: its pid
    r = LogReader(part)
    # truncated, not damaged: the writer's chunk in progress (its header down, lengths pending)
    # is a record cut short
    assert r.status == "truncated", r.problems
    states = r.series("/toy/state")
    assert len(states) > 100 and json.dumps(states[-1])


INTERRUPTED_RUN = r"""
import sys, time
sys.path.insert(0, {tests!r})
import toy_plugins; toy_plugins.install()
from replay.cli import main
import replay.runner as runner
orig = runner.Runner.run
def run(self, out):
    def tick(t, d):
        if t > 1.0:
            # short sleeps: the kernel may hand SIGINT to another thread of the process (BLAS's),
            # which does not wake the main thread's sleep; the handler runs at the next wake-up
            print("ready", flush=True)
            for _ in range(600):
                time.sleep(0.1)
    self.progress = tick
    return orig(self, out)
runner.Runner.run = run
sys.argv = ["replay", "run", {yaml!r}, "-o", {out!r}, "--set", "timing.duration=600"]
main()
"""


def _sigint_as_from_a_shell() -> None:
    """The child starts with SIGINT's default action, as a shell's foreground command does
    (not whatever the test worker holds: it inherits an ignored one, and some earlier test's
    library in the same xdist worker has been seen to leave it ignored)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def test_ctrl_c_keeps_a_closed_log_and_exits_130(toy_yaml, tmp_path):
    """The interrupted run is closed properly under its own name; an old log at -o stays."""
    out = tmp_path / "run.mcap"
    old = Runner(load_scenario(toy_yaml, sets=["timing.duration=0.1"])).run(out).path.read_bytes()
    code = INTERRUPTED_RUN.format(
        tests=str(Path(__file__).resolve().parents[1]), yaml=str(toy_yaml), out=str(out)
    )
    proc = subprocess.Popen(
        [sys.executable, "-c", code],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=_sigint_as_from_a_shell,
    )
    try:
        assert proc.stdout.readline().strip() == "ready"
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    finally:
        proc.kill()
    assert proc.returncode == 130
    assert "interrupted at t = " in err and "partial log kept" in err and "Traceback" not in err
    assert out.read_bytes() == old
    kept = tmp_path / "run.interrupted.mcap"
    assert str(kept) in err
    r = LogReader(kept)  # finished properly: summary, its own name
    assert not r.truncated
    assert [e["kind"] for e in r.events()[-2:]] == ["interrupted", "outcome"]
    assert r.events()[-1]["data"] == {"success": False, "reason": "interrupted"}
    assert 0.9 < r.time_range()[1] < 1.2


def test_sigint_mid_record_is_held_until_the_record_is_whole(tmp_path):
    """Ctrl-C while a record is written is raised only once the write is done, so the log never
    holds a torn record; after close the default handler is back. (The signal arrives while the
    mcap writer writes the chunk the message filled to the file.)"""
    found = signal.signal(signal.SIGINT, signal.default_int_handler)  # (what a CLI starts with)
    try:
        _held_until_whole(tmp_path)
    finally:
        signal.signal(signal.SIGINT, found)


def _held_until_whole(tmp_path) -> None:
    w = LogWriter(tmp_path / "x.mcap", chunk_size=100)
    add, reached = w._file.write, []

    def interrupted_mid_chunk(data):  # Ctrl-C arrives while the chunk is being written
        os.kill(os.getpid(), signal.SIGINT)
        add(data)
        reached.append(True)

    w._file.write = interrupted_mid_chunk
    with pytest.raises(KeyboardInterrupt):
        w.write("/events", Event(0.0, "a"), 0)  # the schema, channel and it fill the chunk
    assert reached
    w._file.write = add
    w.write("/events", Event(0.001, "interrupted"), 1_000_000)
    assert w.close("interrupted") == tmp_path / "x.interrupted.mcap"
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    r = LogReader(tmp_path / "x.interrupted.mcap").check()
    assert r.status == "complete" and [e["kind"] for e in r.events()] == ["a", "interrupted"]


def test_messages_that_are_not_json_objects_are_skipped_and_said(tmp_path):
    from mcap.writer import Writer

    with open(tmp_path / "x.mcap", "wb") as f:
        w = Writer(f)
        w.start()
        c = w.register_channel("/events", "json", w.register_schema("s", "jsonschema", b"{}"))
        for i, data in enumerate([b'{"t": 0, "kind": "a"}', b"\xff\xfe", b"[1]", b"{bad"]):
            w.add_message(c, log_time=i, publish_time=i, data=data)
        w.finish()
    r = LogReader(tmp_path / "x.mcap").check()
    assert [e["kind"] for e in r.events()] == ["a"]
    assert r.damaged and any("3 message(s) not a JSON object" in p for p in r.problems)


def test_readings_are_delivered_their_latency_after_capture_over_random_sensor_sets(
    toy_yaml, tmp_path
):
    """Seeded random sets of 1-3 sensors (rates, latencies, sometimes all equal: the FIFO path,
    else the heap): every reading reaches the controller exactly its latency after capture, in
    delivery order. Reports the share of sets that passed."""
    rng = random.Random(10)
    passed, trials = 0, 12
    for i in range(trials):
        n = rng.randint(1, 3)
        same = rng.random() < 0.5
        lat0 = rng.choice([0, 2, 10])
        spec = [
            (rng.choice([100, 250, 500]), lat0 if same else rng.choice([0, 2, 10]))
            for _ in range(n)
        ]
        sets = [
            "controller.rate=1000",
            "timing.duration=0.1",
            "sensors.cam.rate=%d" % spec[0][0],
            "sensors.cam.latency=%g" % (spec[0][1] * 1e-3),
        ]
        sets += [
            f"sensors.s{j}={{type: toy_sensor, rate: {r}, latency: {lat * 1e-3:g}}}"
            for j, (r, lat) in enumerate(spec[1:])
        ]
        runner = Runner(load_scenario(toy_yaml, sets=sets))
        result = runner.run(tmp_path / f"r{i}.mcap")
        seen = runner.controller.seen
        expected = sorted(
            round(k / r + lat * 1e-3, 9)
            for r, lat in spec
            for k in range(int(0.1 * r))
            if k / r + lat * 1e-3 < result.t_end - 1e-9
        )
        delivered = [round(now, 9) for now, _ in seen]
        ok = delivered == sorted(delivered) and sorted(delivered) == expected
        ok = ok and {round(now - cap, 9) for now, cap in seen} <= {lat * 1e-3 for _, lat in spec}
        passed += ok
    print(f"runner delivery over random sensor sets: {passed}/{trials} passed")
    assert passed == trials


def test_resolved_yaml_is_the_pure_python_emitters_text_for_every_scenario():
    """The logs' /scenario text comes from libyaml's emitter when PyYAML has it: the same text
    as PyYAML's own (so a machine without libyaml writes the same logs)."""
    import yaml

    from conftest import ROOT
    from replay.scenario.loader import resolved_yaml, to_plain

    paths = sorted((ROOT / "scenarios").glob("*.yaml"))
    assert paths
    for path in paths:
        sc = load_scenario(path)
        text = yaml.safe_dump(to_plain(sc), sort_keys=False, default_flow_style=None, width=100)
        assert resolved_yaml(sc) == text, path.name


def test_a_list_in_truth_is_its_items_messages_with_and_without_observers(
    toy_yaml, tmp_path, monkeypatch
):
    """Truth and telemetry go through the log's write_all (one compiled call a dict); a list
    payload is one message an item, as a loop of write would log it, observers or not."""
    import toy_plugins

    def truth(self, t):
        return {"/toy/state": {"t": t, "x": self.x}, "/toy/pair": [{"i": 0}, {"i": 1}]}

    monkeypatch.setattr(toy_plugins.ToyPlant, "truth", truth)
    seen = []
    for observers, name in (((), "plain.mcap"), ((lambda *m: seen.append(m[0]),), "obs.mcap")):
        sc = load_scenario(toy_yaml, sets=["timing.duration=0.01"])
        result = Runner(sc, observers=observers).run(tmp_path / name)
        counts = LogReader(result.path).topic_counts()
        assert counts["/toy/pair"] == 2 * counts["/toy/state"] == 2 * (result.steps + 1)
    assert seen.count("/toy/pair") == 2 * seen.count("/toy/state")
    plain = list(LogReader(tmp_path / "plain.mcap").messages("/toy/pair"))
    assert [m.data["i"] for m in plain[:4]] == [0, 1, 0, 1]
