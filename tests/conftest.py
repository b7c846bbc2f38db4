import pytest

from symlearn.sim.simulator import TabletopSimulator


@pytest.fixture(scope="session")
def sim():
    """One simulator for the session: every scenario rebuilds its own scene."""
    s = TabletopSimulator()
    yield s
    s.close()
