"""The viewer's own error type: one clear line for the user, never a traceback."""

from replay.log import LogError


class ViewerError(LogError):
    """A log cannot be shown (not MCAP, empty, nothing drawable) or the server cannot start."""
