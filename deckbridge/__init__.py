"""deckbridge: one neutral model of a structure in contact, decks for two contact methods,
an open reference solver and a comparator of local contact stresses.

Data flow: model -> mesh -> (render decks | reference solver | external solver) -> results table
-> comparison -> report.

The public Python API (documented, stable; see :mod:`deckbridge.api`)::

    import deckbridge
    model = deckbridge.default_model().with_overrides({"mesh.n_theta": 48})
    lag = deckbridge.solve(model, method="lagrange")
    lag.sigma_n_wall(1.0)        # sigma_N(theta) through the wall at lambda = 1 [Pa], < 0 compression

``default_model``, ``load``, ``Model.with_overrides``, ``solve``, ``run``, ``compare``, ``sweep``, ``liftoff``,
``read_contact`` (a Nastran surface-contact OP2 into the tidy table);
results in :mod:`deckbridge.api_results` and :mod:`deckbridge.api_studies`; summary keys in
:mod:`deckbridge.summary_keys`. The solver and pandas are imported on first use of the API, not here.
"""

import importlib

from .errors import DeckbridgeError  # noqa: F401
from .model import Model, ModelError, load  # noqa: F401

__version__ = "0.1.0"

_API = ("default_model", "solve", "run", "compare", "sweep", "liftoff")
from .contact_results import read_contact  # noqa: F401,E402  (a light module: the reader loads on first call)

__all__ = ["DeckbridgeError", "Model", "ModelError", "load", "read_contact", *_API]


def __getattr__(name: str):
    """The API functions, imported on first use (``import deckbridge`` stays light for the CLI).
    ``solve`` and ``compare`` are also modules: the module itself is returned, calling it calls the API
    function (:mod:`deckbridge.api_callable`)."""
    if name in ("solve", "compare"):
        return importlib.import_module(f".{name}", __name__)
    if name in _API:
        return getattr(importlib.import_module(".api", __name__), name)
    raise AttributeError(f"module 'deckbridge' has no attribute {name!r}")
