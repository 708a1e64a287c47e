"""check_contact_law judges a row on the solver's own gap (``law_gap_m``) where the reader gives one (issue 26:
ccx's CDIS gap of a node-to-surface row, against its faceted master from the deck's rounded coordinates),
else on gap_m; no ccx needed. Numbers of the imported .bdf skirt's stop node 119 at step 2, increment 7."""

import numpy as np
import pandas as pd
import pytest

from deckbridge.errors import InputError
from deckbridge.readers._contact_law import check_contact_law


def _state(sigma_119, law_gap_119):
    # a pressed table node, a lifted stop node (sigma_inf tension), and node 119 of the stop
    return pd.DataFrame({"source": "ccx", "method": "penalty", "step": 2, "increment": 7,
                         "node": [9, 69, 119], "surface": ["table", "stop", "stop"], "r": 1.4925,
                         "sigma_n_pa": [-1.78e6, 0.0176, sigma_119], "gap_m": [-7.95e-4, 1.02e-4, 3.21e-6],
                         "law_gap_m": [-7.95e-4, 1.02e-4, law_gap_119]})


def test_compression_closed_by_the_solvers_own_gap_is_read():
    out = check_contact_law(_state(-4.8e4, -4.1e-8), "x.dat")
    assert "law_gap_m" not in out.columns and len(out) == 3


def test_without_the_solvers_gap_the_same_row_is_refused():
    with pytest.raises(InputError, match="compression in an open contact"):
        check_contact_law(_state(-4.8e4, np.nan), "x.dat")       # judged on gap_m = +3.21e-6 m


def test_a_flipped_sign_is_still_refused_on_the_solvers_gap():
    df = _state(-4.8e4, -4.1e-8)
    df.loc[0, "sigma_n_pa"] *= -1                                # the pressed table node pulls
    with pytest.raises(InputError, match="tension in a closed contact"):
        check_contact_law(df, "x.dat")
    with pytest.raises(InputError, match="compression in an open contact"):
        check_contact_law(_state(-4.8e4, 1e-5), "x.dat")         # ccx's own gap open: compression refused
