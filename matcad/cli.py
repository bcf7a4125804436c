"""Command line: parsing, the exit-code table, signals and dispatch. The commands themselves are the modules of
:mod:`matcad.commands`; each returns its exit code, and :func:`main` maps every exception to one row of
:data:`matcad.errors.EXIT_CODES`:

  1   design-rule failure, or no trustworthy result from measured data (LoopError)
  2   bad input or unusable file: SpecError, InputError, OutputError, a ValueError raised by matcad's own code, an
      OSError of the user's file system (unwritable folder, full disk); nothing is written
  70  anything else is a bug: one line "internal error, please report" with the path of a log holding the
      traceback (in the temporary folder, never under $HOME)
  130 interrupted (Ctrl-C, SIGINT), anywhere, including while the CAD kernel loads; no traceback
  143 terminated (SIGTERM), handled exactly like an interrupt
On an interrupt the output folder is left as it was (matcad.output), further interrupts are ignored while
the temporary folder is removed.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
from pathlib import Path

from matcad import __version__
from matcad.errors import EXIT_INPUT, EXIT_INTERNAL, EXIT_INTERRUPT, EXIT_OK, EXIT_RULES, EXIT_TERMINATED


_SIGNALLED: list[int] = []
"""The signal that interrupted this run, if any (set by :func:`_on_signal`)."""
_STDOUT: list = []
"""This run's standard output as the command saw it (:class:`_Stdout`), once dispatched."""


def _on_signal(signum, frame) -> None:
    """SIGINT and SIGTERM: remember which, ignore any further one while cleaning up, unwind as an interrupt."""
    _SIGNALLED.append(signum)
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, signal.SIG_IGN)
    raise KeyboardInterrupt


def _unraisable(unraisable) -> None:
    """``sys.unraisablehook`` during a run: the interrupt :func:`_on_signal` raises inside a callback that cannot
    propagate it (a weakref's, a finaliser's) is not printed as a traceback; anything else is, as Python would."""
    if _SIGNALLED and issubclass(unraisable.exc_type, KeyboardInterrupt):
        return
    sys.__unraisablehook__(unraisable)


def _install_signal_handlers(previous: dict) -> None:
    """Route SIGINT and SIGTERM to :func:`_on_signal`, noting in ``previous`` the handlers they replace. Both
    signals are held back while the handlers change (where the system can), so one that arrives meanwhile is
    delivered after, as an interrupt the caller's ``try`` sees, and every replaced handler is noted."""
    _SIGNALLED.clear()  # a new run in the same interpreter (tests call main() repeatedly)
    both = {signal.SIGINT, signal.SIGTERM}
    hold = getattr(signal, "pthread_sigmask", None)
    mask = hold(signal.SIG_BLOCK, both) if hold else None
    try:
        for sig in (signal.SIGINT, signal.SIGTERM):
            try:
                previous[sig] = signal.signal(sig, _on_signal)
            except ValueError:  # not the main thread: leave Python's default handling
                pass
    finally:
        if hold:
            hold(signal.SIG_SETMASK, mask)


def _private_caches() -> None:
    """Libraries' caches (ezdxf's font cache, matplotlib's config and font list) default to folders under
    $HOME; unless the user chose them, point them at a private folder in the temporary directory."""
    if all(os.environ.get(v) for v in ("XDG_CACHE_HOME", "MPLCONFIGDIR")):
        return
    import tempfile

    folder = Path(tempfile.gettempdir()) / f"matcad-cache-{os.getuid() if hasattr(os, 'getuid') else 0}"
    try:
        folder.mkdir(mode=0o700, exist_ok=True)
        st = folder.lstat()
        if folder.is_symlink() or (hasattr(os, "getuid") and st.st_uid != os.getuid()):
            folder = Path(tempfile.mkdtemp(prefix="matcad-cache-"))
    except OSError:
        folder = Path(tempfile.mkdtemp(prefix="matcad-cache-"))
    os.environ.setdefault("XDG_CACHE_HOME", str(folder))
    os.environ.setdefault("MPLCONFIGDIR", str(folder / "matplotlib"))


def _deliberate(exc: ValueError) -> bool:
    """A ValueError is a refusal of input when matcad's own code raised it (``raise ValueError(...)`` in a
    matcad module, or InputError/SpecError); one raised inside a library or by a math function is a bug."""
    from matcad.errors import InputError

    if isinstance(exc, InputError):
        return True
    if str(exc) in ("math domain error", "math range error"):
        return False
    tb = exc.__traceback__
    while tb is not None and tb.tb_next is not None:
        tb = tb.tb_next
    package = str(Path(__file__).resolve().parent)
    return tb is not None and str(Path(tb.tb_frame.f_code.co_filename).resolve()).startswith(package)


