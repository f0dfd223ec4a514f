"""The MCAP file itself, written by foxglove-sdk's MCAP writer (Rust, the ``mcap`` crate):
indexed, chunked, each chunk zstd-compressed (level 1, one thread, so the same messages give
the same bytes), with chunk CRCs and a summary with statistics, chunk and
metadata indexes and summary offsets. Nothing of the format is written here; this module only
fixes the options a log uses so that the writer and its tests and benchmarks make the same
files.

Measured against the ``mcap`` library's ``Writer`` it replaces (same messages, one process):
~2.0 against ~6.5 us a ~60-byte JSON message, ~7 against ~17 us a 16 KiB image; in a run
(``python -m tools.bench.runs``, stick_3step, alternated on a loaded host) a JSON message 10.4 /
7.6 / 9.9 -> 6.5 / 4.3 / 5.3 us. Its ``Writer`` still
writes test files (tests/) and ``mcap``'s reader reads every log.

zstd level 1, not the default 3: a catch run's chunks are ~94 % camera images (2000 16 KiB
frames a simulated second), and level 3's larger match tables are cold in the cache by each
chunk's end in a run (its writes cost ~2.3x their cost in a loop of writes alone). Measured
(catch_optimised, whole runs alternated, median CPU s a run): level 3 0.2484 / 0.2306 /
0.2229, level 1 0.2290 / 0.2126 / 0.2011 (~8 % of the run), and the file is ~1 % smaller
(554 -> 547 kB for 0.47 s); lz4 was as fast but 64 % larger."""

from __future__ import annotations

from typing import Any

import foxglove
from foxglove.mcap import MCAPCompression, MCAPWriteOptions, MCAPWriter

MAGIC = b"\x89MCAP0\r\n"  # the MCAP file's leading and trailing magic (the MCAP spec)
ZSTD_LEVEL = 1  # the chunks' zstd level (see above)


def mcap_writer(
    stream: Any, context: foxglove.Context, *, chunk_size: int, compression: str = "zstd"
) -> MCAPWriter:
    """The SDK's writer on ``stream`` (which must have ``write``, ``seek`` and ``flush``: a
    chunk's header is written, then its data, then the header again with the lengths) for the
    channels of ``context``, with every index, chunks of ``chunk_size`` bytes compressed with
    ``compression`` ("zstd" or "") in this thread."""
    if compression not in ("zstd", ""):
        raise ValueError(f"compression {compression!r}: zstd or '' (none)")
    options = MCAPWriteOptions(
        compression=MCAPCompression.Zstd if compression else None,
        profile="",
        chunk_size=chunk_size,
        use_chunks=True,
        emit_statistics=True,
        emit_summary_offsets=True,
        emit_message_indexes=True,
        emit_chunk_indexes=True,
        repeat_channels=True,
        repeat_schemas=True,
        calculate_chunk_crcs=True,
        calculate_summary_section_crc=True,
        calculate_data_section_crc=False,  # (as the mcap library's Writer wrote it)
        compression_threads=0,  # (threads would make the bytes depend on the machine)
        compression_level=ZSTD_LEVEL if compression else 0,
    )
    return foxglove.open_mcap(stream, context=context, writer_options=options)
