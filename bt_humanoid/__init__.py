"""bt-humanoid: behaviour-tree missions for a simulated humanoid in MuJoCo."""

__version__ = "0.1.0"

import os as _os

# Off-screen rendering without a display needs EGL; it must be chosen before mujoco is first imported.
_os.environ.setdefault("MUJOCO_GL", "egl")
