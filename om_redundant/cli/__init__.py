"""The ``om-redundant`` command.

Subcommands, one module each: ``solve`` (one pose, one configuration or all), ``sweep`` (the
arm angle of a 7-DOF arm for a pose or a path; also the run without arguments), ``arms``
(the arms and their models), ``check-model`` (a MuJoCo model against an arm), ``import-arm``
(an arm file from a MuJoCo model) and ``bench paper`` (the OM paper's experiment).

Exit status: 0 on success; 1 when the answer is no (a model that differs, a feature not
built yet); 2 on bad input, with one line ``om-redundant: error: ...`` and no traceback, and
when standard output is closed (``>&-``) and the command has something to print there (with
``-q``, or ``--json FILE``, it runs normally); 130 on Ctrl-C; 141 when the reader of standard
output goes away (``| head``).
"""

from __future__ import annotations

import io
import os
import sys

from .. import __version__
from ..exceptions import OMError
from . import arms, bench, check_model, import_arm, solve, sweep
from .common import Failed, Parser, UsageError

PROG = "om-redundant"
SUBCOMMANDS = (solve, sweep, arms, check_model, import_arm, bench)


def build_parser() -> Parser:
    parser = Parser(
        prog=PROG,
        description="Exact inverse kinematics with configuration control (offset modification method). "
        "Without a command: sweep the Panda's arm angle for its built-in pose, a ball beside its elbow.",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    parser.add_argument("-q", "--quiet", action="store_true", help="print no table, only errors")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for module in SUBCOMMANDS:
        module.add_parser(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the command; returns the exit status (see the module docstring)."""
    if sys.stdout is None:  # started with standard output closed (>&-)
        _hold_stdout()
    parser = build_parser()
    try:
        try:
            args = parser.parse_args(argv)
        except SystemExit as done:  # --help and --version print and stop here
            return done.code if isinstance(done.code, int) else 0
        if args.command is None:
            args = parser.parse_args([*sweep.DEFAULT_RUN, *(["--quiet"] if args.quiet else [])])
        status = args.run(args)
        sys.stdout.flush()  # a closed pipe shows here, not at interpreter exit
        return status
    except BrokenPipeError:
        _discard_stdout()
        return 141
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return 130
    except Failed as exc:
        _error(exc)
        return 1
    except (OMError, ValueError, OSError) as exc:
        _error(exc)
        return 2


def _error(exc: BaseException) -> None:
    print(f"{PROG}: error: {' '.join(str(exc).split())}", file=sys.stderr)


CLOSED_STDOUT = "standard output is closed (>&-); nothing can be printed (use -q or --json FILE)"


class _ClosedOutput(io.TextIOBase):
    """Standard output of a command started with it closed: writing anything is an error."""

    def writable(self) -> bool:
        return True

    def write(self, text: str) -> int:
        if text:
            raise UsageError(
                "standard output is closed (>&-); nothing can be printed (use -q or --json FILE)"
            )
        return 0


def _hold_stdout() -> None:
    """Keep file descriptor 1 taken (by /dev/null, so that no file the command opens lands on it
    and receives what a library prints) and make Python's standard output refuse writes."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        if devnull != 1:
            os.dup2(devnull, 1)
            os.close(devnull)
    except OSError:
        pass
    sys.stdout = _ClosedOutput()


def _discard_stdout() -> None:
    """Point standard output at /dev/null so that Python's final flush does not fail again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):  # no file descriptor (e.g. captured output in tests)
        pass


if __name__ == "__main__":
    sys.exit(main())
