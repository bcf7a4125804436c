"""Exceptions the CLI maps to exit codes (kept import-light: the CLI loads this on every command)."""

ECHO_MAX_CHARS = 80
"""Longest echo of a user's value in a message: a 100 MB field must not come back as a 100 MB error."""


def shorten(value, limit: int = ECHO_MAX_CHARS) -> str:
    """``repr(value)`` cut to ``limit`` characters, saying how long it was when cut."""
    text = repr(value)
    if len(text) <= limit:
        return text
    return f"{text[:limit - 1]}… ({len(text)} characters)"


class OutputError(Exception):
    """The output folder cannot be (re)placed: bad input, exit code 2."""


class InputError(ValueError):
    """An input file is unusable before it is parsed (not a regular file, larger than its limit): exit code 2."""


class LoopError(Exception):
    """Measured data cannot give a trustworthy answer (no tone, a tone at a band edge, degenerate calibration data,
    a force outside the calibrated range): exit code 1 with the reason."""
