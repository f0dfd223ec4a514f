"""`python -m tools.bench.log_costs` runs: its stages cost something for real messages."""

from tools.bench.log_costs import capture, costs


def test_the_log_bench_times_each_stage_of_a_real_runs_messages(project_root):
    messages = capture("stick_3step", 0.01)
    assert {topic for topic, _, _ in messages} >= {"/scenario", "/stick/state", "/events"}
    c = costs(messages, repeat=1)
    assert set(c) == {"encode", "records", "write", "open_close"}
    assert all(c[k] > 0.0 for k in ("encode", "records", "open_close"))
