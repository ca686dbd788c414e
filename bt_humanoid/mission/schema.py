"""The one mission schema.

Every tree node is a mapping with exactly one *kind* key (``sequence``,
``retry``, ``move_base``, a behaviour name, …) plus optional ``name`` and
``recovery``. The pydantic models below are used twice: the loader validates
each node's body with the model of its kind (which gives precise, positioned
error messages), and ``json_schema()`` combines them into the JSON Schema that
editors use. Skills come from the skill registry, behaviours from behaviors/.
"""

from __future__ import annotations

from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, create_model

from bt_humanoid.skills import REGISTRY
from bt_humanoid.strict_model import StrictModel

# --- mission-level sections ----------------------------------------------------


class RecoveryBudget(StrictModel):
    """After a node fails, in this order: retry it, run its alternative, start the enclosing sequence over
    (replan), ask the person. A field left out falls back to the mission's per-skill setting, then the
    mission's, then the skill's own default, then the robot's."""

    retries: int | None = Field(None, ge=0, le=10, description="extra attempts after a failure")
    backoff: float | None = Field(None, ge=0, le=60, description="simulation seconds between attempts")
    replan: int | None = Field(
        None,
        ge=0,
        le=5,
        description="times the enclosing sequence starts over from its first step when this still fails "
        "(perception looks again, routes and grasps are planned anew)",
    )
    ask: bool | None = Field(
        None, description="when all else failed, ask the person whether to try again (when someone can answer)"
    )


class RecoverySettings(RecoveryBudget):
    alternative: dict[str, Any] | None = Field(
        None, description="a node (skill, behaviour, tree) to run instead when this one still fails"
    )


class RecoverySection(RecoveryBudget):
    skills: dict[str, RecoverySettings] = Field(default_factory=dict, description="per-skill overrides")


class SafetySection(StrictModel):
    max_base_speed: float | None = Field(None, gt=0, le=2.0, description="m/s cap on base motion")
    joint_limit_margin: float | None = Field(None, ge=0, le=0.5, description="rad past a joint range that trips")
    time_budget: float | None = Field(None, gt=0, le=86400, description="simulation seconds for the whole mission")


class PlaceTolerance(StrictModel):
    place: str
    tolerance: float = Field(0.15, gt=0, description="metres from the place's pose")
    yaw_tolerance: float = Field(15.0, gt=0, description="degrees from the place's heading")


class OnCondition(StrictModel):
    on: tuple[str, str] = Field(description="[object, surface]: the object rests on the surface")


class InsideCondition(StrictModel):
    inside: tuple[str, str] = Field(description="[object, container]: the object lies in an open bin, below its rim")


class AtCondition(StrictModel):
    at: str | PlaceTolerance = Field(description="the robot stands at a named place")


class InHandCondition(StrictModel):
    in_hand: str = Field(description="the object is held between the fingers of a gripper")


class UprightCondition(StrictModel):
    upright: str = Field(description="the object stands upright (within 15°)")


class NearSpot(StrictModel):
    object: str
    position: tuple[float, float] = Field(description="[x, y] in the world (m)")
    within: float = Field(0.03, gt=0, description="metres, horizontal distance")


class NearCondition(StrictModel):
    near: NearSpot = Field(description="the object's centre lies within `within` of a spot (horizontally)")


class DeliveredCondition(StrictModel):
    delivered: str = Field(description="the object was handed over: in a person's hand (both their fingers on it)")


class GripperCondition(StrictModel):
    gripper: tuple[Literal["left", "right"], Literal["open", "closed"]] = Field(description="[side, state]")


SuccessCondition = (
    OnCondition
    | InsideCondition
    | AtCondition
    | InHandCondition
    | UprightCondition
    | NearCondition
    | GripperCondition
    | DeliveredCondition
)
CONDITION_KINDS = ("on", "inside", "at", "in_hand", "upright", "near", "gripper", "delivered")


class MissionHeader(StrictModel):
    """Everything in a mission file except its tree."""

    mission: str = Field(description="what the mission does, in a few words")
    description: str = ""
    world: str = Field("apartment", description="a folder of worlds/")
    robot: str = Field("wheeled_humanoid", description="a folder of robots/")
    scene: str | None = Field(
        None,
        description="where the world's objects stand, where the robot starts and what it holds: a scene of the "
        "world (worlds/WORLD/scenes/NAME.yaml) by name, or a scene file relative to this one; none: the world's "
        "own (bt-run --scene overrides it)",
    )
    seed: int = Field(0, description="default random seed")
    safety: SafetySection = SafetySection()
    recovery: RecoverySection = RecoverySection()
    blackboard: dict[str, Any] = Field(default_factory=dict, description="initial blackboard values")
    success: list[SuccessCondition] = Field(default_factory=list, description="checked in ground truth at the end")


