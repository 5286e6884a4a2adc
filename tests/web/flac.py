"""A FLAC "decompression bomb": constant-level frames of 65,535 samples, ~14 bytes each.

Written bit by bit from the FLAC format specification (frame header with CRC-8, one
CONSTANT subframe, CRC-16), so that hours of audio cost a few kilobytes and no encoder
is needed.
"""

from __future__ import annotations

BLOCK_SAMPLES = 65_535  # the largest FLAC block
RATE_HZ = 48_000
BYTES_PER_FRAME = 14  # for frame numbers up to 2,047 (two-byte UTF-8 coding)


def _crc8(data: bytes) -> int:
    crc = 0
    for byte in data:
        crc ^= byte
        for _ in range(8):
            crc = ((crc << 1) ^ 0x07) & 0xFF if crc & 0x80 else (crc << 1) & 0xFF
    return crc


def _crc16(data: bytes) -> int:
    crc = 0
    for byte in data:
        crc ^= byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x8005) & 0xFFFF if crc & 0x8000 else (crc << 1) & 0xFFFF
    return crc


def _stream_info(total_samples: int) -> bytes:
    """The STREAMINFO block: 48 kHz, mono, 16 bit, ``total_samples`` (0 = unknown)."""
    info = BLOCK_SAMPLES.to_bytes(2, "big") * 2 + bytes(6)  # block sizes; frame sizes unknown
    packed = (RATE_HZ << 44) | (0 << 41) | (15 << 36) | total_samples
    info += packed.to_bytes(8, "big") + bytes(16)  # no MD5
    return bytes([0x80]) + len(info).to_bytes(3, "big") + info  # last metadata block


def _frame(number: int, level: int) -> bytes:
    # sync + fixed blocking; 16-bit block size at the end, 48 kHz; mono, 16 bit
    head = bytes([0xFF, 0xF8, 0x7A, 0x08]) + chr(number).encode("utf-8", "surrogatepass")
    head += (BLOCK_SAMPLES - 1).to_bytes(2, "big")
    head += bytes([_crc8(head)])
    frame = head + bytes([0x00]) + level.to_bytes(2, "big", signed=True)  # CONSTANT subframe
    return frame + _crc16(frame).to_bytes(2, "big")


def flac_bomb(frames: int, *, level: int = 8000, declare_length: bool = False) -> bytes:
    """A FLAC file of ``frames`` x 65,535 samples at a constant ``level`` (DC).

    Args:
        frames: number of frames (each 1.365 s of audio).
        level: the sample value of every sample.
        declare_length: write the total sample count into STREAMINFO; without it the
            length is only known by decoding.
    """
    total = frames * BLOCK_SAMPLES if declare_length else 0
    return b"".join([b"fLaC", _stream_info(total), *(_frame(n, level) for n in range(frames))])


def bomb_duration_s(frames: int) -> float:
    """Seconds of audio in :func:`flac_bomb` of ``frames`` frames."""
    return frames * BLOCK_SAMPLES / RATE_HZ
