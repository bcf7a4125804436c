"""WAV input: mono or multichannel, 8/16/24/32-bit integer or 32/64-bit float, any sample rate.

The RIFF header is parsed here, chunk by chunk, with every size checked against the file (Microsoft's RIFF/WAVE
and WAVE_FORMAT_EXTENSIBLE layouts): a truncated or inconsistent header is a ValueError naming what is wrong,
never a struct or division error. Reading is by frame blocks (:func:`read_frames`), so that a caller can walk
a long recording without holding it whole. Sample rates Hz; samples float64 in [-1, 1].
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from matcad.inputs import open_regular

MAX_CHUNKS = 1024
"""Chunks scanned for 'fmt ' and 'data' before the file is refused (real files have < 10)."""
MAX_FMT_BYTES = 1024
"""The 'fmt ' chunk is 16, 18 or 40 bytes; a larger one is not a WAV header."""
MAX_CHANNELS = 64
PCM, IEEE_FLOAT, EXTENSIBLE = 0x0001, 0x0003, 0xFFFE


@dataclass(frozen=True)
class WavInfo:
    """What the header says: rate (Hz), channels, 'int' or 'float' samples of ``bits`` bits, where the sample
    data start (bytes) and how many whole frames the file really holds."""

    sample_rate_hz: float
    channels: int
    sample_format: str
    bits: int
    data_offset: int
    frames: int
    big_endian: bool = False

    @property
    def block_align(self) -> int:
        return self.channels * self.bits // 8

    @property
    def duration_s(self) -> float:
        return self.frames / self.sample_rate_hz


def _bad(path, why: str) -> ValueError:
    return ValueError(f"recording {path}: not a readable WAV file ({why})")


def _parse_fmt(path, body: bytes, end: str) -> tuple[str, int, int, float]:
    if len(body) < 16:
        raise _bad(path, f"'fmt ' chunk of {len(body)} bytes, needs 16")
    tag, channels, rate, _, block_align, bits = struct.unpack(end + "HHIIHH", body[:16])
    if tag == EXTENSIBLE:
        if len(body) < 26:
            raise _bad(path, "WAVE_FORMAT_EXTENSIBLE without its sub-format")
        tag = struct.unpack(end + "H", body[24:26])[0]
    kinds = {PCM: ("int", (8, 16, 24, 32, 64)), IEEE_FLOAT: ("float", (32, 64))}
    if tag not in kinds:
        raise _bad(path, f"sample format tag 0x{tag:04x}; only PCM integer and IEEE float are read")
    kind, allowed_bits = kinds[tag]
    if bits not in allowed_bits:
        raise _bad(path, f"{bits}-bit {kind} samples; allowed {', '.join(map(str, allowed_bits))}")
    if not 1 <= channels <= MAX_CHANNELS:
        raise _bad(path, f"{channels} channels; allowed 1-{MAX_CHANNELS}")
    if rate < 1:
        raise _bad(path, "sample rate 0 Hz")
    if block_align != channels * bits // 8:
        raise _bad(path, f"block align {block_align} bytes, but {channels} x {bits}-bit samples need "
                         f"{channels * bits // 8}")
    return kind, bits, channels, float(rate)


def read_info(path: str | Path) -> WavInfo:
    """Parse the header of ``path`` without reading its samples. Raises ValueError (InputError) on any
    unreadable, truncated or inconsistent header."""
    with open_regular(path, "recording") as f:
        size = f.seek(0, 2)
        f.seek(0)
        def skip(n: int, cid: bytes, fmt) -> None:
            if f.tell() + n > size:
                raise _bad(path, "no 'data' chunk" if fmt else "no 'fmt ' chunk")
            f.seek(n, 1)

        (kind, bits, channels, rate), end, csize = _riff_header(path, f.read, skip, "")
        offset = f.tell()
        frames = min(csize, size - offset) // (channels * bits // 8)
        if frames <= 0:
            raise ValueError(f"recording {path}: holds no samples")
        return WavInfo(rate, channels, kind, bits, offset, frames, end == ">")


def _riff_header(name, read, skip, hint: str):
    """Walk a RIFF/RIFX WAVE header up to its 'data' chunk: ((kind, bits, channels, rate), byte order, data
    chunk size). ``read(n)`` returns up to n bytes, ``skip(n, chunk id, fmt so far)`` passes over an unknown
    chunk (the caller bounds it); ``hint`` is added to the no-header message."""
    head = read(12)
    if len(head) < 12 or head[:4] not in (b"RIFF", b"RIFX") or head[8:12] != b"WAVE":
        raise _bad(name, f"no RIFF/WAVE header{hint}")
    end = ">" if head[:4] == b"RIFX" else "<"
    fmt = None
    for _ in range(MAX_CHUNKS):
        chunk = read(8)
        if len(chunk) < 8:
            raise _bad(name, "no 'data' chunk" if fmt else "no 'fmt ' chunk")
        cid, csize = chunk[:4], struct.unpack(end + "I", chunk[4:])[0]
        if cid == b"fmt ":
            if csize > MAX_FMT_BYTES:
                raise _bad(name, f"'fmt ' chunk of {csize} bytes")
            fmt = _parse_fmt(name, read(csize + (csize & 1))[:csize], end)
        elif cid == b"data":
            if fmt is None:
                raise _bad(name, "'data' chunk before the 'fmt ' chunk")
            return fmt, end, csize
        else:
            skip(csize + (csize & 1), cid, fmt)
    raise _bad(name, f"no 'data' chunk among the first {MAX_CHUNKS} chunks")


def _decode(raw: bytes, info: WavInfo) -> np.ndarray:
    """Frames × channels as float64 in [-1, 1]."""
    end = ">" if info.big_endian else "<"
    if info.sample_format == "float":
        x = np.frombuffer(raw, dtype=f"{end}f{info.bits // 8}").astype(np.float64)
    elif info.bits == 8:
        x = (np.frombuffer(raw, dtype=np.uint8).astype(np.float64) - 128.0) / 128.0
    elif info.bits == 24:
        b = np.frombuffer(raw, dtype=np.uint8).reshape(-1, 3).astype(np.int32)
        hi, lo = (b[:, 0], b[:, 2]) if info.big_endian else (b[:, 2], b[:, 0])
        x = ((hi << 24) | (b[:, 1] << 16) | (lo << 8)).astype(np.float64) / 2.0 ** 31
    else:
        x = np.frombuffer(raw, dtype=f"{end}i{info.bits // 8}").astype(np.float64) / 2.0 ** (info.bits - 1)
    return x.reshape(-1, info.channels)


FLOAT_PEAK_MAX = 1e12
"""Largest |sample| a float recording may hold: its full scale is ±1, and integer sample values saved as floats
reach 2³¹ ≈ 2.1e9; beyond 1e12 the numbers are no recording, and their squares would overflow the spectra."""


def _mono(x: np.ndarray, info: WavInfo, name) -> np.ndarray:
    """Frames × channels → mono (channels averaged); ValueError on NaN, infinite or absurdly large samples (checked
    before averaging, which could overflow)."""
    if not np.all(np.isfinite(x)):
        raise ValueError(f"recording {name}: contains NaN or infinite samples")
    peak = float(np.max(np.abs(x), initial=0.0))
    if peak > FLOAT_PEAK_MAX:
        raise ValueError(f"recording {name}: float samples reach {peak:.3g}; a float WAV's full scale is ±1 and "
                         f"no recording holds samples beyond ±{FLOAT_PEAK_MAX:g}")
    return x[:, 0] if info.channels == 1 else x.mean(axis=1)


def read_frames(path: str | Path, info: WavInfo, start: int = 0, count: int | None = None) -> np.ndarray:
    """Frames ``start`` .. ``start + count`` of ``path`` as mono float64 in [-1, 1] (channels averaged).
    Raises ValueError on NaN, infinite or absurdly large (:data:`FLOAT_PEAK_MAX`) samples."""
    count = info.frames - start if count is None else max(0, min(count, info.frames - start))
    with open_regular(path, "recording") as f:
        f.seek(info.data_offset + start * info.block_align)
        raw = f.read(count * info.block_align)
    return _mono(_decode(raw[:len(raw) // info.block_align * info.block_align], info), info, path)


def read_mono(path: str | Path) -> tuple[np.ndarray, float]:
    """Samples as float64 in [-1, 1] (channels averaged) and the sample rate (Hz). Raises ValueError."""
    info = read_info(path)
    return read_frames(path, info), info.sample_rate_hz


BLOCK_FRAMES = 1 << 16
"""Frames per block when streaming (~1.5 s at 44.1 kHz: ~10 MB of spectra whatever the recording's length)."""
RAW_FORMATS = {"s16le": ("int", 16), "s24le": ("int", 24), "s32le": ("int", 32), "u8": ("int", 8),
               "f32le": ("float", 32), "f64le": ("float", 64)}
"""Raw PCM sample formats for a live stream (names as in ffmpeg/arecord), little-endian."""


def iter_blocks(path: str | Path, info: WavInfo | None = None, block_frames: int = BLOCK_FRAMES):
    """Mono float64 blocks of ``path`` in order, ``block_frames`` frames each: memory bounded by one block."""
    info = info or read_info(path)
    for start in range(0, info.frames, block_frames):
        yield read_frames(path, info, start, block_frames)


def _read_exact(stream, n: int) -> bytes:
    out = b""
    while len(out) < n:
        chunk = stream.read(n - len(out))
        if not chunk:
            break
        out += chunk
    return out


def stream_info(stream, rate_hz: float | None = None, sample_format: str | None = None,
                channels: int = 1, name: str = "standard input") -> WavInfo:
    """Header of a live byte stream: parsed from a WAV header when ``sample_format`` is None (a streaming WAV may
    give 0 or 0xFFFFFFFF as its data size: it is read to its end), else raw PCM at ``rate_hz`` (Hz)."""
    if sample_format is not None:
        if sample_format not in RAW_FORMATS:
            raise ValueError(f"--format {sample_format!r} invalid, must be one of {', '.join(RAW_FORMATS)}")
        if rate_hz is None or not 1 <= rate_hz <= 1e7:
            raise ValueError(f"--rate {rate_hz} invalid: raw PCM needs a sample rate of 1-1e7 Hz")
        if not 1 <= channels <= MAX_CHANNELS:
            raise ValueError(f"--channels {channels} invalid, must be 1-{MAX_CHANNELS}")
        kind, bits = RAW_FORMATS[sample_format]
        return WavInfo(float(rate_hz), channels, kind, bits, 0, -1)
    def skip(n: int, cid: bytes, fmt) -> None:
        if n > MAX_FMT_BYTES * 64:
            raise _bad(name, f"a '{cid.decode('latin-1')}' chunk of {n} bytes before the data")
        _read_exact(stream, n)

    (kind, bits, channels, rate), end, csize = _riff_header(
        name, lambda n: _read_exact(stream, n), skip, " (raw PCM needs --format and --rate)")
    frames = -1 if csize in (0, 0xFFFFFFFF) else csize // (channels * bits // 8)
    return WavInfo(rate, channels, kind, bits, 0, frames, end == ">")


def iter_stream(stream, info: WavInfo, block_frames: int = 4096, name: str = "standard input"):
    """Mono float64 blocks from a byte stream as they arrive (``block_frames`` frames, ~93 ms at 44.1 kHz, so that
    live output keeps up), until its end or ``info.frames`` frames."""
    left = info.frames
    while left != 0:
        want = block_frames if left < 0 else min(block_frames, left)
        raw = _read_exact(stream, want * info.block_align)
        whole = len(raw) // info.block_align * info.block_align
        if whole == 0:
            return
        x = _mono(_decode(raw[:whole], info), info, name)
        left = left - len(x) if left > 0 else left
        yield x
        if whole < want * info.block_align:
            return
