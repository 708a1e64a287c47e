"""Readers of reference-solver folders, Abaqus .dat contact print tables and plain CSV exports.

Each sample is written here in its real layout; the expected rows follow from the sample's numbers
(CPRESS flipped: sigma_N = -CPRESS; units from the header) and from the model's node numbering
(node id = index + 1: base ring, inner face first, theta_j = 360 j / n_theta).
"""

import numpy as np
import pandas as pd
import pytest

from deckbridge import readers
from deckbridge.compare import compare_tables
from deckbridge.errors import DeckbridgeError
from deckbridge.results import COLUMNS, REQUIRED, conform

# Abaqus/Standard .dat layout: increment summaries, a node table (ignored), contact tables per pair.
ABAQUS_DAT = """1

   Abaqus/Standard 2023                                   DATE 12-Mar-2024  TIME 09:41:07
                                                                                  STEP    1  INCREMENT    1

                              S T E P       1     S T A T I C   A N A L Y S I S


     N only

     AUTOMATIC TIME CONTROL WITH -
          A SUGGESTED INITIAL TIME INCREMENT OF                 1.00
          AND A TOTAL TIME PERIOD OF                            1.00


                                   INCREMENT     1 SUMMARY


 TIME INCREMENT COMPLETED   1.00    ,  FRACTION OF STEP COMPLETED   1.00
 STEP TIME COMPLETED        1.00    ,  TOTAL TIME COMPLETED         1.00


                                        N O D E   O U T P U T


  THE FOLLOWING TABLE IS PRINTED FOR NODES BELONGING TO NODE SET ASSEMBLY_REF

       NODE FOOT-  U1           U2           U3
            NOTE

         81       0.000        0.000      -1.2345E-04

 MAXIMUM           0.000        0.000      -1.2345E-04
 AT NODE              81           81           81


                                   C O N T A C T   O U T P U T


  CONTACT OUTPUT FOR SLAVE SURFACE  ASSEMBLY_BASE_NODES              AND MASTER SURFACE  ASSEMBLY_TABLE

       NODE FOOT-  CPRESS       CSHEAR1      CSHEAR2      COPEN        CSLIP1       CSLIP2
            NOTE

          1       1.0743E+07    0.000        0.000      -1.2000E-06    0.000        0.000
          2       1.0743E+07    0.000        0.000      -1.2000E-06    0.000        0.000
         17       1.0700E+07    0.000        0.000      -1.1900E-06    0.000        0.000
         18       1.0700E+07    0.000        0.000      -1.1900E-06    0.000        0.000

 MAXIMUM          1.0743E+07    0.000        0.000      -1.1900E-06    0.000        0.000
 AT NODE               1            1            1           17            1            1

                                                                                  STEP    2  INCREMENT    1

                              S T E P       2     S T A T I C   A N A L Y S I S


     N + lambda (T, M)


                                   INCREMENT     1 SUMMARY


 TIME INCREMENT COMPLETED  0.500    ,  FRACTION OF STEP COMPLETED  0.500
 STEP TIME COMPLETED       0.500    ,  TOTAL TIME COMPLETED         1.50


                                   C O N T A C T   O U T P U T


  CONTACT OUTPUT FOR SLAVE SURFACE  ASSEMBLY_BASE_NODES              AND MASTER SURFACE  ASSEMBLY_TABLE

       NODE FOOT-  CPRESS       CSHEAR1      CSHEAR2      COPEN        CSLIP1       CSLIP2
            NOTE

          1       2.5000E+06    0.000        0.000      -2.8000E-07    0.000        0.000
          2       4.0000E+06    0.000        0.000      -4.5000E-07    0.000        0.000
         17       2.4000E+06    0.000        0.000      -2.7000E-07    0.000        0.000
         18       3.9000E+06    0.000        0.000      -4.4000E-07    0.000        0.000

  CONTACT OUTPUT FOR SLAVE SURFACE  ASSEMBLY_BASE_INNER              AND MASTER SURFACE  ASSEMBLY_STOP

       NODE FOOT-  CPRESS       CSHEAR1      CSHEAR2      COPEN        CSLIP1       CSLIP2
            NOTE

          1       1.0000E+05    0.000        0.000      -1.0000E-08    0.000        0.000

                                   INCREMENT     2 SUMMARY


 TIME INCREMENT COMPLETED  0.500    ,  FRACTION OF STEP COMPLETED   1.00
 STEP TIME COMPLETED        1.00    ,  TOTAL TIME COMPLETED         2.00


                                   C O N T A C T   O U T P U T


  CONTACT OUTPUT FOR SLAVE SURFACE  ASSEMBLY_BASE_NODES              AND MASTER SURFACE  ASSEMBLY_TABLE

       NODE FOOT-  CPRESS       CSHEAR1      CSHEAR2      COPEN        CSLIP1       CSLIP2
            NOTE

          1        0.000        0.000        0.000       2.5000E-05    0.000        0.000
          2       1.5000E+06    0.000        0.000      -1.7000E-07    0.000        0.000
         17        0.000        0.000        0.000       2.4000E-05    0.000        0.000
         18       1.4000E+06    0.000        0.000      -1.6000E-07    0.000        0.000


          THE ANALYSIS HAS BEEN COMPLETED
"""


