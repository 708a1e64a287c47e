"""``deckbridge.solve`` and ``deckbridge.compare`` are both a module (``deckbridge/solve.py``,
``deckbridge/compare/``) and an API function: calling the module calls the function of :mod:`deckbridge.api`
(``deckbridge.solve(model, method="lagrange")``), while ``deckbridge.solve.solve_path`` stays the module's.

Python allows a module's ``__class__`` to be set to a :class:`types.ModuleType` subclass (the data model's
"Customizing module attribute access"); each of the two modules does it on itself, at its import.
"""

from __future__ import annotations

import importlib
import sys
import types


class _CallableModule(types.ModuleType):
    """A module whose call is ``deckbridge.api.<name>`` (its docstring: see that function)."""

    def __call__(self, *args, **kwargs):
        api = importlib.import_module("deckbridge.api")     # by name: the API imports these modules
        return getattr(api, self.__name__.rsplit(".", 1)[-1])(*args, **kwargs)


def make_callable(module_name: str) -> None:
    """Make ``sys.modules[module_name]`` callable as the API function of its last name."""
    sys.modules[module_name].__class__ = _CallableModule
