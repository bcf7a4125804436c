"""Compressed recordings (FLAC, OGG Vorbis/Opus) through libsndfile's Python binding ``soundfile``.

An optional extra (``pip install 'matcad[audio]'``), imported only when such a file is given: WAV and raw PCM need
nothing beyond numpy (:mod:`matcad.loop.wav`). Without the library a FLAC/OGG recording is bad input (exit 2) with
the command that installs it. Samples come back as mono float64 in [-1, 1] (channels averaged), in blocks, like
:func:`matcad.loop.wav.iter_blocks`: memory stays bounded by one block whatever the recording's length.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

SUFFIXES = (".flac", ".ogg", ".oga", ".opus")
"""File endings read through soundfile (libsndfile's formats; WAV stays with matcad's own reader)."""
MISSING = ("{path}: FLAC/OGG recordings need the optional audio library soundfile: "
           "pip install 'matcad[audio]' (or convert the file to WAV)")


def compressed(path) -> bool:
    """Whether ``path`` names a recording read through soundfile (by its ending, case-insensitive)."""
    return Path(str(path)).suffix.lower() in SUFFIXES


@dataclass(frozen=True)
class AudioInfo:
    """What the loop needs of a compressed recording: rate (Hz), channels and frames."""

    sample_rate_hz: float
    channels: int
    frames: int

    @property
    def duration_s(self) -> float:
        return self.frames / self.sample_rate_hz


def _soundfile(path):
    try:
        import soundfile
    except (ImportError, OSError):  # OSError: the package is there but libsndfile is not
        raise ValueError(MISSING.format(path=path)) from None
    return soundfile


def read_info(path) -> AudioInfo:
    """The header of a FLAC/OGG recording; ValueError (exit 2) naming the file when it is not one."""
    soundfile = _soundfile(path)
    try:
        info = soundfile.info(str(path))
    except (RuntimeError, soundfile.LibsndfileError if hasattr(soundfile, "LibsndfileError") else RuntimeError) as exc:
        raise ValueError(f"{path}: not a readable FLAC/OGG recording ({exc})") from None
    if info.frames <= 0 or info.samplerate <= 0:
        raise ValueError(f"{path}: the recording holds no samples")
    return AudioInfo(float(info.samplerate), int(info.channels), int(info.frames))


def iter_blocks(path, block_frames: int = 1 << 16):
    """Mono float64 blocks of the FLAC/OGG recording ``path`` in order, ``block_frames`` frames each."""
    import numpy as np

    soundfile = _soundfile(path)
    with soundfile.SoundFile(str(path)) as f:
        for block in f.blocks(blocksize=block_frames, dtype="float64", always_2d=True):
            mono = block.mean(axis=1)
            if not np.all(np.isfinite(mono)):
                raise ValueError(f"{path}: the recording holds non-finite samples")
            yield mono
