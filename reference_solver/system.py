"""The public ``condense``: the condensed system a problem's contact laws run on.

``tangential='springs'`` (frictionless laws): :func:`reference_solver.condense.condense`, the contact
normal dofs retained (springs condensed out). ``tangential='friction'``: the friction laws also need the
tangential dofs, :func:`reference_solver.friction.condense_friction`. Keyword arguments go to
:func:`reference_solver.condense.condense` either way.
"""

from __future__ import annotations

from .condense import condense as condense_normal
from .friction import condense_friction
from .problem import Problem


def condense(problem: Problem, **kw):
    """The condensed system for ``problem`` (a ``CondensedSystem`` or, with friction, a ``FrictionSystem``)."""
    return condense_friction(problem, **kw) if problem.tangential == "friction" else condense_normal(problem, **kw)
