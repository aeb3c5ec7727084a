"""A chunk's declared uncompressed size is not trusted: 98 KB of zstd declaring 3 GiB was
decompressed whole. A chunk declaring more than MAX_CHUNK_BYTES is damaged, and none is
decompressed past what it declares (lz4 too)."""

from __future__ import annotations

import tracemalloc
import zlib

import lz4.frame
import pytest
import zstandard
from mcap.records import Chunk

from cyborg.record.scan import MAX_CHUNK_BYTES, decompress

ZEROS = bytes(8 * 2**20)


def _chunk(compression: str, data: bytes, declared: int, crc: int = 0) -> Chunk:
    return Chunk(compression=compression, data=data, message_start_time=0, message_end_time=0,
                 uncompressed_crc=crc, uncompressed_size=declared)


@pytest.mark.parametrize("compression", ["zstd", "lz4", ""])
def test_a_chunk_declaring_more_than_the_cap_is_refused_before_decompressing(
        compression: str) -> None:
    data = {"zstd": zstandard.ZstdCompressor().compress, "lz4": lz4.frame.compress,
            "": bytes}[compression](b"x")
    with pytest.raises(ValueError, match=r"declares 3,221,225,472 bytes uncompressed, more than "
                                         r"the 256 MiB a chunk may hold"):
        decompress(_chunk(compression, data, 3 * 2**30))
    assert MAX_CHUNK_BYTES == 256 * 2**20


@pytest.mark.parametrize("compression", ["zstd", "lz4"])
def test_a_chunk_is_never_decompressed_past_what_it_declares(compression: str) -> None:
    compress = {"zstd": zstandard.ZstdCompressor().compress, "lz4": lz4.frame.compress}
    data = compress[compression](ZEROS)  # a few KB that hold 8 MiB
    tracemalloc.start()
    try:
        with pytest.raises(ValueError):
            decompress(_chunk(compression, data, 1000, crc=zlib.crc32(ZEROS[:1000]) + 1))
        _now, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 2**20, f"{peak:,} bytes taken for a chunk that declares 1,000"
    assert decompress(_chunk(compression, data, len(ZEROS), crc=zlib.crc32(ZEROS))) == ZEROS
