"""WAV input: mono or multichannel, 8/16/24/32-bit integer or 32/64-bit float, any sample rate."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def read_mono(path: str | Path) -> tuple[np.ndarray, float]:
    """Samples as float64 in [-1, 1] (channels averaged) and the sample rate (Hz). Raises ValueError."""
    import warnings

    from scipy.io import wavfile

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", wavfile.WavFileWarning)
            rate, data = wavfile.read(str(path))
    except (OSError, ValueError, EOFError) as exc:
        raise ValueError(f"recording {path}: not a readable WAV file ({exc})") from None
    if data.size == 0 or rate <= 0:
        raise ValueError(f"recording {path}: holds no samples")
    if data.dtype == np.uint8:
        x = (data.astype(np.float64) - 128.0) / 128.0
    elif np.issubdtype(data.dtype, np.integer):
        x = data.astype(np.float64) / float(-np.iinfo(data.dtype).min)  # 24-bit arrives left-justified in int32
    else:
        x = data.astype(np.float64)
    if x.ndim == 2:
        x = x.mean(axis=1)
    if not np.all(np.isfinite(x)):
        raise ValueError(f"recording {path}: contains NaN or infinite samples")
    return x, float(rate)
