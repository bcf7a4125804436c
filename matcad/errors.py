"""Exceptions the CLI maps to exit codes (kept import-light: the CLI loads this on every command)."""


class OutputError(Exception):
    """The output folder cannot be (re)placed: bad input, exit code 2."""
