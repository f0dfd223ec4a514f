"""The runner's observers (replay/observers.py): each step's record handed once, in step order,
and a ``Runner(observers=...)`` callable sees the log's messages, in the log's order."""

from replay.log import LogReader
from replay.observers import StepRecord
from replay.runner import Runner
from replay.scenario import load_scenario


class Counting:
    def __init__(self) -> None:
        self.ks: list[int] = []
        self.messages = 0

    def start(self, info) -> None:
        pass

    def record(self, rec: StepRecord) -> None:
        if rec.captures or rec.state is not None:  # a step's record, not only events
            self.ks.append(rec.k)
        self.messages += len(rec.messages())


def test_each_step_is_handed_once_in_order(toy_yaml):
    sc = load_scenario(toy_yaml, sets=["timing.duration=0.05"])
    runner = Runner(sc)
    runner.start(None)
    counting = Counting()
    runner.watchers.append(counting)
    while not runner.done:
        runner.step()
    result = runner.finish()
    assert counting.ks == list(range(result.steps + 1))  # every step, then the final state
    assert counting.messages == result.messages - 1  # all but the scenario, at start


def test_a_callable_observer_sees_the_logs_messages_in_order(toy_yaml, tmp_path):
    seen: list[tuple[str, int]] = []
    sc = load_scenario(toy_yaml, sets=["timing.duration=0.05"])
    runner = Runner(sc, observers=(lambda topic, payload, t_ns: seen.append((topic, t_ns)),))
    result = runner.run(tmp_path / "run.mcap")
    logged = [(m.topic, m.t_ns) for m in LogReader(result.path).messages()]
    assert seen == logged and seen[-1][0] == "/events"  # (the outcome last)
