"""Shared test fixtures: small models and the path of ../shared beside the checkout."""

from pathlib import Path

import pytest

from deckbridge.model import load

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared"


@pytest.fixture
def small_model():
    """A light JAR variant for fast tests (16 x 4 x 1 hexahedra)."""
    return load(None, ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1"])
