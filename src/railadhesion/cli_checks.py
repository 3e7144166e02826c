"""Exit codes of the command line and how it reports results that cannot be trusted.

The policy (``docs/CONVENTIONS.md``, "Careless inputs"; ``docs/checks.md``): a command whose
result is not trustworthy (a fit the quality gate flags, a train that did not stop, NaN
results, failed sweep points or stops) says why, with the first reason, and exits with
:data:`EXIT_UNTRUSTED` unless ``--allow-untrusted`` accepts such results knowingly.

=====  ======================================================================================
code   meaning
=====  ======================================================================================
0      done; every result can be trusted (warnings about inputs may have been printed)
1      an unexpected failure (a bug: please report it)
2      an error: a bad option, file or input (the message names it); nothing was computed
3      done, but a result is not trustworthy (the message gives the first reason); outputs
       are written, so that they can be inspected
4      a test bench (``wsp-test``, ``odometry-test``): a case or fit failed its checks
141    the reader of standard output went away (``| head``): the command stopped quietly, as
       a program ended by SIGPIPE (128 + 13)
=====  ======================================================================================

Messages (``warning:``, ``note:``, ``error:``, the ``not trusted`` verdict, progress bars) go
to standard error through :data:`err_console`: standard output holds only what the command
was asked for (a table, CSV, JSON), so ``--format csv > file`` and pipes read clean output.
"""

from __future__ import annotations

import math
import os
import sys

import typer
from rich.console import Console
from rich.markup import escape


def stop_on_broken_pipe() -> None:
    """Stop the command quietly with :data:`EXIT_BROKEN_PIPE`: the reader of standard output
    went away (``| head``). Standard output is pointed at devnull first (Python docs, "Note
    on SIGPIPE"), so that the flush at exit does not fail again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):  # no file descriptor (a test's captured output)
        pass
    raise typer.Exit(code=EXIT_BROKEN_PIPE)


class OutputConsole(Console):
    """The commands' Rich console: a closed pipe stops the command with
    :data:`EXIT_BROKEN_PIPE` (Rich itself would exit with code 1, which means a bug)."""

    def on_broken_pipe(self) -> None:
        self.quiet = True
        stop_on_broken_pipe()


#: Where messages go (standard error); ``console.print`` of the commands is their output.
err_console = OutputConsole(stderr=True)

# The messages printed in this run of a command: each distinct one is printed once.
_printed: set[str] = set()


def start_messages() -> None:
    """Forget the messages printed so far (called when a command starts: one run of the
    CLI, or one ``CliRunner.invoke`` of the tests, prints each distinct message once)."""
    _printed.clear()


def message(kind: str, text: str, style: str = "yellow") -> None:
    """Print ``<kind>: <text>`` on standard error, once per command run, as one line.

    Parameters
    ----------
    kind : str
        The label: ``warning``, ``note`` or ``error``.
    text : str
        The message, plain text (brackets such as ``[0, 100]`` are printed as written).
    style : str
        Rich style of the label.
    """
    line = f"{kind}: {text}"
    if line in _printed:
        return
    _printed.add(line)
    err_console.print(f"[{style}]{kind}:[/{style}] {escape(text)}", highlight=False,
                      soft_wrap=True)


def warn(text: str) -> None:
    """Print ``warning: <text>`` on standard error, once per command run."""
    message("warning", text)


def note(text: str) -> None:
    """Print ``note: <text>`` on standard error, once per command run."""
    message("note", text, style="cyan")


def fail(exc) -> None:
    """Print ``error: <exc>`` on standard error and exit with :data:`EXIT_ERROR`."""
    message("error", str(exc), style="red")
    raise typer.Exit(code=EXIT_ERROR)


def progress_disabled() -> bool:
    """True when progress bars would not be live (standard error is not a terminal): a
    finished bar would leave a blank or stale line among the messages."""
    return not err_console.is_terminal


#: Exit code of an error (bad option, file or input).
EXIT_ERROR = 2
#: Exit code when a result is not trustworthy (and ``--allow-untrusted`` was not given).
EXIT_UNTRUSTED = 3
#: Exit code when the reader of standard output closed the pipe (``railadhesion ... | head``):
#: 128 + SIGPIPE, what a shell reports for a program that SIGPIPE ended.
EXIT_BROKEN_PIPE = 141
#: Exit code of a test bench (``wsp-test``, ``odometry-test``) when a case or fit failed its
#: checks or could not run: the unit under test failed, not the program (code 1 stays "a bug").
EXIT_CHECKS_FAILED = 4

ALLOW_HELP = ("Exit with code 0 even if a result is not trustworthy (an untrusted fit, a train "
              "that did not stop, NaN results, failed points); without it such results exit "
              "with code 3.")  # fmt: skip


def allow_untrusted_option():
    """The ``--allow-untrusted`` option of the commands that produce results."""
    return typer.Option(False, "--allow-untrusted", help=ALLOW_HELP)


def braking_findings(result, label: str = "") -> list[str]:
    """Why a braking result is not trustworthy: its ``warnings`` when it is flagged (the
    ``trusted`` attribute), else a stop that did not end or a non-finite distance."""
    where = f"{label}: " if label else ""
    if hasattr(result, "trusted"):
        if result.trusted:
            return []
        found = [where + str(w) for w in getattr(result, "warnings", ())]
        return found or [where + (getattr(result, "message", "") or "not trusted")]
    found = []
    if not getattr(result, "success", True):
        found.append(where + (getattr(result, "message", "") or "the train did not stop"))
    distance = getattr(result, "stopping_distance", 0.0)
    if distance is None or not math.isfinite(float(distance)):
        found.append(where + f"the stopping distance is {distance} (NaN results)")
    return found


def finish(findings, *, allow: bool, what: str = "result") -> None:
    """Report findings (reasons a result is not trustworthy) and exit accordingly.

    Prints ``<what> not trusted: <first reason>`` (and how many more) on standard error
    (:data:`err_console`) and exits with :data:`EXIT_UNTRUSTED`, or only the message when
    ``allow`` (``--allow-untrusted``).
    """
    console = err_console
    findings = [str(f) for f in findings if f]
    if not findings:
        return
    more = f" (and {len(findings) - 1} more finding(s))" if len(findings) > 1 else ""
    console.print(f"[bold red]{escape(what)} not trusted[/bold red]: {escape(findings[0])}"
                  f"{escape(more)}", highlight=False, soft_wrap=True)  # fmt: skip
    if allow:
        console.print("accepted with --allow-untrusted", highlight=False)
        return
    console.print(f"exit code {EXIT_UNTRUSTED} (--allow-untrusted accepts such results)",
                  highlight=False)  # fmt: skip
    raise typer.Exit(code=EXIT_UNTRUSTED)
