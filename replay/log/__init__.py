"""MCAP run logs: the platform's contract (docs/DESIGN.md). Symmetric writer and reader."""

from replay.log.errors import LogError, NonFiniteValueError, NotALogError
from replay.log.reader import LogMessage, LogReader
from replay.log.writer import LogWriter, seconds_to_ns

__all__ = [
    "LogError",
    "LogMessage",
    "LogReader",
    "LogWriter",
    "NonFiniteValueError",
    "NotALogError",
    "seconds_to_ns",
]
