"""Comparator: sources aligned on azimuth at matching load factors, liftoff zones and differences.

``compare_tables(tables, load_factors=None, origins=None) -> ComparisonResult`` is the entry point
(see :mod:`.result`); :mod:`.align` holds the azimuth alignment, :mod:`.metrics` the metrics.
"""

from .result import ComparisonResult, PointResult, compare_series, compare_tables, default_load_factors  # noqa: F401
from .series import LoadFactorError, Profile, Series, split_tables  # noqa: F401


from ..api_callable import make_callable  # noqa: E402  (deckbridge.compare(...) is the API call)
make_callable(__name__)
