"""The one error the reference solver raises: a one-line message, never a traceback for bad input."""


class ReferenceSolverError(RuntimeError):
    """A problem the solver cannot solve (mechanism, no contact, tipping, non-finite numbers).

    ``str(err)`` is one line saying what is wrong and, where it helps, at which step and load factor.
    """
