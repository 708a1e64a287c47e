"""Shared pieces of the command line: the group, model options and one-line error handling.

Every failure ends in one line ``deckbridge: error: ...`` on stderr (control characters escaped, at
most a few hundred characters) and an exit code: 2 for usage, model and input-file errors
(:class:`~deckbridge.errors.InputError`), 1 for failures while running on valid input
(:class:`~deckbridge.errors.RunError`: solver diverged, tipped over, ccx failed) and for unexpected
errors. ``--debug`` (or DECKBRIDGE_DEBUG=1) shows the traceback. SIGTERM is handled like Ctrl-C: both end
in one line ``deckbridge: error: interrupted ...`` and exit 1.
Warnings raised during a command (numpy RuntimeWarnings, say) are shown after it succeeds; a failing
command shows its error line alone.
"""

from __future__ import annotations

import functools
import re
import os
import signal
import traceback
import warnings

import click

from .. import limits, outdir as outdir_mod
from ..errors import EXIT_INPUT, EXIT_RUN, DeckbridgeError, ModelError
from ..model import Model, load
from ..readers._checks import compare_up_to
from ..results import ResultsError
from ..textsafe import one_line

EXIT_HELP = """\b
Exit status: 0 success; 2 usage, model or input-file error; 1 the run failed
(solver diverged, the skirt tipped over, ccx failed, cluster unreachable) or an
unexpected error. Errors are one line; --debug shows the traceback."""


class Terminated(KeyboardInterrupt):
    """SIGTERM, handled like Ctrl-C: running children are stopped, staged outputs removed."""


def _on_sigterm(signum, frame):
    raise Terminated()


MESH_META = "deckbridge.mesh"      # click context meta: the mesh the memory guard built (None when it built none)
OPTION_FLAGS = {"k_factor": "--k-factor", "alpha": "--alpha"}   # library argument named in an error -> its flag
# Library messages name a function's parameter in backquotes (`workers`), never a flag; the command line
# shows the flag that sets it. One mapping: parameter -> flag.
PARAMETER_FLAGS = {
    "workers": "--workers", "tol": "--tol", "scheduler": "--scheduler", "executor": "--executor",
    "k_factors": "--k-factors", "open_stiffness": "--open-stiffness", "load_factors": "--load-factor",
    "mesh_variants": "--mesh", "grid": "--grid", "methods": "--method", "allow_large": "--allow-large",
    "force": "--force", "outdir": "-o", "overrides": "--set", "dialects": "--dialect", "solvers": "--with",
}
_PARAMETER = re.compile(r"`([a-z_]+)`")


def as_flags(text: str) -> str:
    """``text`` with each backquoted parameter of :data:`PARAMETER_FLAGS` written as its flag."""
    return _PARAMETER.sub(lambda m: PARAMETER_FLAGS.get(m.group(1), m.group(0)), text)


def _describe(exc: BaseException) -> tuple[str, int]:
    """(one-line message, exit code) of an exception raised by a command."""
    if isinstance(exc, ModelError) and exc.key in OPTION_FLAGS:
        exc = ModelError(OPTION_FLAGS[exc.key], exc.value, exc.reason, exc.source)
    if isinstance(exc, DeckbridgeError):
        return as_flags(one_line(exc)), EXIT_RUN if _solver_failure(exc) else exc.exit_code
    if isinstance(exc, ResultsError):
        return one_line(exc), EXIT_INPUT
    if isinstance(exc, MemoryError):
        return "out of memory (use a coarser mesh or fewer workers)", EXIT_RUN
    if isinstance(exc, RecursionError):
        return "input nested too deeply", EXIT_INPUT
    if isinstance(exc, OSError):
        where = f" {exc.filename!r}" if getattr(exc, "filename", None) else ""
        return one_line(f"{exc.strerror or type(exc).__name__}{where}"), EXIT_RUN
    if isinstance(exc, SystemExit):
        return f"a library ended the command (exit {one_line(exc.code)})", EXIT_RUN
    text = str(exc).splitlines()[0] if str(exc).strip() else ""
    return one_line(f"{type(exc).__name__}: {text}" if text else type(exc).__name__) + \
        " (unexpected; --debug shows the traceback)", EXIT_RUN


def _solver_failure(exc: BaseException) -> bool:
    """A reference-solver error on the load path (tipped over, did not converge) re-raised as one line.

    Errors of the condensation (a mechanism, non-finite stiffness) are the model's: input errors.
    """
    cause = exc.__cause__ or exc.__context__
    if cause is None or type(cause).__module__.split(".")[0] != "reference_solver":
        return False
    tb, module = cause.__traceback__, ""
    while tb is not None:
        module = tb.tb_frame.f_globals.get("__name__", "")
        tb = tb.tb_next
    return module != "reference_solver.condense"


