"""The one table between the mission language and BehaviorTree.CPP v4's node vocabulary.

Export, import, the TreeNodesModel and docs/btcpp.md all read it, so a node kind maps the same way everywhere.
"""

from __future__ import annotations

from dataclasses import dataclass

#: mission composites → BehaviorTree.CPP controls (children in order)
COMPOSITE_TAGS = {
    "sequence": "Sequence",
    "fallback": "Fallback",
    "reactive_sequence": "ReactiveSequence",
    "reactive_fallback": "ReactiveFallback",
}
#: BehaviorTree.CPP controls read as mission composites (SequenceWithMemory: see SEMANTICS)
TAG_COMPOSITES = {tag: kind for kind, tag in COMPOSITE_TAGS.items()} | {"SequenceWithMemory": "sequence"}

#: mission decorators with one child → BehaviorTree.CPP decorators: (tag, its port, the mission setting)
DECORATOR_TAGS = {
    "retry": ("RetryUntilSuccessful", "num_attempts", "attempts"),
    "timeout": ("Timeout", "msec", "seconds"),
    "repeat": ("Repeat", "num_cycles", "times"),
    "invert": ("Inverter", None, None),
    "force_success": ("ForceSuccess", None, None),
    "force_failure": ("ForceFailure", None, None),
}
TAG_DECORATORS = {tag: (kind, port, setting) for kind, (tag, port, setting) in DECORATOR_TAGS.items()}

#: BehaviorTree.CPP's own node names that have no counterpart here (an import names them as such)
UNSUPPORTED_BUILTINS = (
    "AlwaysFailure",
    "AlwaysSuccess",
    "AsyncFallback",
    "AsyncSequence",
    "Delay",
    "IfThenElse",
    "KeepRunningUntilFailure",
    "LoopBool",
    "LoopDouble",
    "LoopInt",
    "LoopString",
    "ParallelAll",
    "Precondition",
    "RunOnce",
    "Script",
    "ScriptCondition",
    "SetBlackboard",
    "SkipUnlessUpdated",
    "Sleep",
    "Switch2",
    "Switch3",
    "Switch4",
    "Switch5",
    "Switch6",
    "TryCatch",
    "UnsetBlackboard",
    "WaitValueUpdate",
    "WasEntryUpdated",
    "WhileDoElse",
)
#: attributes BehaviorTree.CPP gives every node (pre- and post-conditions in its script language): not read here
SCRIPTED_ATTRIBUTES = (
    "_skipIf",
    "_while",
    "_successIf",
    "_failureIf",
    "_onSuccess",
    "_onFailure",
    "_post",
    "_onHalted",
)


@dataclass(frozen=True)
class CustomNode:
    """A node of ours that BehaviorTree.CPP does not have: its category, ports and description."""

    id: str
    category: str  # Control or Decorator
    ports: tuple[tuple[str, str, str | None, str], ...]  # (name, type, default, description)
    description: str


ROUND_ROBIN = CustomNode(
    "RoundRobin",
    "Control",
    (),
    "one child per run, taking turns (the next run runs the next child); its status is that child's",
)
RECOVERY_PORTS = (
    ("retries", "int", None, "extra attempts after a failure"),
    ("backoff", "double", None, "simulation seconds between attempts"),
    ("replan", "int", None, "times the enclosing sequence starts over when this still fails"),
    ("ask", "bool", None, "when all else failed, ask the person whether to try again"),
)
#: a node's own recovery (the mission's ``recovery:``), written around it
RECOVERY = CustomNode("Recovery", "Decorator", RECOVERY_PORTS, "the child's recovery: retries, replan, ask")
RECOVERY_OR_ELSE = CustomNode(
    "RecoveryOrElse",
    "Control",
    RECOVERY_PORTS,
    "the first child's recovery; the second child is its alternative, run when the first still fails",
)
#: the nodes of our own a mission XML may hold
MISSION_NODES = (ROUND_ROBIN, RECOVERY, RECOVERY_OR_ELSE)

#: the wrappers the compiler adds (engine/decorators.py), in a compiled export only: they are not read back
WRAPPERS = (
    CustomNode(
        "SafetyGuard",
        "Decorator",
        (),
        "halts its branch and fails on a stop request, collision, joint limit, workspace or time budget violation",
    ),
    CustomNode("FaultWatch", "Decorator", (), "fails its skill on a dropped object, joint strain or lack of progress"),
    CustomNode(
        "RecoveryRetry",
        "Decorator",
        (
            ("retries", "int", None, "extra attempts after a failure"),
            ("backoff", "double", None, "simulation seconds between attempts"),
        ),
        "runs the child again after it fails, backoff simulation seconds apart",
    ),
    CustomNode(
        "RecoveryReplan",
        "Decorator",
        (
            ("backoff", "double", None, "simulation seconds before starting over"),
            ("watches", "std::string", None, "the nodes below whose failure starts this sequence over (×times)"),
        ),
        "starts its sequence over when a node below that may replan failed",
    ),
    CustomNode("RecoveryAsk", "Decorator", (), "once all else failed, asks whether to try the child again"),
    CustomNode("OrElse", "Control", (), "the first child (with its retries), or else the second, its alternative"),
)
WRAPPER_IDS = {node.id for node in WRAPPERS}
MISSION_NODE_IDS = {node.id: node for node in MISSION_NODES}

#: where BehaviorTree.CPP would run a node differently, keyed by the XML element; written as an XML comment
#: for the elements a document holds, and in docs/btcpp.md
SEMANTICS = {
    "Sequence": "Sequence: as BehaviorTree.CPP's (a running child is resumed, a failure starts it over next "
    "time); SequenceWithMemory is read as Sequence",
    "Parallel": "Parallel: success_count -1 (all) or 1, failure_count 1; children that succeeded are not ticked again",
    "Timeout": "Timeout: msec of simulation time, not wall-clock time",
    "RoundRobin": "RoundRobin: one child per run and its status (Nav2's moves on to the next child in the same "
    "tick when one fails)",
    "ReactiveSequence": "ReactiveSequence/ReactiveFallback: their children are written <ID …/> (BehaviorTree.CPP "
    "4.8 looks up a reactive node's children by element name); a mission's guard is a ReactiveSequence of its "
    "condition and its child",
    "SubTree": "SubTree: behaviours share the one blackboard (as with _autoremap); {param} inside a longer text "
    "is filled in here, BehaviorTree.CPP would keep the braces",
    "Recovery": "Recovery/RecoveryOrElse: the node's own recovery; the compiler adds the retries, replan, ask "
    "and alternative it asks for, and a safety guard around every node",
    "SafetyGuard": "compiled tree: the wrappers the compiler added (SafetyGuard, FaultWatch, RecoveryRetry, "
    "RecoveryReplan, RecoveryAsk, OrElse); bt-export's no-wrappers flag writes a tree bt-run can read back",
}
