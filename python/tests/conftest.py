import pytest

import verti


@pytest.fixture(scope="session")
def world():
    """World 1 of the built-in set (generated once, about 0.1 s)."""
    return verti.World.generate(seed=0, index=1)


@pytest.fixture(scope="session")
def worlds():
    """Worlds 1..4 of the built-in set."""
    return [verti.World.generate(seed=0, index=i) for i in range(1, 5)]
