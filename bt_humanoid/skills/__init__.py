"""Leaf behaviours. Importing this package registers every built-in skill."""

from bt_humanoid.skills import (  # noqa: F401
    arm_skills,
    blackboard_skills,
    manipulation_skills,
    motion_skills,
    navigation_skills,
    perception_skills,
    speech_skills,
    timing_skills,
)
from bt_humanoid.skills.registry import REGISTRY, SkillInfo, skill

__all__ = ["REGISTRY", "SkillInfo", "skill"]
