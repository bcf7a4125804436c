"""The exit-code table, the exceptions the CLI maps to it and the record of folders written that its messages
quote (kept import-light: the CLI loads this on every command).

  0   ok
  1   design-rule failure, or for analyze/calibrate/sense no trustworthy result (no tone, a tone at the band
      edge, degenerate or flat data, a force outside the calibrated range): :class:`LoopError`
  2   bad input or unusable file (spec, data, recording, output folder, the file system refusing a write):
      ``SpecError``, :class:`InputError`, :class:`OutputError`, a ValueError raised by matcad's own code
  70  internal error (a bug): one line "internal error, please report" with the path of a log holding the
      traceback (in the temporary folder, never under $HOME) — never 1, which is reserved for the rules
  130 interrupted (Ctrl-C, SIGINT), anywhere, including while the CAD kernel loads; no traceback
  143 terminated (SIGTERM), handled exactly like an interrupt
"""

EXIT_OK, EXIT_RULES, EXIT_INPUT, EXIT_INTERNAL, EXIT_INTERRUPT, EXIT_TERMINATED = 0, 1, 2, 70, 130, 143
EXIT_CODES = {EXIT_OK: "ok", EXIT_RULES: "design-rule failure or no trustworthy result",
              EXIT_INPUT: "bad input or unusable file", EXIT_INTERNAL: "internal error (please report)",
              EXIT_INTERRUPT: "interrupted (SIGINT)", EXIT_TERMINATED: "terminated (SIGTERM)"}
"""One row per exit code, enforced by :func:`matcad.cli.main`."""

WRITTEN: list = []
"""Folders (paths) this process has put in place, in order (:func:`matcad.output.staged_output`): a later failure (a
full standard output after the kit was written) can then say truthfully what was written. The CLI clears it at
the start of each run; it lives here, not in :mod:`matcad.output`, so that a command writing no folder does not
load the output machinery (hashlib, shutil) to report an error."""

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


class _Missing:
    """The ``value`` of a SpecError about a table or field that is not there at all (no ``= None`` in messages)."""

    def __repr__(self) -> str:
        return "(missing)"


MISSING = _Missing()


class SpecError(ValueError):
    """Bad spec input. ``field`` is the dotted spec key, ``value`` what was given (:data:`MISSING` when nothing
    was), ``allowed`` the rule."""

    def __init__(self, field_name: str, value, allowed: str):
        self.field = field_name
        self.value = value
        self.allowed = allowed
        given = "" if value is MISSING else f" = {shorten(value)}"
        super().__init__(f"{field_name}{given}: {allowed}")
