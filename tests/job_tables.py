"""The job without its report, for tests that read only the folders each source writes (decks/,
reference_<method>/, ccx/ and their ParaView series): :func:`deckbridge.job.run_job` with
``write_report_with_verdict`` (report.html, its figures, discrepancy.csv, the top-level summary.json) left
out, as tests/scenarios.py's run_case does. The comparison is still made and returned; the report is under
test where a test reads it (tests/test_job.py, tests/test_output_folders.py, ...)."""

from __future__ import annotations

from unittest import mock

from deckbridge.job import run_job


def run_job_tables(model, outdir, **kwargs) -> dict:
    """``run_job(model, outdir, **kwargs)`` without drawing the report (its "paths" are then [])."""
    with mock.patch("deckbridge.job.write_report_with_verdict", return_value=[]):
        return run_job(model, outdir, **kwargs)