# --- tree nodes -------------------------------------------------------------------

COMPOSITES = {
    "sequence": "children in order; remembers progress",
    "fallback": "children in order until one succeeds; remembers progress",
    "reactive_sequence": "sequence that re-checks earlier children every tick",
    "reactive_fallback": "fallback that re-tries higher-priority children every tick",
    "round_robin": "one child per run, taking turns (the next run runs the next child); its status is that child's",
}
DECORATOR_DESCRIPTIONS = {
    "parallel": "children at once; success by policy",
    "retry": "re-run the child after failure, up to attempts",
    "timeout": "fail and halt the child after seconds of simulation time",
    "repeat": "run the child until it has succeeded times",
    "invert": "success ↔ failure",
    "force_success": "failure counts as success",
    "force_failure": "success counts as failure",
    "guard": "run the child while the condition holds",
    "subtree": "a behaviour from a YAML file, with arguments",
}
NODE_EXTRAS = ("name", "recovery")


def decorator_bodies(node: Any) -> dict[str, type[BaseModel]]:
    """Body models of the non-leaf kinds; ``node`` types their children.

    The loader passes ``Any`` (it validates children itself, with positions);
    the JSON Schema passes the node union.
    """
    strict = ConfigDict(extra="forbid")

    def body(name: str, **fields: Any) -> type[BaseModel]:
        return create_model(name, __config__=strict, **fields)

    child = (node, Field(description="the decorated node"))
    return {
        "parallel": body(
            "ParallelBody",
            policy=(Literal["all", "one"], Field("all", description="succeed when all children succeed, or one")),
            children=(list[node], Field(min_length=1)),
        ),
        "retry": body("RetryBody", attempts=(int, Field(ge=1, le=100, description="total attempts")), child=child),
        "timeout": body(
            "TimeoutBody", seconds=(float, Field(gt=0, le=86400, description="simulation seconds")), child=child
        ),
        "repeat": body("RepeatBody", times=(int, Field(ge=1, le=100000, description="successes needed")), child=child),
        "invert": body("InvertBody", child=child),
        "force_success": body("ForceSuccessBody", child=child),
        "force_failure": body("ForceFailureBody", child=child),
        "guard": body(
            "GuardBody",
            condition=(node, Field(description="re-checked every tick; the child is halted when it fails")),
            child=child,
        ),
        "subtree": body(
            "SubtreeBody",
            file=(str, Field(description="path of a behaviour YAML file, relative to this file")),
            args=(dict[str, Any], Field(default_factory=dict)),
        ),
    }


LOADER_BODIES = decorator_bodies(Any)


def structural_kinds() -> list[str]:
    return [*COMPOSITES, *DECORATOR_DESCRIPTIONS]


def json_schema(behaviors: dict[str, type[BaseModel]]) -> dict[str, Any]:
    """JSON Schema of a mission file; ``behaviors`` maps behaviour names to their argument models."""
    bodies = decorator_bodies("Node")
    node_recovery = create_model(
        "NodeRecovery",
        __base__=RecoverySettings,
        alternative=(
            "Node | None",
            Field(None, description=RecoverySettings.model_fields["alternative"].description),
        ),
    )
    # "Node" is a forward reference, resolved by model_rebuild below
    kinds: dict[str, tuple[Any, str]] = {k: (list["Node"], d) for k, d in COMPOSITES.items()}  # noqa: F821
    kinds |= {k: (bodies[k], d) for k, d in DECORATOR_DESCRIPTIONS.items()}
    kinds |= {k: (info.params, info.description) for k, info in REGISTRY.items()}
    kinds |= {k: (model, model.__doc__ or "") for k, model in behaviors.items()}
    extras = {
        "name": (str | None, Field(None, description="label shown in the live tree and the event log")),
        "recovery": (
            node_recovery | None,
            Field(None, description="this node's recovery: retries, alternative, replan, ask"),
        ),
    }
    models = [
        create_model(
            f"{kind}_node",
            __config__=ConfigDict(extra="forbid", title=kind),
            __doc__=description,
            **{kind: (body, Field(description=description))},
            **extras,
        )
        for kind, (body, description) in kinds.items()
    ]
    node_union: Any = models[0]
    for model in models[1:]:
        node_union = node_union | model
    namespace = {"Node": node_union}
    for model in [node_recovery, *bodies.values(), *models]:
        model.model_rebuild(_types_namespace=namespace)
    mission = create_model(
        "Mission", __base__=MissionHeader, tree=(node_union, Field(description="the behaviour tree"))
    )
    schema = mission.model_json_schema()
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "bt-humanoid mission"
    return schema
