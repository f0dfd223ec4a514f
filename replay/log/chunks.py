"""The MCAP file itself, written by the ``mcap`` library's ``Writer``: indexed, chunked, each
chunk zstd-compressed (the library's level 3), a summary with statistics, chunk and metadata
indexes and summary offsets. Nothing of the format is written here; this module only fixes the
options a log uses so that the writer and its tests and benchmarks make the same files.

Measured on whole runs against the hand-written chunk builder it replaces (docs/DESIGN.md,
"The log"): +2-3 us a message, the same file structure (the library's own bytes were what that
builder was held to)."""

from __future__ import annotations

from typing import Any

from mcap.writer import CompressionType, IndexType, Writer

MAGIC = b"\x89MCAP0\r\n"  # the MCAP file's leading and trailing magic (the MCAP spec)


def mcap_writer(stream: Any, *, chunk_size: int, compression: str = "zstd") -> Writer:
    """The library's writer on ``stream`` (which must have ``write`` and ``tell``) with every
    index, chunks of ``chunk_size`` bytes compressed with ``compression`` ("zstd" or "")."""
    if compression not in ("zstd", ""):
        raise ValueError(f"compression {compression!r}: zstd or '' (none)")
    return Writer(
        stream,
        chunk_size=chunk_size,
        compression=CompressionType.ZSTD if compression else CompressionType.NONE,
        index_types=IndexType.ALL,
    )
