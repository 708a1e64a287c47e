"""Plain CSV results that were read wrongly without a word (issue 26): duplicate rows (averaged downstream),
node ``12.5`` (read as 12), azimuths of 1e6 and 1e300 deg (wrapped). Each is refused with one line naming the
file, the line in the file (comments and blank lines counted), the column and the value."""

import re

import numpy as np
import pytest

from deckbridge import readers
from deckbridge.errors import DeckbridgeError
from deckbridge.readers._nodemap import slave_nodes

HEAD = "# exported by hand\nnode,CPRESS [MPa],COPEN [mm]\n\n"     # data rows start on line 4


def _nodes_csv(tmp_path, model, rows=None, name="r.csv"):
    """A CSV of every table slave node of ``model``: 10 MPa, closed; ``rows`` replaces data rows by index."""
    nodes = slave_nodes(model).index.to_numpy()[:6]
    body = [f"{n},10.0,-0.001" for n in nodes]
    for i, text in (rows or {}).items():
        body[i] = text
    p = tmp_path / name
    p.write_text(HEAD + "\n".join(body) + "\n")
    return p, nodes


def test_clean_file_reads(tmp_path, small_model):
    p, nodes = _nodes_csv(tmp_path, small_model)
    df = readers.read(p, model=small_model)
    assert sorted(df["node"]) == sorted(nodes)
    assert np.allclose(df["sigma_n_pa"], -10e6)


def test_duplicate_row_is_refused_naming_both_lines(tmp_path, small_model):
    p, nodes = _nodes_csv(tmp_path, small_model)
    dup = nodes[1]
    p.write_text(p.read_text() + f"{dup},30.0,-0.003\n")          # line 10 repeats line 5
    with pytest.raises(DeckbridgeError) as err:
        readers.read(p, model=small_model)
    msg = str(err.value)
    assert msg == (f"{str(p)!r}: line 10, column 'node': '{dup}' repeats line 5 (same source, method, step, "
                   "increment and surface): duplicate rows are refused, not averaged")


def test_fractional_node_is_refused(tmp_path, small_model):
    nodes = slave_nodes(small_model).index.to_numpy()
    p, _ = _nodes_csv(tmp_path, small_model, {2: f"{nodes[2]}.5,10.0,-0.001"})
    with pytest.raises(DeckbridgeError, match=re.escape(f"{str(p)!r}: line 6, column 'node': '{nodes[2]}.5' is not "
                                                        "a whole number")):
        readers.read(p, model=small_model)
    q, _ = _nodes_csv(tmp_path, small_model, {2: f"{nodes[2]}.0,10.0,-0.001"}, name="whole.csv")
    assert nodes[2] in set(readers.read(q, model=small_model)["node"])       # 12.0 is node 12


@pytest.mark.parametrize("value", ["1e6", "1e300", "-361", "400"])
def test_far_azimuth_is_refused(tmp_path, value):
    p = tmp_path / "theta.csv"
    p.write_text(f"theta [deg],sigma_n_pa\n0,-1e6\n90,-2e6\n{value},-3e6\n")
    with pytest.raises(DeckbridgeError, match=re.escape(f"{str(p)!r}: line 4, column 'theta [deg]': '{value}' is "
                                                        "outside [-360, 360] deg")):
        readers.read(p)


def test_azimuths_within_a_turn_wrap(tmp_path):
    p = tmp_path / "theta.csv"
    p.write_text("theta [deg],sigma_n_pa\n-90,-1e6\n360,-2e6\n359.5,-3e6\n")
    assert readers.read(p)["theta_deg"].tolist() == [270.0, 0.0, 359.5]
    q = tmp_path / "rad.csv"
    q.write_text("theta [rad],sigma_n_pa\n6.3,-1e6\n")
    with pytest.raises(DeckbridgeError, match="line 2, column 'theta \\[rad\\]': '6.3' is outside"):
        readers.read(q)


def test_compression_at_an_open_gap_names_its_line(tmp_path, small_model):
    """COPEN 2 mm (open) with 10 MPa CPRESS: the contact law is broken at that line (contact-law check)."""
    nodes = slave_nodes(small_model).index.to_numpy()
    p, _ = _nodes_csv(tmp_path, small_model, {3: f"{nodes[3]},10.0,2.0"})
    with pytest.raises(DeckbridgeError, match=re.escape(f"{str(p)!r}: line 7: sigma_n = -1e+07 Pa with gap 0.002 m")
                       + ".*compression in an open contact"):
        readers.read(p, model=small_model)
