import os

import numpy as np
import pytest

os.environ.setdefault("MPLBACKEND", "Agg")


@pytest.fixture
def paper_phi():
    """The paper's stroke, -30...+30 deg, on a dense grid (rad)."""
    return np.radians(np.linspace(-30.0, 30.0, 6001))
