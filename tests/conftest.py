import os

import numpy as np
import pytest

# No optimized model libraries compiled in the background while the tests run (they would
# compete for the cores); tests/codegen/test_optimized_tier.py sets the mode it tests.
os.environ.setdefault("SYMCAT_OPTIMIZE", "off")


@pytest.fixture
def rng():
    return np.random.default_rng(20261121)
