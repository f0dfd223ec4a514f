"""The log package's own error types."""

from replay.limits import LimitError


class LogError(Exception):
    """A log could not be written or read."""


class LogLimitError(LogError, LimitError):
    """A log holds more than a reader will load (a chunk or message over ``message_bytes``, a
    topic over ``series_bytes``): one line naming the limit and its environment variable."""


class NotALogError(LogError):
    """The file is not an MCAP file."""


class NonFiniteValueError(LogError):
    """A payload held NaN or infinity (NaN is not JSON): a physics error, not a message."""

    def __init__(self, topic: str, payload: dict, fields: list[str] | None = None):
        self.topic = topic
        self.payload = payload
        bad = sorted(_non_finite_paths(payload)) if fields is None else fields
        self.fields = bad
        super().__init__(f"non-finite value on {topic}: {', '.join(bad) or '?'}")


def _non_finite_paths(value, path=""):
    import math

    if isinstance(value, float):
        if not math.isfinite(value):
            yield path or "(value)"
    elif isinstance(value, dict):
        for k, v in value.items():
            yield from _non_finite_paths(v, f"{path}.{k}" if path else str(k))
    elif isinstance(value, (list, tuple)):
        for i, v in enumerate(value):
            yield from _non_finite_paths(v, f"{path}[{i}]")


class LogWriteError(LogError):
    """Writing or finishing a log failed (a full disk, an I/O error): a system fault, not bad
    input; ``errno`` says which."""

    def __init__(self, message: str, errno: int | None = None) -> None:
        super().__init__(message)
        self.errno = errno
