"""Several controller plug-ins as parallel tasks (replay/tasks.py, scenario ``tasks:``): routing of
outputs in the listed order, declared command fields, sensor-to-actuator latency, outcomes; and
the loader's tasks-or-controller rule, without changing how single-controller scenarios resolve."""

from __future__ import annotations

from dataclasses import dataclass

import pytest

from replay.interfaces import Controller
from replay.scenario import ScenarioError, load_scenario, resolved_yaml
from replay.tasks import Task, TaskError, TaskSet


@dataclass
class Msg:
    t: float
    value: float


@dataclass
class Cmd:
    a: float | None = None
    b: float | None = None


class Publisher(Controller):
    """Publishes /a = t each tick; writes command field a."""

    Params = None

    def __init__(self, field="a"):
        super().__init__(None, spec=None)
        self.field = field
        self.t = 0.0

    def update(self, t, measurements):
        self.t = t
        return Cmd(**{self.field: t})

    def telemetry(self, t):
        return {"/a": Msg(t, t)}


class Reader(Controller):
    Params = None

    def __init__(self, fail=None):
        super().__init__(None, spec=None)
        self.seen = []
        self.fail = fail

    def update(self, t, measurements):
        self.seen.append((t, [(topic, m.t) for topic, m in measurements]))
        return None

    def outcome(self, t):
        return {"success": False, "reason": self.fail} if self.fail else {"reader_ticks": 1}


def taskset(*tasks):
    return TaskSet(
        [Task(name, c, div, frozenset(i), frozenset(o)) for name, c, div, i, o in tasks], 1000
    )


def test_outputs_reach_later_tasks_in_the_same_step_and_earlier_ones_next_step():
    early, late = Reader(), Reader()
    ts = taskset(
        ("early", early, 1, {"/a"}, set()),
        ("pub", Publisher(), 1, set(), {"/a", "a"}),
        ("late", late, 1, {"/a"}, set()),
    )
    for k in range(3):
        cmds = ts.update(k / 1000, [])
        assert cmds == [Cmd(a=k / 1000)]
    assert late.seen == [(0.0, [("/a", 0.0)]), (0.001, [("/a", 0.001)]), (0.002, [("/a", 0.002)])]
    assert early.seen == [(0.0, []), (0.001, [("/a", 0.0)]), (0.002, [("/a", 0.001)])]
    loops = ts.telemetry(0.002)["/tasks/loops"]
    assert loops.names == ["early", "pub", "late"] and loops.ticked == [True, True, True]
    assert loops.latency[0] == pytest.approx(0.001) and loops.latency[2] == pytest.approx(0.0)
    assert loops.latency[1] is None  # no inputs


def test_sensor_messages_go_to_the_tasks_that_read_them_with_their_latency():
    r1, r2 = Reader(), Reader()
    ts = taskset(("r1", r1, 1, {"/cam"}, set()), ("r2", r2, 2, {"/enc"}, set()))
    ts.update(0.001, [("/cam", Msg(0.0, 1.0)), ("/enc", Msg(0.001, 2.0))])
    ts.update(0.002, [("/enc", Msg(0.002, 3.0))])
    assert r1.seen == [(0.001, [("/cam", 0.0)]), (0.002, [])]
    assert r2.seen == [(0.002, [("/enc", 0.001), ("/enc", 0.002)])]  # every 2nd step
    loops = ts.telemetry(0.002)["/tasks/loops"]
    assert loops.ticked == [True, True]
    assert loops.latency == [pytest.approx(0.002), pytest.approx(0.0)]
    assert loops.oldest == ["/cam", "/enc"]


def test_a_task_may_write_only_its_declared_command_fields():
    ts = taskset(("pub", Publisher("b"), 1, set(), {"a"}))
    with pytest.raises(TaskError, match="'b'"):
        ts.update(0.0, [])


def test_the_first_failing_task_gives_the_reason_and_metrics_merge():
    ts = taskset(
        ("ok", Reader(), 1, set(), set()),
        ("bad", Reader("no shape"), 1, set(), set()),
        ("bad2", Reader("later"), 1, set(), set()),
    )
    out = ts.outcome(1.0)
    assert out["success"] is False and out["reason"] == "no shape"
    assert out["reader_ticks"] == 1


TASKS = """\
name: toy_tasks
paper: none
timing: {physics_rate: 1000, duration: 0.1}
plant: {type: toy}
sensors:
  cam: {type: toy_sensor, rate: 100}
tasks:
  pd: {type: toy_pd, rate: 500, inputs: [/toy/measured], outputs: [], params: {target: 1.0}}
"""


def test_loader_takes_tasks_or_a_controller(tmp_path):
    p = tmp_path / "t.yaml"
    p.write_text(TASKS)
    sc = load_scenario(p)
    assert sc.controller is None and sc.tasks["pd"].params.target == 1.0
    assert sc.tasks["pd"].inputs == ["/toy/measured"]
    assert "tasks:" in resolved_yaml(sc)
    p.write_text(TASKS + "controller: {type: toy_pd}\n")
    with pytest.raises(ScenarioError, match="either controller: or tasks:, not both"):
        load_scenario(p)
    p.write_text(TASKS.replace("rate: 500", "rate: 300"))
    with pytest.raises(ScenarioError, match="tasks.pd.rate"):
        load_scenario(p)
    p.write_text(TASKS.replace("tasks:\n  pd:", "unused:\n  pd:"))
    with pytest.raises(ScenarioError):
        load_scenario(p)


def test_a_single_controller_scenario_resolves_without_tasks(toy_yaml):
    text = resolved_yaml(load_scenario(toy_yaml))
    assert "tasks" not in text and "controller:" in text
