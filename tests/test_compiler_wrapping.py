"""Every node the compiler emits sits under a Safety guard, with only its recovery steps between the two."""

import pytest
from py_trees.behaviour import Behaviour

from bt_humanoid.cli import _default_args
from bt_humanoid.engine.decorators import RECOVERY_STEPS, FaultWatch, OrElse, SafetyGuard
from bt_humanoid.mission.behaviors import BehaviorLibrary
from bt_humanoid.paths import project_root
from bt_humanoid.skills.base import Skill
from bt_humanoid.testing.scenario import build_run

MISSIONS = sorted((project_root() / "missions").glob("*.yaml"))
BEHAVIORS = sorted(BehaviorLibrary().behaviors)
# a valid value for every required behaviour parameter used in this repo
SAMPLE_ARGS = {"place": "table", "object": "red cube", "surface": "counter", "to": "counter", "x": 8.4, "y": 2.8}
# behaviours that need a world other than the apartment (its bins): the world and the arguments they take there
IN_OTHER_WORLDS = {"throw_away": ("kitchen", {"object": "coke", "into": "trash_can"})}


def assert_fully_wrapped(root: Behaviour) -> int:
    """Walk the tree; return how many mission nodes were checked."""
    assert isinstance(root, SafetyGuard), "the root must be a Safety guard"
    checked = 0
    for node in root.iterate():
        if isinstance(node, SafetyGuard):
            alternative = isinstance(node.parent, OrElse) and node.parent.children[1] is node
            assert node.parent is None or alternative or not isinstance(node.parent, RECOVERY_STEPS), (
                f"{node.decorated.name}: a recovery step above a Safety guard"
            )
            continue
        if isinstance(node, RECOVERY_STEPS):
            continue
        if isinstance(node, Skill):
            assert isinstance(node.parent, FaultWatch), f"{node.name}: a skill without its fault watch"
        child, above = node, node.parent
        while isinstance(above, RECOVERY_STEPS):
            alternative = isinstance(above, OrElse) and above.children[1] is child
            assert not alternative, f"{node.name}: an alternative without a Safety guard of its own"
            child, above = above, above.parent
        assert isinstance(above, SafetyGuard), f"{node.name} is not wrapped"
        checked += 1
    return checked


@pytest.mark.parametrize("mission", MISSIONS, ids=lambda p: p.name)
def test_every_mission_is_fully_wrapped(mission):
    run = build_run(mission)
    described = [path for _, path in run.compiled.nodes if not path.endswith(".or_else")]  # "or else" is a step
    assert assert_fully_wrapped(run.compiled.root) == len(described) > 0


@pytest.mark.parametrize("behavior", BEHAVIORS)
def test_every_behaviour_is_fully_wrapped(behavior):
    world, samples = IN_OTHER_WORLDS.get(behavior, ("apartment", SAMPLE_ARGS))
    args = {k: samples[k] for k in _default_args(BehaviorLibrary().behaviors[behavior])}
    run = build_run({"mission": f"wrap {behavior}", "world": world, "tree": {behavior: args}})
    assert assert_fully_wrapped(run.compiled.root) > 1


def test_the_check_catches_an_unwrapped_node():
    run = build_run({"mission": "x", "tree": {"sequence": [{"wait": {"seconds": 1}}]}})
    sequence = run.compiled.root.decorated
    guard = sequence.children[0]
    # splice the bare leaf in place of its wrappers: the walk must notice
    leaf = guard.decorated.decorated  # safety → faults → wait
    leaf.parent = sequence
    sequence.children[0] = leaf
    with pytest.raises(AssertionError, match="without its fault watch"):
        assert_fully_wrapped(run.compiled.root)
