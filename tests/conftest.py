import os

import pytest

os.environ.setdefault("MUJOCO_GL", "egl")


@pytest.fixture(autouse=True)
def _physics_is_marked(request, monkeypatch):
    """A test that steps physics carries the ``sim`` mark, so ``pytest -m "not sim"`` is the fast subset."""
    if request.node.get_closest_marker("sim") is not None:
        yield
        return
    from bt_humanoid.sim.simulation import Simulation

    stepped = []
    original = Simulation.step

    def step(self, n: int = 1) -> None:
        stepped.append(n)
        original(self, n)

    monkeypatch.setattr(Simulation, "step", step)
    yield
    if stepped:
        pytest.fail("this test steps physics: mark it @pytest.mark.sim (the fast subset leaves such tests out)")
