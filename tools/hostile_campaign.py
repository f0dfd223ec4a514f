"""A hostile but fair user's campaign against the `replay` command line (not part of the suite).

Generates bad inputs (scenario values through ``--set``, YAML shapes and encodings, plug-in
mismatches, output paths, damaged logs, Ctrl-C and kill at chosen moments, the viewer's socket)
and runs ``replay`` on each in a subprocess with a timeout. Each call is classified:

- ``traceback``: "Traceback (most recent call last)" in the output
- ``abort``: killed by a signal or exit status 134/139 (a C assertion)
- ``hang``: the time limit passed
- ``accepted``: a meaningless value that ``validate`` accepted
- ``ran``: ... and that ``run`` then ran to exit 0
- ``run_failed``: ``validate`` accepted it and ``run`` failed (validate must accept exactly
  what run can run)
- ``not_one_line``: exit 2 but not exactly one line on stderr
- ``wrong_line``: the error does not name the expected ``file:LINE:``
- ``silent``: a damaged or truncated log read without saying so
- ``data_loss``: a log that cannot be read after Ctrl-C or kill, an old log replaced by a failed
  run, an input overwritten

    python tools/hostile_campaign.py [--replay "CMD"] [--root DIR] [--only FAMILY] [--jobs N]

``--replay`` is the command prefix (default: this venv's ``replay``); ``--root`` the project
checkout to run in (its scenarios/ and data/).
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import random
import shlex
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

HERE = Path(__file__).resolve().parents[1]
BIG_INT = "1" + "0" * 400


@dataclass
class Case:
    family: str
    argv: list
    expect: str = "reject"  # reject | ok | either
    files: dict = field(default_factory=dict)  # name -> bytes, created in the case's folder
    line: int | None = None  # the line the error must name
    then_run: bool = False  # when validate accepts it: run it too
    note: str = ""


# -- value cases ---------------------------------------------------------------------------

STICK = "scenarios/stick_3step.yaml"
CATCH = "scenarios/catch_optimised.yaml"

ANY = ["nan", "inf", "-inf", "big", "str", "map", "huge"]
POS = ANY + ["neg", "zero"]
NONNEG = ANY + ["neg"]
INT_SIZE = ["nan", "float", "neg", "big", "huge_int", "zero"]
RATE = ["nan", "inf", "neg", "zero", "tiny", "nodivide", "big"]

VALUES = {
    "nan": ".nan",
    "inf": ".inf",
    "-inf": "-.inf",
    "big": BIG_INT,
    "str": "abc",
    "map": "{a: 1}",
    "huge": "1.0e300",
    "neg": "-1",
    "zero": "0",
    "float": "1.5",
    "huge_int": "1000000000000",
    "tiny": "1.0e-300",
    "nodivide": "7",
}

FIELDS = [
    # (scenario, path, kind or list of value keys, list length or None)
    (STICK, "plant.params.stick.mass", POS, None),
    (STICK, "plant.params.stick.inertia", POS, None),
    (STICK, "plant.params.stick.length", POS, None),
    (STICK, "plant.params.stick.visual_width", POS, None),
    (STICK, "plant.params.stick.restitution", NONNEG + ["float"], None),
    (STICK, "plant.params.stick.friction", NONNEG, None),
    (STICK, "plant.params.initial.theta", ANY, None),
    (STICK, "plant.params.initial.vy", ANY, None),
    (STICK, "plant.params.initial.omega", ANY, None),
    (STICK, "plant.params.hand.base_speed", POS, None),
    (STICK, "plant.params.hand.joint_speed", POS, None),
    (STICK, "plant.params.hand.tip_radius", POS, None),
    (STICK, "plant.params.hand.link_lengths", "list", 2),
    (STICK, "plant.params.solver.iterations", INT_SIZE, None),
    (STICK, "plant.params.rest_speed", POS, None),
    (STICK, "sensors.camera.rate", RATE, None),
    (STICK, "sensors.camera.latency", NONNEG, None),
    (STICK, "sensors.camera.params.width", INT_SIZE, None),
    (STICK, "sensors.camera.params.position", "list", 3),
    (STICK, "sensors.camera.params.target", ["same_as_position"], None),
    (STICK, "sensors.camera.params.fov_x", POS, None),
    (STICK, "controller.rate", RATE, None),
    (STICK, "controller.params.lambda_2", "list", 2),
    (STICK, "controller.params.horizon", POS, None),
    (STICK, "controller.params.window", INT_SIZE, None),
    (STICK, "timing.physics_rate", INT_SIZE, None),
    (STICK, "timing.duration", POS + ["tiny"], None),
    (STICK, "stop.after", NONNEG, None),
    (STICK, "seed", ["nan", "float", "neg", "big"], None),
    (STICK, "name", ["escape", "map"], None),
    (CATCH, "plant.params.object_mass", POS, None),
    (CATCH, "plant.params.object_radius", POS, None),
    (CATCH, "plant.params.gravity", NONNEG, None),
    (CATCH, "plant.params.hand_closing_speed", POS, None),
    (CATCH, "plant.params.miss_height", ANY, None),
    (CATCH, "plant.params.object_size", "list", 3),
    (CATCH, "plant.params.base_position", "list", 3),
    (CATCH, "plant.params.object_velocity", "list", 3),
    (CATCH, "plant.params.initial_q", "list", 4),
    (CATCH, "plant.params.velocity_limits", "list", 4),
    (CATCH, "plant.params.torque_limits", "list", 4),
    (CATCH, "plant.params.locked_joints", ["joint9", "joint_num"], None),
    (CATCH, "plant.params.solver_iterations", INT_SIZE, None),
    (CATCH, "sensors.stereo.rate", RATE, None),
    (CATCH, "sensors.stereo.latency", NONNEG, None),
    (CATCH, "sensors.stereo.params.width", INT_SIZE, None),
    (CATCH, "sensors.stereo.params.cam0_position", "list", 3),
    (CATCH, "controller.params.q_alpha", ANY, None),
    (CATCH, "controller.params.order", INT_SIZE, None),
    (CATCH, "controller.params.throw_start", "list", 3),
    (CATCH, "controller.params.throw_speeds", ["empty", "list_nan", "list_neg"], None),
    (CATCH, "controller.params.kp", "list", 4),
    (CATCH, "controller.params.fit_window", POS, None),
    (CATCH, "controller.params.throw_grid", INT_SIZE, None),
]


def _list_values(n: int) -> dict:
    ok = ["0.1"] * n
    return {
        "l_nan": "[" + ", ".join([".nan"] + ok[1:]) + "]",
        "l_inf": "[" + ", ".join(ok[:-1] + [".inf"]) + "]",
        "l_str": "[" + ", ".join(["a"] * n) + "]",
        "l_big": "[" + ", ".join([BIG_INT] + ok[1:]) + "]",
        "l_short": "[" + ", ".join(ok[:-1]) + "]",
        "l_long": "[" + ", ".join(ok + ["0.1"]) + "]",
        "l_nested": "[" + ", ".join(["[1]"] * n) + "]",
        "l_huge": "[" + ", ".join(["1.0e300"] + ok[1:]) + "]",
    }


SPECIAL = {
    "same_as_position": "[0.0, 0.2, 1.0]",
    "escape": "../../../escaped",
    "joint9": "[J9]",
    "joint_num": "[3]",
    "empty": "[]",
    "list_nan": "[8.0, .nan]",
    "list_neg": "[8.0, -9.0]",
}


def value_cases() -> list[Case]:
    cases = []
    for scen, path, kind, n in FIELDS:
        values = (
            _list_values(n) if kind == "list" else {k: SPECIAL.get(k, VALUES.get(k)) for k in kind}
        )
        if path.endswith("lambda_2"):
            values.update({"l_range": "[5, 0]", "l_zero": "[0, 0]"})
        if path.endswith("throw_start"):
            values["l_zero_x"] = "[0.0, 0.0, 0.9]"
        for key, v in values.items():
            cases.append(
                Case(
                    "value",
                    ["validate", scen, "--set", f"{path}={v}"],
                    then_run=True,
                    note=f"{path}={v[:40]}",
                )
            )
    return cases


# -- YAML shapes and encodings ----------------------------------------------------------------


def shape_cases() -> list[Case]:
    stick = (HERE / STICK).read_text()
    head = "name: shape\npaper: higashimori2007\n"
    deep = "a: " + "[" * 1000 + "]" * 1000 + "\n"
    bomb = "x0: &a [1, 1, 1, 1, 1, 1, 1, 1, 1, 1]\n"
    for i in range(1, 9):
        prev = "a" if i == 1 else f"a{i - 1}"
        bomb += f"x{i}: &a{i} [" + ", ".join([f"*{prev}"] * 10) + "]\n"
    bomb_in_list = (
        f"extends: {HERE / STICK}\n"
        "controller:\n  params:\n    lambda_2: &l [&a0 [1,1,1,1,1,1,1,1,1,1]"
        + "".join(f", &a{i} [" + ", ".join([f"*a{i - 1}"] * 10) + "]" for i in range(1, 8))
        + "]\n"
    )
    ext = f"extends: {HERE / STICK}\n"
    files = {
        "binary": bytes(range(256)) * 4,
        "utf16": stick.encode("utf-16"),
        "latin1": ("# caf\xe9\n" + stick).encode("latin-1"),
        "nul_comment": ("# a\x00b\n" + stick).encode(),
        "extends_binary": b"extends: bin.yaml\n",
        "deep": (head + deep).encode(),
        "complex_key": (stick + "? [a, b]\n: 1\n").encode(),
        "complex_key_params": stick.replace(
            "  params:\n    lambda_2", "  params:\n    ? [a, b]\n    : 1\n    lambda_2"
        ).encode(),
        "alias_bomb_top": (bomb + stick).encode(),
        "alias_bomb_list": bomb_in_list.encode(),
        "empty": b"",
        "only_comment": b"# nothing\n",
        "top_list": b"- a\n- b\n",
        "top_scalar": b"hello\n",
        "duplicate_key": (stick + "seed: 4\n").encode(),
        "python_tag": stick.replace(
            "seed: 0", "seed: !!python/object/apply:os.system [true]"
        ).encode(),
        "null_plant": (head + "plant:\ncontroller: {type: stick_3step}\n").encode(),
        "int_key": stick.replace(
            "  params:\n    lambda_2", "  params:\n    3: 4\n    lambda_2"
        ).encode(),
        "null_key": stick.replace(
            "  params:\n    lambda_2", "  params:\n    ~: 4\n    lambda_2"
        ).encode(),
        "extends_loop": b"extends: extends_loop.yaml\nname: x\n",
        "extends_dir": b"extends: .\nname: x\n",
        "extends_list": b"extends: [a.yaml]\nname: x\n",
        "extends_missing": b"extends: nowhere.yaml\n",
        "huge_string": (ext + "description: " + "x" * 2_000_000 + "\n").encode(),
        "huge_file_comment": (stick + "#" + "y" * 30_000_000 + "\n").encode(),
        "bad_indent": (stick + "  oops: [\n").encode(),
        "sensor_list": (ext + "sensors: [a, b]\n").encode(),
        "sensors_null_entry": (ext + "sensors:\n  camera:\n").encode(),
        "tab_indent": stick.replace("  type: airtable", "\ttype: airtable").encode(),
        "bom_utf8": b"\xef\xbb\xbf" + stick.encode(),
        "rate_line": stick.replace("    rate: 300 ", "    rate: 7   ").encode(),
        "duration_line": stick.replace("  duration: 2.0 ", "  duration: 1.0e-12 ").encode(),
    }
    cases = []
    for name, data in files.items():
        fs = {f"{name}.yaml": data}
        if name == "extends_binary":
            fs["bin.yaml"] = bytes(range(256)) * 4
        expect = "ok" if name == "bom_utf8" else "reject"
        line = None
        if name in ("rate_line", "duration_line"):
            key = "rate: 7" if name == "rate_line" else "duration: 1.0e-12"
            line = next(i + 1 for i, l in enumerate(data.decode().splitlines()) if key in l)
        cases.append(
            Case(
                "shape",
                ["validate", f"{name}.yaml"],
                expect=expect,
                files=fs,
                then_run=True,
                note=name,
                line=line,
            )
        )
    # one bad file in a scenarios/ folder must not break `replay list`
    cases.append(
        Case(
            "shape",
            ["list"],
            expect="ok",
            files={"scenarios/bad.yaml": bytes(range(256)), "scenarios/good.yaml": stick.encode()},
            note="list with a binary",
        )
    )
    return cases


# -- plug-in mismatches -------------------------------------------------------------------------


def mismatch_cases() -> list[Case]:
    child = f"extends: {HERE / STICK}\nplant: {{type: arm_rig, params: {{}}}}\n"
    return [
        Case(
            "mismatch",
            [
                "validate",
                STICK,
                "--set",
                "controller.type=catching",
                "--set",
                "controller.params={}",
            ],
            then_run=True,
            note="stick + catching",
        ),
        Case(
            "mismatch",
            ["validate", "child.yaml"],
            files={"child.yaml": child.encode()},
            then_run=True,
            note="stick controller on an arm",
        ),
        Case(
            "mismatch",
            ["validate", CATCH, "--set", "plant.params.initial_q=[0,0]"],
            then_run=True,
            note="initial_q of 2 on wam4",
        ),
        Case(
            "mismatch",
            ["validate", CATCH, "--set", "plant.type=airtable", "--set", "plant.params={}"],
            then_run=True,
            note="catching on the air table",
        ),
        Case(
            "mismatch",
            ["validate", CATCH, "--set", "plant.params.arm=wam7"],
            then_run=True,
            note="wam7 with 4-joint lists",
        ),
        Case(
            "mismatch",
            ["validate", CATCH, "--set", "plant.params.hand_initial=[0]"],
            then_run=True,
            note="hand_initial of 1",
        ),
        Case(
            "mismatch",
            ["validate", CATCH, "--set", "controller.params.held_joints=[J9]"],
            then_run=True,
            note="held J9",
        ),
        Case(
            "mismatch",
            ["validate", CATCH, "--set", "controller.params.selected_joint=J9"],
            then_run=True,
            note="selected J9",
        ),
        Case(
            "mismatch",
            ["validate", CATCH, "--set", "sensors={}"],
            then_run=True,
            note="catching without sensors",
        ),
    ]


# -- output paths ---------------------------------------------------------------------------------


def output_cases() -> list[Case]:
    stick = (HERE / STICK).read_text()
    short = ["--set", "timing.duration=0.05", "-q"]
    return [
        Case(
            "output",
            ["run", STICK, "-o", "afile/x.mcap", *short],
            files={"afile": b"I am a file"},
            note="-o under a file",
        ),
        Case("output", ["run", STICK, "-o", "/proc/x.mcap", *short], note="-o /proc"),
        Case(
            "output",
            ["run", "self.yaml", "-o", "self.yaml", *short],
            files={"self.yaml": stick.encode()},
            note="-o = the scenario",
        ),
        Case(
            "output",
            ["run", "esc.yaml", *short],
            files={"esc.yaml": stick.replace("name: stick_3step", "name: ../../../x").encode()},
            note="name leaves out/logs",
        ),
        Case(
            "output",
            ["run", STICK, "-o", "adir", *short],
            files={"adir/keep": b"x"},
            note="-o a directory",
        ),
        Case(
            "output",
            ["run", STICK, "-o", "notes.txt", *short],
            files={"notes.txt": b"my notes"},
            note="-o an existing non-log",
        ),
        Case("output", ["figures", "good.mcap", "-o", "/proc/figs"], note="figures -o /proc"),
        Case(
            "output",
            ["claims", "good.mcap", "--markdown", "/proc/claims.md"],
            note="claims --markdown /proc",
        ),
        Case("output", ["optimise", "scenarios/catch_initial.yaml"], note="optimise no file"),
        Case("output", ["optimise", CATCH, "-o", CATCH], note="optimise -o = the scenario"),
        Case("output", ["optimise", CATCH, "-o", "/proc/a.json"], note="optimise -o /proc"),
    ]


# -- logs --------------------------------------------------------------------------------------


def _mcap_with(messages: list) -> bytes:
    """A well-formed MCAP file holding ``messages`` [(topic, bytes)]."""
    import io

    from mcap.writer import Writer

    buf = io.BytesIO()
    w = Writer(buf)
    w.start()
    sid = w.register_schema("s", "jsonschema", b"{}")
    chans = {}
    for i, (topic, data) in enumerate(messages):
        if topic not in chans:
            chans[topic] = w.register_channel(topic, "json", sid)
        w.add_message(chans[topic], log_time=i, publish_time=i, data=data)
    w.finish()
    return buf.getvalue()


def log_files(good: bytes) -> dict:
    rng = random.Random(7)
    flipped = bytearray(good)
    for _ in range(64):
        i = rng.randrange(len(MAGIC) + 64, len(flipped) - 64)
        flipped[i] ^= 0xFF
    scen_msg = json.dumps(
        {"t": 0.0, "name": "x", "yaml": "name: x\n", "seed": 0, "version": "0"}
    ).encode()
    return {
        "empty.mcap": b"",
        "random.mcap": bytes(rng.randrange(256) for _ in range(4096)),
        "magic_only.mcap": MAGIC,
        "cut50.mcap": good[: len(good) // 2],
        "cut90.mcap": good[: len(good) * 9 // 10],
        "flipped.mcap": bytes(flipped),
        "no_paper.mcap": _mcap_with([("/scenario", scen_msg)]),
        "not_utf8.mcap": _mcap_with([("/scenario", b"\xff\xfe\x00bad"), ("/events", b"\xc3\x28")]),
        "not_json.mcap": _mcap_with([("/events", b"{not json")]),
        "json_list.mcap": _mcap_with([("/scenario", b"[1, 2]"), ("/events", b"42")]),
    }


MAGIC = b"\x89MCAP0\r\n"
DAMAGED = {
    "cut50.mcap",
    "cut90.mcap",
    "flipped.mcap",
    "not_utf8.mcap",
    "not_json.mcap",
    "json_list.mcap",
}


def log_cases(good: bytes) -> list[Case]:
    cases = []
    for name, data in log_files(good).items():
        for cmd in (["info", name], ["figures", name, "-o", "figs"], ["claims", name]):
            expect = "damaged" if name in DAMAGED else "reject"
            cases.append(
                Case("log", cmd, expect=expect, files={name: data}, note=f"{cmd[0]} {name}")
            )
    return cases


def golden_cases(good: bytes) -> list[Case]:
    manifest = (HERE / "data/golden/manifest.yaml").read_bytes()
    base = {"data/golden/manifest.yaml": manifest}
    out = []
    for label, files in {
        "empty stored log": {**base, "data/golden/stick_3step.mcap": b""},
        "random stored log": {**base, "data/golden/stick_3step.mcap": bytes(range(256)) * 8},
        "cut stored log": {**base, "data/golden/stick_3step.mcap": good[: len(good) // 2]},
        "broken manifest": {"data/golden/manifest.yaml": b"stick_3step: [unclosed\n"},
        "manifest a list": {"data/golden/manifest.yaml": b"- a\n- b\n"},
        "manifest no log key": {
            "data/golden/manifest.yaml": b"stick_3step: {scenario: scenarios/stick_3step.yaml}\n"
        },
        "manifest binary": {"data/golden/manifest.yaml": bytes(range(256))},
    }.items():
        out.append(
            Case(
                "golden", ["golden", "check", "stick_3step"], expect="fail", files=files, note=label
            )
        )
    return out


# -- running -----------------------------------------------------------------------------------


class Campaign:
    def __init__(self, replay: list, root: Path, work: Path, timeout: float) -> None:
        self.replay = replay
        self.root = root
        self.work = work
        self.timeout = timeout
        self.counts = collections.Counter()
        self.problems: list[str] = []
        self.calls = 0
        self.progress = ""

    def call(self, argv, cwd: Path, timeout=None):
        env = dict(os.environ, PYTHONUNBUFFERED="1", COLUMNS="200")
        self.calls += 1
        try:
            p = subprocess.run(
                self.replay + argv,
                cwd=cwd,
                capture_output=True,
                timeout=timeout or self.timeout,
                env=env,
            )
            return (
                p.returncode,
                p.stdout.decode(errors="replace"),
                p.stderr.decode(errors="replace"),
            )
        except subprocess.TimeoutExpired:
            return None, "", ""

    def flag(self, kind: str, case: Case, detail: str = "") -> None:
        self.counts[kind] += 1
        line = f"{kind:<13} {case.family:<9} {case.note} {detail}".rstrip()
        self.problems.append(line)
        if self.progress:
            with open(self.progress, "a") as f:
                f.write(line + "\n")

    def setup_dir(self, case: Case, idx: int) -> Path:
        d = self.work / f"c{idx:04d}"
        d.mkdir(parents=True)
        for sub in ("scenarios", "data"):
            if not (d / sub).exists() and not any(n.startswith(sub + "/") for n in case.files):
                os.symlink(self.root / sub, d / sub)
        for name, data in case.files.items():
            p = d / name
            p.parent.mkdir(parents=True, exist_ok=True)
            p.write_bytes(data)
        if case.family in ("golden",) and not (d / "scenarios").exists():
            os.symlink(self.root / "scenarios", d / "scenarios")
        if case.family in ("log", "output", "golden"):
            good = self.work / "good.mcap"
            if good.exists() and not (d / "good.mcap").exists():
                shutil.copy(good, d / "good.mcap")
        return d

    def judge(self, case: Case, rc, out: str, err: str) -> str:
        """The call's verdict: 'accepted', 'rejected', 'failed' or a problem kind."""
        text = out + err
        if rc is None:
            return "hang"
        if "Traceback (most recent call last)" in text:
            return "traceback"
        if rc < 0 or rc in (134, 139):
            return "abort"
        if rc == 0:
            return "accepted"
        if rc == 2:
            lines = [l for l in err.splitlines() if l.strip()]
            if case.argv[0] == "validate":
                lines = [l for l in lines if l.startswith("error:")] or lines
            if len(lines) != 1:
                return "not_one_line"
            if case.line is not None and f":{case.line}:" not in lines[0]:
                return "wrong_line"
            return "rejected"
        return "failed"

    def run_case(self, idx: int, case: Case) -> None:
        d = self.setup_dir(case, idx)
        rc, out, err = self.call(case.argv, d)
        v = self.judge(case, rc, out, err)
        last = (err.strip().splitlines() or out.strip().splitlines() or [""])[-1][:160]
        if v in ("hang", "traceback", "abort", "not_one_line", "wrong_line"):
            self.flag(v, case, last)
            return
        if case.family == "log":
            said = any(w in (out + err).lower() for w in ("truncated", "damaged", "incomplete"))
            if case.expect == "damaged" and v == "accepted" and not said:
                self.flag("silent", case, "exit 0 without saying the log is damaged")
            return
        if case.family == "golden":
            if v == "accepted":
                self.flag("silent", case, "golden check passed")
            return
        if case.family == "output":
            self.check_output(case, d, v, last)
            return
        if case.expect == "ok":
            if v != "accepted":
                self.flag("rejected_ok", case, last)
            return
        if v == "accepted" and case.argv[0] == "validate":
            self.flag("accepted", case)
            if case.then_run:
                self.run_after_validate(case, d)
        elif v == "failed" and case.argv[0] != "validate":
            pass

    def run_after_validate(self, case: Case, d: Path) -> None:
        argv = ["run", *case.argv[1:], "-q", "-o", "after.mcap"]
        if not any("timing.duration" in a for a in argv):
            argv += ["--set", "timing.duration=0.03"]
        rc, out, err = self.call(argv, d)
        v = self.judge(case, rc, out, err)
        last = (err.strip().splitlines() or [""])[-1][:160]
        if v in ("hang", "traceback", "abort"):
            self.flag(v, case, "(run) " + last)
        elif v == "accepted":
            self.flag("ran", case)
        else:
            self.flag("run_failed", case, last)

    def check_output(self, case: Case, d: Path, verdict: str, last: str) -> None:
        for name, data in case.files.items():
            p = d / name
            if p.is_file() and p.read_bytes() != data:
                self.flag("data_loss", case, f"input {name} overwritten")
        if "esc.yaml" in case.files:
            escaped = [
                p
                for p in (d / "x.mcap", d.parent / "x.mcap", d.parent.parent / "x.mcap")
                if p.exists()
            ]
            if escaped:
                self.flag("data_loss", case, f"wrote outside out/logs: {escaped[0]}")
                for p in escaped:
                    p.unlink()
            return
        if verdict not in ("rejected",):
            self.flag("not_rejected", case, last)

    # -- Ctrl-C, kill and failed runs ----------------------------------------------------------

    def interrupt_cases(self) -> None:
        delays = [0.05, 0.15, 0.3, 1.0, 2.5, 4.0, 6.0]
        for i, delay in enumerate(delays):
            for sig in (signal.SIGINT, signal.SIGKILL) if delay in (2.5, 6.0) else (signal.SIGINT,):
                case = Case("signal", [], note=f"{signal.Signals(sig).name} at {delay} s")
                d = self.work / f"sig{i}_{sig}"
                d.mkdir()
                os.symlink(self.root / "scenarios", d / "scenarios")
                os.symlink(self.root / "data", d / "data")
                good = self.work / "good.mcap"
                shutil.copy(good, d / "run.mcap")  # an old good log at the same path
                self.calls += 1
                p = subprocess.Popen(
                    self.replay + ["run", STICK, "-o", "run.mcap", "-q"],
                    cwd=d,
                    stdout=subprocess.PIPE,
                    stderr=subprocess.PIPE,
                )
                time.sleep(delay)
                p.send_signal(sig)
                try:
                    out, err = p.communicate(timeout=60)
                except subprocess.TimeoutExpired:
                    p.kill()
                    self.flag("hang", case)
                    continue
                text = (out + err).decode(errors="replace")
                if "Traceback" in text:
                    self.flag("traceback", case, text.strip().splitlines()[-1][:120])
                if "Aborted!" in text:
                    self.flag("not_clean", case, "Aborted!")
                if sig == signal.SIGINT and p.returncode not in (130, 0):
                    self.flag("not_clean", case, f"exit {p.returncode}")
                if (d / "run.mcap").read_bytes() != good.read_bytes() and p.returncode != 0:
                    self.flag("data_loss", case, "the old log was replaced by an unfinished run")
                for log in sorted(d.glob("run*.mcap*")):
                    if log.name == "run.mcap" and log.read_bytes() == good.read_bytes():
                        continue
                    self.check_readable(case, d, log)

    def check_readable(self, case: Case, d: Path, log: Path) -> None:
        rc, out, err = self.call(["info", log.name], d)
        if rc != 0 or "Traceback" in out + err:
            self.flag("data_loss", case, f"`replay info {log.name}`: exit {rc}")
            return
        if "interrupted" not in out and "outcome" not in out and not log.name.endswith(".part"):
            self.flag("data_loss", case, f"{log.name}: no interrupted/outcome event")
        try:
            from mcap.stream_reader import StreamReader

            with open(log, "rb") as f:
                for _ in StreamReader(f, skip_magic=False).records:
                    pass
        except Exception as exc:  # noqa: BLE001
            if not log.name.endswith(".part"):
                self.flag("data_loss", case, f"mcap reader: {type(exc).__name__}")

    def failed_run_keeps_old_log(self) -> None:
        """A run that fails (a non-finite value) must not replace a good log at its path."""
        d = self.work / "failed_run"
        d.mkdir()
        os.symlink(self.root / "scenarios", d / "scenarios")
        os.symlink(self.root / "data", d / "data")
        good = (self.work / "good.mcap").read_bytes()
        (d / "run.mcap").write_bytes(good)
        case = Case("failed", [], note="stick with a huge speed (non-finite at run time)")
        rc, out, err = self.call(
            ["run", STICK, "-o", "run.mcap", "-q", "--set", "plant.params.initial.vy=-1e200"], d
        )
        if "Traceback" in out + err:
            self.flag("traceback", case)
        if (d / "run.mcap").read_bytes() != good and rc != 0:
            self.flag("data_loss", case, "old log replaced by the failed run")

    def viewer_cases(self) -> None:
        d = self.work / "viewer"
        d.mkdir()
        shutil.copy(self.work / "good.mcap", d / "good.mcap")
        port = 18000 + random.Random(os.getpid()).randrange(1000)
        for host in ("127.0.0.1", "0.0.0.0"):
            case = Case("viewer", [], note=f"bare TCP connect, --host {host}")
            self.calls += 1
            p = subprocess.Popen(
                self.replay
                + ["view", "good.mcap", "--port", str(port), "--host", host, "--timeout", "25"],
                cwd=d,
                stdout=subprocess.PIPE,
                stderr=subprocess.PIPE,
            )
            deadline = time.time() + 20
            connected = False
            while time.time() < deadline and not connected:
                try:
                    with socket.create_connection(("127.0.0.1", port), timeout=1) as s:
                        connected = True
                        s.sendall(b"hello\r\n\r\n")
                        time.sleep(0.5)
                except OSError:
                    time.sleep(0.3)
            for _ in range(3):
                try:
                    socket.create_connection(("127.0.0.1", port), timeout=1).close()
                except OSError:
                    pass
            time.sleep(1.0)
            p.send_signal(signal.SIGINT)
            try:
                out, err = p.communicate(timeout=30)
            except subprocess.TimeoutExpired:
                p.kill()
                out, err = p.communicate()
                self.flag("hang", case)
            text = (out + err).decode(errors="replace")
            if not connected:
                self.flag(
                    "no_server",
                    case,
                    text.strip().splitlines()[-1:][0][:100] if text.strip() else "",
                )
            if "Traceback" in text:
                self.flag("traceback", case)
            if host == "0.0.0.0" and "warning" not in text.lower():
                self.flag("no_warning", case, "0.0.0.0 served without a warning")
            port += 1


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--replay", default=str(HERE / ".venv/bin/replay"))
    ap.add_argument("--root", default=str(HERE))
    ap.add_argument("--only", default="")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=90.0)
    ap.add_argument("--report", default="")
    ap.add_argument(
        "--sample",
        type=int,
        default=0,
        help="run a seeded sample of this many value cases (0: all)",
    )
    args = ap.parse_args()
    root = Path(args.root).resolve()
    work = Path(tempfile.mkdtemp(prefix="campaign_"))
    c = Campaign(shlex.split(args.replay), root, work, args.timeout)
    if args.report:
        c.progress = args.report + ".progress"
        Path(c.progress).write_text("")
    t0 = time.time()
    rc, out, err = c.call(
        ["run", STICK, "-o", str(work / "good.mcap"), "-q", "--set", "timing.duration=0.6"], root
    )
    if rc != 0:
        sys.exit(f"cannot make the good log: {err}")
    good = (work / "good.mcap").read_bytes()
    families = {
        "value": value_cases,
        "shape": shape_cases,
        "mismatch": mismatch_cases,
        "output": output_cases,
        "log": lambda: log_cases(good),
        "golden": lambda: golden_cases(good),
    }
    only = set(args.only.split(",")) if args.only else None
    cases = []
    for name, make in families.items():
        if only is None or name in only:
            made = make()
            if name == "value" and args.sample and args.sample < len(made):
                made = random.Random(1).sample(made, args.sample)
            cases += made
    with ThreadPoolExecutor(max_workers=args.jobs) as ex:
        list(ex.map(lambda ic: c.run_case(*ic), enumerate(cases)))
    if only is None or "signal" in only:
        c.interrupt_cases()
        c.failed_run_keeps_old_log()
    if only is None or "viewer" in only:
        c.viewer_cases()
    lines = [
        f"cases: {len(cases)} generated + signal/viewer; replay calls: {c.calls}; "
        f"wall {time.time() - t0:.0f} s"
    ]
    for kind in (
        "traceback",
        "abort",
        "hang",
        "accepted",
        "ran",
        "run_failed",
        "not_one_line",
        "wrong_line",
        "silent",
        "data_loss",
        "not_rejected",
        "not_clean",
        "no_warning",
        "rejected_ok",
        "no_server",
    ):
        lines.append(f"{kind:<13} {c.counts.get(kind, 0)}")
    text = "\n".join(lines + ["", *sorted(c.problems)])
    print(text)
    if args.report:
        Path(args.report).write_text(text + "\n")
    shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