def test_abaqus_dat_contact_tables(tmp_path, small_model):
    p = tmp_path / "jar_abaqus.dat"
    p.write_text(ABAQUS_DAT)
    assert readers.detect(p) == "abaqus_dat"
    df = readers.read(p, model=small_model)
    assert list(df.columns) == COLUMNS and len(df) == 4 + 5 + 4
    assert set(df["source"]) == {"abaqus"} and set(df["method"]) == {"lagrange"}
    # step 1 -> lambda 0; step 2 -> lambda_max * fraction of step completed
    states = df.groupby(["step", "increment"])["load_factor"].first().to_dict()
    assert states == {(1, 1): 0.0, (2, 1): 0.5, (2, 2): 1.0}
    row = df[(df["step"] == 1) & (df["node"] == 1)].iloc[0]
    assert row["sigma_n_pa"] == -1.0743e7 and row["gap_m"] == -1.2e-6 and row["status"] == "closed"
    last = df[(df["step"] == 2) & (df["increment"] == 2)].set_index("node")
    assert last.loc[1, "sigma_n_pa"] == 0.0 and last.loc[1, "gap_m"] == 2.5e-5 and last.loc[1, "status"] == "open"
    assert last.loc[18, "sigma_n_pa"] == -1.4e6 and last.loc[18, "status"] == "closed"
    # node ids through the 16-azimuth model: 1, 17 at 0 deg (inner, outer face), 2, 18 at 22.5 deg
    assert last["theta_deg"].to_dict() == pytest.approx({1: 0.0, 2: 22.5, 17: 0.0, 18: 22.5})
    t, g = small_model.geometry.thickness, small_model.geometry.radius
    assert last.loc[1, "r"] == pytest.approx(g - t / 2) and last.loc[17, "r"] == pytest.approx(g + t / 2)
    stop = df[df["surface"] == "stop"]
    assert len(stop) == 1 and stop.iloc[0]["node"] == 1 and stop.iloc[0]["sigma_n_pa"] == -1.0e5


def test_abaqus_dat_of_a_mm_deck_reads_back_in_si(tmp_path, small_model):
    """A job whose deck says ``** deckbridge-units: mm``: CPRESS [MPa] and COPEN [mm] come back in Pa and m."""
    (tmp_path / "jar_abaqus.dat").write_text(ABAQUS_DAT)
    (tmp_path / "jar_abaqus.inp").write_text("*HEADING\nJAR\n** deckbridge-units: mm\n")
    df = readers.read(tmp_path / "jar_abaqus.dat", model=small_model)
    row = df[(df["step"] == 1) & (df["node"] == 1) & (df["surface"] == "table")].iloc[0]
    assert row["sigma_n_pa"] == pytest.approx(-1.0743e13) and row["gap_m"] == pytest.approx(-1.2e-9)


def test_abaqus_dat_without_contact_tables_or_of_another_model(tmp_path, small_model):
    p = tmp_path / "nocontact.dat"
    p.write_text(ABAQUS_DAT.split("                                   C O N T A C T")[0])
    with pytest.raises(DeckbridgeError, match=r"nocontact\.dat.*no contact data"):
        readers.read(p, model=small_model)
    q = tmp_path / "other.dat"
    q.write_text(ABAQUS_DAT.replace("         18       1.4000E+06", "        999       1.4000E+06"))
    with pytest.raises(DeckbridgeError, match=r"other\.dat.*node 999 is not a contact slave node"):
        readers.read(q, model=small_model)
    r = tmp_path / "cut.dat"
    r.write_text(ABAQUS_DAT.replace("          2       1.5000E+06    0.000        0.000      -1.7000E-07",
                                    "          2       1.5000E+06    0.000        0.000"))
    with pytest.raises(DeckbridgeError, match=r"cut\.dat.*line \d+: 5 values under 6 columns"):
        readers.read(r, model=small_model)