def _internal_error(exc: BaseException, args=None) -> int:
    """Log the traceback to a fresh file in the temporary folder and print one line pointing at it."""
    import tempfile
    import time
    import traceback

    text = "".join(traceback.format_exception(exc))
    try:
        fd, log = tempfile.mkstemp(prefix=f"matcad-internal-error-{time.strftime('%Y%m%dT%H%M%S')}-",
                                   suffix=".log")
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(f"matcad {__version__}\nargv: {sys.argv!r}\n\n{text}")
    except OSError:
        log = "(no log: the temporary folder is not writable)"
    return _fail(args, EXIT_INTERNAL, f"internal error, please report it with the log {log} "
                                      f"({exc.__class__.__name__})")


def _interrupted(args=None) -> int:
    terminated = bool(_SIGNALLED) and _SIGNALLED[0] == signal.SIGTERM
    return _fail(args, EXIT_TERMINATED if terminated else EXIT_INTERRUPT,
                 f"{'terminated' if terminated else 'interrupted'}; no output folder is left half-written")


def _fail(args, code: int, text: str, exc: BaseException | None = None) -> int:
    """Print ``matcad: text`` on stderr and, when the command was asked for ``--json`` and has printed nothing yet,
    the same as a JSON error object on stdout (``{"error": {"exit_code", "meaning", "field", "message",
    "written"}}``): a script reading stdout always gets one JSON document. Returns ``code``."""
    print(f"matcad: {text}", file=sys.stderr)
    if getattr(args, "json", False) and not (_STDOUT and _STDOUT[0].used):
        import json

        from matcad.errors import EXIT_CODES, WRITTEN

        error = {"exit_code": code, "meaning": EXIT_CODES[code], "field": getattr(exc, "field", None),
                 "message": str(exc) if exc is not None else text, "written": [str(p) for p in WRITTEN]}
        try:
            print(json.dumps({"error": error}, indent=2), flush=True)
        except (OSError, ValueError):  # stdout itself is what failed: stderr has said it
            _quiet_stdout()
    return code


