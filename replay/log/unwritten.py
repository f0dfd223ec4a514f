"""A run without a log (``Runner.run(None)``: a sweep that keeps neither logs nor log metrics).

Every message is encoded as :meth:`LogWriter.write` encodes it (so a non-finite number raises
:class:`NonFiniteValueError`, a payload JSON cannot hold fails alike, and the run ends as it
does with a log) and counted; nothing is compressed or written, and no Foxglove topics (3-D
frames, camera images) are made."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from replay.log.writer import encode


class UnwrittenLog:
    """What the runner writes to when it keeps no log: ``write``/``write_all`` check and count."""

    def __init__(self) -> None:
        self.count = 0

    def write(self, topic: str, payload: Any, t_ns: int) -> None:
        encode(topic, payload)
        self.count += 1

    def write_all(self, messages: dict[str, Any], t_ns: int) -> None:
        for topic, payload in messages.items():
            for item in payload if isinstance(payload, list) else (payload,):
                self.write(topic, item, t_ns)

    def metadata(self, name: str, data: dict[str, str]) -> None:
        pass

    def close(self, status: str = "") -> Path:
        return Path(os.devnull)
