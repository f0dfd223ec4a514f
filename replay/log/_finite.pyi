"""Types of the log's compiled finiteness check (replay/log/_finite.c documents it)."""

from typing import Any

def finite(payload: Any) -> bool | None: ...