class _Group(click.Group):
    def invoke(self, ctx):
        debug = bool(ctx.params.get("debug")) or os.environ.get("DECKBRIDGE_DEBUG", "") not in ("", "0")
        old = None
        try:
            old = signal.signal(signal.SIGTERM, _on_sigterm)
        except ValueError:           # not the main thread (tests may run commands in threads)
            pass
        try:
            with warnings.catch_warnings(record=True) as caught:   # the filters in force stay as they are
                try:
                    result = super().invoke(ctx)
                except (click.exceptions.Exit, click.exceptions.Abort, click.ClickException):
                    raise
                except KeyboardInterrupt as exc:              # Ctrl-C / SIGTERM: one line, not click's "Aborted!"
                    if debug:
                        traceback.print_exc()
                    what = "terminated (SIGTERM)" if isinstance(exc, Terminated) else "interrupted (SIGINT, Ctrl-C)"
                    click.echo(f"deckbridge: error: {what}; running solvers stopped, unfinished outputs removed",
                               err=True)
                    ctx.exit(EXIT_RUN)
                except (Exception, SystemExit) as exc:  # noqa: BLE001  (every failure ends as one line)
                    if debug:
                        traceback.print_exc()
                    msg, code = _describe(exc)
                    click.echo(f"deckbridge: error: {msg}", err=True)
                    ctx.exit(code)
            for w in caught:                                       # shown after success only
                click.echo(f"deckbridge: warning: {one_line(w.message)} ({w.category.__name__})", err=True)
            return result
        finally:
            if old is not None:
                signal.signal(signal.SIGTERM, old)


@click.group(cls=_Group, context_settings={"help_option_names": ["-h", "--help"]}, epilog=EXIT_HELP)
@click.option("--debug", is_flag=True, help="Show the traceback of an error.")
@click.version_option(package_name="deckbridge")
def main(debug):
    """deckbridge: one contact model, decks for penalty and Lagrange, a reference solver, a comparison."""


def model_options(func):
    """Add ``[MODEL]``, ``--set key.sub=value`` and ``--allow-large``; pass a validated ``model``.

    The memory estimate of the model's mesh is checked here, before any work (see :mod:`deckbridge.limits`);
    when that needs the mesh, the mesh is left in the context's meta under :data:`MESH_META` for the command.
    """

    @click.argument("model_path", metavar="[MODEL]", required=False,
                    type=click.Path(dir_okay=False))
    @click.option("--set", "overrides", multiple=True, metavar="KEY=VALUE",
                  help="Override a model value, e.g. --set mesh.n_theta=48 (repeatable).")
    @click.option("--allow-large", is_flag=True,
                  help="Run a model whose estimated memory exceeds what is available (also DECKBRIDGE_ALLOW_LARGE=1).")
    @functools.wraps(func)
    def wrapper(model_path, overrides, allow_large, **kwargs):
        model: Model = load(model_path, list(overrides))
        built = []

        def mesh_once():                            # built only when the guard's symbolic path needs it
            from ..mesh import build_mesh
            built.append(build_mesh(model))
            return built[0]

        ctx = click.get_current_context()
        limits.check_memory(model, allow_large, mesh=mesh_once,
                            released=ctx.command.name == "solve")   # solve frees its factor before the VTUs
        ctx.meta["deckbridge.allow_large"] = allow_large
        ctx.meta[MESH_META] = built[0] if built else None      # the command reuses it (built once)
        return func(model=model, **kwargs)

    return wrapper


def guard_outputs(command: click.Command) -> None:
    """Give a command with an ``-o`` folder a ``--force`` flag and wrap it: the folder is checked before any
    work (:func:`deckbridge.outdir.check_target`: a folder of another command, or one holding files deckbridge
    did not write, is refused without ``--force``), marked as written by this command before it runs (a killed
    sweep resumes), and when the command fails having written nothing, removed again if it created it, or
    left without the marker and lock it added."""
    names = {p.name for p in command.params}
    if "outdir" not in names or command.callback is None:
        return
    if "force" not in names:
        command.params.append(click.Option(["--force"], is_flag=True,
                                           help="Write into a folder another deckbridge command wrote, or one holding files deckbridge did not write."))
    callback = command.callback

    @functools.wraps(callback)
    def guarded(*args, force=False, **kwargs):
        target = kwargs.get("outdir")
        if target is None:
            return callback(*args, **kwargs)
        sources = tuple(kwargs.get("sources") or ())
        out = outdir_mod.check_target(target, command.name, force=force, sources=sources)
        existed = out.exists()
        before = outdir_mod.entries(out) if existed else set()
        created = [n for n in outdir_mod.CONTROL if not (out / n).exists()]
        lfs = [lf for lf in (kwargs.get("load_factors") or ()) if lf == lf]
        try:
            outdir_mod.mark(outdir_mod.prepare(out), command.name)  # marked first: a killed sweep resumes
            with compare_up_to(max(lfs) if lfs else None):     # results may end at the last one asked for
                result = callback(*args, **kwargs)
        except BaseException:
            if not existed:
                outdir_mod.remove_if_empty(out)
            elif out.is_dir() and outdir_mod.entries(out) == before:
                for name in created:                           # nothing written: the folder as it was
                    (out / name).unlink(missing_ok=True)
            raise
        return result

    command.callback = guarded
