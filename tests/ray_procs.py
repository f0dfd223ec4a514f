"""What the Ray tests look at: this machine's processes (/proc), by session, and its listeners
(``ss``); nothing here starts or stops anything."""

from __future__ import annotations

import contextlib
import ipaddress
import os
import re
import subprocess
import time


def procs() -> dict[int, tuple[int, int, str, str]]:
    """pid -> (parent, session, state, name) of every live process (zombies left out)."""
    out = {}
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            with open(f"/proc/{pid}/stat", "rb") as f:
                stat = f.read()
        except OSError:
            continue
        name, rest = stat.split(b"(", 1)[1].rsplit(b")", 1)
        fields = rest.split()
        if fields[0] != b"Z":
            out[int(pid)] = (int(fields[1]), int(fields[3]), fields[0].decode(), name.decode())
    return out


def session(sid: int) -> dict[int, str]:
    """pid -> name of every live process of session ``sid``."""
    return {p: name for p, (_, s, _, name) in procs().items() if s == sid}


def listeners() -> list[tuple[int, str, str]]:
    """(pid, local address, ss line) of every TCP/UDP listener, from ``ss -Hltunp``."""
    text = subprocess.run(
        ["ss", "-Hltunp"], capture_output=True, text=True, check=True, timeout=10
    ).stdout
    return [
        (int(pid), line.split()[4], line)
        for line in text.splitlines()
        for pid in re.findall(r"pid=(\d+)", line)
    ]


def loopback(address: str) -> bool:
    host = address.rsplit(":", 1)[0].strip("[]").split("%")[0]
    try:
        ip = ipaddress.ip_address(host)
    except ValueError:
        return False  # "*", "0.0.0.0" is parsed; a name is not loopback
    if isinstance(ip, ipaddress.IPv6Address) and ip.ipv4_mapped:
        ip = ip.ipv4_mapped
    return ip.is_loopback


def wait_for(what, within: float, proc: subprocess.Popen | None = None):
    """``what()`` once it is true (polled every 0.1 s), or its last value after ``within`` s or
    once ``proc`` has ended."""
    end = time.monotonic() + within
    while time.monotonic() < end:
        got = what()
        if got:
            return got
        if proc is not None and proc.poll() is not None:
            break
        time.sleep(0.1)
    return what()


@contextlib.contextmanager
def ending(proc: subprocess.Popen):
    """A process the test did not see to its end is killed (a sweep's keeper then clears its
    Ray)."""
    try:
        yield proc
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
