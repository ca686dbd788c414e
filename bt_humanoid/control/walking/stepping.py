"""Step adjustment: where, and how soon, the swinging foot must land to capture a disturbed DCM.

After Khadiv et al. ("Walking control based on step timing adaptation", IEEE T-RO 2020), in closed form. While
the DCM error e = ξ − ξ_ref lies within what the stance sole's centre of pressure can answer (its ``room`` that
way, ``cop_room``), the balance law's ankle torque makes it decay and the footstep stays. Beyond, the centre of
pressure stops at the sole's edge, p = c + room ê, and the DCM runs away as ξ(τ) = p + (ξ − p) e^{ω τ}: the
footstep moves by what that adds to the plan's DCM at touchdown (less the room the new sole will have), within
what the legs can reach. The nominal landing time is kept while that footstep is reachable; otherwise the foot
lands sooner, where the DCM has gone less far.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from bt_humanoid.control.walking.footsteps import Footstep, StepLimits

TIMING_CANDIDATES = 8  # landing times tried, from the nominal one to the soonest
REACH_TOLERANCE = 0.01  # m: a footstep this near to the one wanted is as good


@dataclass(frozen=True)
class Sole:
    """The centre of pressure's reach on a sole: half its length and width, less the cone's margin (m)."""

    half_length: float
    half_width: float


def cop_room(stance: Footstep, direction: np.ndarray, sole: Sole, share: float) -> float:
    """How far the centre of pressure may go from the stance sole's centre towards ``direction`` (world, unit):
    to the edge of the sole's rectangle, times ``share`` (what the ankles are counted on for)."""
    c, s = math.cos(stance.yaw), math.sin(stance.yaw)
    along, across = abs(c * direction[0] + s * direction[1]), abs(-s * direction[0] + c * direction[1])
    return share * min(sole.half_length / max(along, 1e-9), sole.half_width / max(across, 1e-9))


def capture_step(
    nominal: Footstep,
    stance: Footstep,
    dcm: np.ndarray,
    dcm_reference: np.ndarray,
    touchdown_dcm: np.ndarray,
    omega: float,
    remaining: float,
    shortest: float,
    room: float,
    limits: StepLimits,
) -> tuple[Footstep, float] | None:
    """The footstep and the time to touchdown (s from now) that capture the DCM; None while the ankles can.

    ``nominal``: the planned footstep, landing ``remaining`` s from now, where the plan has the DCM at
    ``touchdown_dcm``; ``dcm`` and ``dcm_reference``: the DCM now and the plan's; ``shortest``: the soonest the
    foot may land (s from now); ``room``: the centre of pressure's reach from the stance sole's centre towards
    the error (``cop_room``); ``limits``: where the foot may go relative to ``stance``.
    """
    error = np.asarray(dcm, dtype=float) - dcm_reference
    size = float(np.linalg.norm(error))
    if size <= room:
        return None
    direction = error / size
    pivot = stance.position + room * direction  # the centre of pressure, at the sole's edge
    offset = touchdown_dcm - nominal.position  # the plan's DCM from the footstep at touchdown
    best: tuple[float, float, Footstep] | None = None
    for duration in np.linspace(remaining, min(shortest, remaining), TIMING_CANDIDATES):
        needed = pivot + (dcm - pivot) * math.exp(omega * duration) - offset - room * direction
        wanted = Footstep(nominal.side, float(needed[0]), float(needed[1]), nominal.yaw)
        target = limits.clip(wanted, stance)
        miss = float(np.linalg.norm(target.position - wanted.position))
        if best is None or miss < best[0] - REACH_TOLERANCE:
            best = (miss, float(duration), target)
        if miss <= REACH_TOLERANCE:
            break
    assert best is not None
    return best[2], best[1]