def _reference_table(n_theta=16):
    th = 360.0 * np.arange(n_theta) / n_theta
    s = -5e6 + 8e6 * np.cos(np.radians(th))
    rows = [("reference", "penalty", 2, 1, 1.0, j + 1, "table", th[j], 0.0, 1.49, s[j], 0.0,
             "open" if s[j] > 0 else "closed") for j in range(n_theta)]
    return conform(pd.DataFrame(rows, columns=REQUIRED))


def test_reference_folder_and_csv_are_detected_and_read(tmp_path, small_model):
    folder = tmp_path / "ref"
    folder.mkdir()
    _reference_table().to_csv(folder / "contact.csv", index=False)
    (folder / "summary.json").write_text("{}")
    assert readers.detect(folder) == "reference"
    assert readers.detect(folder / "contact.csv") == "reference"       # not the plain CSV reader
    df = readers.read(folder, model=small_model)
    pd.testing.assert_frame_equal(df, _reference_table())
    (tmp_path / "lonely").mkdir()
    (tmp_path / "lonely" / "contact.csv").write_text("x\n")
    with pytest.raises(DeckbridgeError, match="format not recognised"):
        readers.detect(tmp_path / "lonely")


def test_plain_csv_node_and_cpress_in_mpa_with_copen_in_mm(tmp_path, small_model):
    """Semicolon export: node, CPRESS [MPa] (compression positive), COPEN [mm]; no load-factor column:
    the end of step 2 of the model. It lands on the reference curve it was exported from."""
    ref = _reference_table()
    lines = ["Node Label;CPRESS [MPa];COPEN [mm]"]
    for _, r in ref.iterrows():
        lines.append(f"{r['node']};{-r['sigma_n_pa'] / 1e6:.9g};{0.02 if r['sigma_n_pa'] > 0 else -0.001}")
    p = tmp_path / "abaqus_export.csv"
    p.write_text("\n".join(lines) + "\n")
    assert readers.detect(p) == "plain_csv"
    df = readers.read(p, model=small_model)
    assert np.allclose(df["sigma_n_pa"], ref["sigma_n_pa"], rtol=1e-8, atol=1e-3)
    assert df["theta_deg"].tolist() == pytest.approx(ref["theta_deg"].tolist())
    assert set(df["gap_m"].round(9)) == {2e-5, -1e-6}
    assert (df["status"] == ref["status"]).all()
    assert set(df["step"]) == {2} and set(df["load_factor"]) == {small_model.steps.lambda_max}
    assert df["method"].iloc[0] == "abaqus_export"
    pair = compare_tables([ref, df], load_factors=[1.0]).primary.pairs[0]
    assert pair["max_abs_diff_pa"] < 1.0 and pair["liftoff_zone_overlap"] == pytest.approx(1.0)


def test_plain_csv_azimuth_in_radians_and_sigma_n_in_kpa(tmp_path):
    p = tmp_path / "post.csv"
    p.write_text("# exported by a post-processor\ntheta (rad),sigma_n_kpa,load_factor\n"
                 "0.0,-100,0\n3.14159265358979,-300,0\n0.0,250,0.5\n3.14159265358979,-700,0.5\n")
    df = readers.read(p)
    assert df["theta_deg"].tolist() == pytest.approx([0.0, 180.0, 0.0, 180.0])
    assert df["sigma_n_pa"].tolist() == pytest.approx([-1e5, -3e5, 2.5e5, -7e5])
    assert df["step"].tolist() == [1, 1, 2, 2] and df["status"].tolist() == ["closed", "closed", "open", "closed"]


def test_plain_csv_bad_units_values_and_nodes(tmp_path, small_model):
    bad_unit = tmp_path / "u.csv"
    bad_unit.write_text("node,CPRESS [ksi]\n1,2\n")
    with pytest.raises(DeckbridgeError, match=r"u\.csv.*'CPRESS \[ksi\]'.*unit 'ksi' not understood"):
        readers.read(bad_unit, model=small_model)
    bad_value = tmp_path / "v.csv"
    bad_value.write_text("node,CPRESS\n1,2\n2,n/a\n")
    with pytest.raises(DeckbridgeError, match=r"v\.csv': line 3, column 'CPRESS': 'n/a' is not a number"):
        readers.read(bad_value, model=small_model)
    bad_node = tmp_path / "w.csv"
    bad_node.write_text("node,CPRESS\n1,2\n4000,2\n")
    with pytest.raises(DeckbridgeError, match=r"w\.csv.*node 4000 is not a contact slave node"):
        readers.read(bad_node, model=small_model)