def _quiet_stdout() -> None:
    """After a broken pipe: send further output (and the interpreter's final flush) to /dev/null."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError):
        pass


class _Stdout:
    """Standard output as the command sees it, remembering a write that failed (a full disk, /dev/full), so that
    the error is told apart from a failure to write the kit (only then does the CLI say what was written), and
    whether the command printed anything (then a --json error object would break its JSON document)."""

    def __init__(self, inner):
        self.inner = inner
        self.failed: OSError | None = None
        self.used = False

    def write(self, text):
        self.used = self.used or bool(text)
        try:
            return self.inner.write(text)
        except OSError as exc:
            self.failed = exc
            raise

    def flush(self):
        try:
            return self.inner.flush()
        except OSError as exc:
            self.failed = exc
            raise

    def __getattr__(self, name):
        return getattr(self.inner, name)


def main(argv: list[str] | None = None) -> int:
    """Run one command; every outcome maps to one row of :data:`EXIT_CODES`."""
    previous: dict = {}
    args = None
    try:  # from the first line: an interrupt right as the handlers are installed is an interrupt, not a traceback
        _install_signal_handlers(previous)
        sys.unraisablehook = _unraisable
        _STDOUT.clear()
        _private_caches()
        from matcad.commands import parser

        argv = sys.argv[1:] if argv is None else [str(a) for a in argv]
        args = _parse(parser(argv[0] if argv else None), argv)  # the command's own parser; any other: the whole
        return _dispatch(args)
    except KeyboardInterrupt:
        return _interrupted(args)
    except BaseException as exc:  # noqa: BLE001 - the last line of the exit-code table
        if isinstance(exc, SystemExit):  # argparse: usage error (2), --help/--version (0)
            raise
        if _SIGNALLED:  # an interrupt inside a C extension's import surfaces as ImportError/SystemError
            return _interrupted(args)
        return _internal_error(exc, args)
    finally:
        if not _SIGNALLED:  # after a signal both stay ignored: the process is on its way out
            for sig, handler in previous.items():
                signal.signal(sig, handler)


def _parse(top, argv: list[str]):
    """``top.parse_args(argv)``; a usage error (argparse's exit 2: an unknown option, an --out refused by its type)
    of a command asked for ``--json`` also prints the JSON error object on stdout, like every other error exit."""
    told: list[str] = []
    stderr = sys.stderr

    class Tee:
        def write(self, text):
            told.append(text)
            return stderr.write(text)

        def __getattr__(self, name):
            return getattr(stderr, name)

    sys.stderr = Tee()
    try:
        return top.parse_args(argv)
    except SystemExit as exc:
        options = argv[:argv.index("--")] if "--" in argv else argv
        if exc.code == 2 and "--json" in options:
            import json
            import re

            from matcad.errors import EXIT_CODES

            message = ("".join(told).strip().splitlines() or ["usage error"])[-1].partition("error: ")[2]
            field = re.match(r"argument ([^:]+): ", message)
            error = {"exit_code": EXIT_INPUT, "meaning": EXIT_CODES[EXIT_INPUT],
                     "field": field.group(1).split("/")[-1] if field else None, "message": message, "written": []}
            with contextlib.suppress(OSError, ValueError):
                print(json.dumps({"error": error}, indent=2), flush=True)
        raise
    finally:
        sys.stderr = stderr


def _dispatch(args) -> int:
    from matcad.errors import WRITTEN, LoopError, OutputError, SpecError

    WRITTEN.clear()  # a new run in the same interpreter
    stdout = sys.stdout = _Stdout(sys.stdout)
    _STDOUT[:] = [stdout]
    try:
        code = args.func(args)
        stdout.flush()  # a full standard output fails here at the latest, where what was written can be said
        return code
    except SpecError as exc:
        return _fail(args, EXIT_INPUT, f"spec error: {exc}", exc)
    except OutputError as exc:
        return _fail(args, EXIT_INPUT, f"error: {exc}", exc)
    except LoopError as exc:
        return _fail(args, EXIT_RULES, str(exc), exc)
    except BrokenPipeError:  # output piped into e.g. `head`: not an error of ours (before OSError: a subclass)
        _quiet_stdout()
        return EXIT_OK
    except OSError as exc:  # unwritable output folder, full disk, unreadable input: the user's file system
        from matcad.errors import shorten

        if exc is stdout.failed:  # the result could not be printed: say truthfully what was written
            _quiet_stdout()
            done = (f"the output was written and is complete: {', '.join(map(str, WRITTEN))}" if WRITTEN
                    else "nothing was written")
            print(f"matcad: error: standard output: {exc.strerror or exc}: the result could not be printed; {done}",
                  file=sys.stderr)
            return EXIT_INPUT
        where = f"{shorten(str(exc.filename))}: " if exc.filename else ""
        return _fail(args, EXIT_INPUT, f"error: {where}{exc.strerror or exc} (check the path, its permissions and "
                                       "free space)", exc)
    except ValueError as exc:
        if not _deliberate(exc):
            raise
        return _fail(args, EXIT_INPUT, f"error: {exc}", exc)
    finally:
        if sys.stdout is stdout:
            sys.stdout = stdout.inner


def quiet_exit() -> None:
    """Outside :func:`main` (starting up, finishing) there is nothing to clean up: a signal exits at once with
    its code and no traceback."""
    signal.signal(signal.SIGINT, lambda *_: os._exit(EXIT_INTERRUPT))
    signal.signal(signal.SIGTERM, lambda *_: os._exit(EXIT_TERMINATED))


def run() -> None:
    """Console entry point. After a command that loaded OpenCASCADE (or was interrupted, perhaps half-way through
    loading it), every output file is closed and moved into place or cleaned up, yet interpreter teardown would
    spend 0.3-0.7 s destroying kernel objects, and on a half-imported kernel abort ("Fatal Python error ...
    finalizing", exit -6): flush and leave at once."""
    quiet_exit()
    code = main()
    for sig in (signal.SIGINT, signal.SIGTERM):  # the answer is decided: a late signal must not become a traceback
        signal.signal(sig, signal.SIG_IGN)
    kernel = any(name.partition(".")[0] in ("OCP", "build123d") for name in sys.modules)
    if kernel or _SIGNALLED:  # also a kernel import cut short by a signal: its half-made objects abort teardown
        try:
            sys.stdout.flush()
        except BrokenPipeError:
            _quiet_stdout()
        sys.stderr.flush()
        os._exit(code)
    try:
        sys.stdout.flush()
    except BrokenPipeError:
        _quiet_stdout()
    sys.exit(code)
