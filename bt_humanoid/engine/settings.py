"""A mission's safety settings, resolved once against the robot's defaults, each with the layer it came from."""

from __future__ import annotations

from dataclasses import dataclass, fields

from bt_humanoid.mission.schema import SafetySection
from bt_humanoid.sim.robot_config import SafetyDefaults


@dataclass(frozen=True)
class Setting:
    value: float
    source: str  # where the value came from: "mission safety:" or "robot.yaml safety:"


@dataclass(frozen=True)
class SafetyLimits:
    """What a run enforces. A mission may lower the robot's base speed cap, never raise it."""

    max_base_speed: Setting
    joint_limit_margin: Setting
    time_budget: Setting


MISSION = "mission safety:"
ROBOT = "robot.yaml safety:"


def resolve_safety(mission: SafetySection, robot: SafetyDefaults) -> SafetyLimits:
    """Each setting from the mission where it sets one, else the robot's default; the speed cap is the lower."""
    resolved = {}
    for name in (f.name for f in fields(SafetyLimits)):
        asked, default = getattr(mission, name), getattr(robot, name)
        if asked is None:
            resolved[name] = Setting(default, ROBOT)
        elif name == "max_base_speed" and asked > default:
            resolved[name] = Setting(default, f"{ROBOT} (the mission asked for {asked:g})")
        else:
            resolved[name] = Setting(asked, MISSION)
    return SafetyLimits(**resolved)
