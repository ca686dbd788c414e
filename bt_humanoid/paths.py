"""Where robots/, worlds/, behaviors/ and missions/ live.

They sit beside the package in the repository (an editable install), or
wherever ``BT_HUMANOID_HOME`` points.
"""

from __future__ import annotations

import os
from pathlib import Path


def project_root() -> Path:
    """The folder holding robots/, worlds/, behaviors/ and missions/."""
    env = os.environ.get("BT_HUMANOID_HOME")
    if env:
        return Path(env).resolve()
    return Path(__file__).resolve().parent.parent


def robots_dir() -> Path:
    return project_root() / "robots"


def worlds_dir() -> Path:
    return project_root() / "worlds"


def behaviors_dir() -> Path:
    return project_root() / "behaviors"


def missions_dir() -> Path:
    return project_root() / "missions"
