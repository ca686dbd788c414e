"""Leaf behaviours. Importing this package registers every built-in skill."""

from bt_humanoid.skills import blackboard_skills, motion_skills, speech_skills, timing_skills  # noqa: F401
from bt_humanoid.skills.registry import REGISTRY, SkillInfo, skill

__all__ = ["REGISTRY", "SkillInfo", "skill"]
