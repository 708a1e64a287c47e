"""The one error the reference solver raises: a one-line message, never a traceback for bad input."""


class ReferenceSolverError(RuntimeError):
    """A problem the solver cannot solve (mechanism, no contact, tipping, non-finite numbers).

    ``str(err)`` is one line saying what is wrong and, where it helps, at which step and load factor.
    """


def no_equilibrium(step: int, load_factor: float) -> ReferenceSolverError:
    """The error for an unbounded contact problem: nothing presses the body on (step 1) or the load
    tips it over (step 2, at ``load_factor``)."""
    if step == 1:
        return ReferenceSolverError("no contact possible: the step-1 load does not press the body onto its supports")
    return ReferenceSolverError(f"step 2, load factor {load_factor:.6g}: the load tips the body over "
                                "(no equilibrium on its supports)")

