"""Step adjustment: where, and how soon, the swinging foot must land to capture a disturbed DCM.

After Khadiv et al. ("Walking control based on step timing adaptation", IEEE T-RO 2020), in closed form. While
the DCM error e = ξ − ξ_ref lies within what the stance sole's centre of pressure can answer (its ``room`` that
way, ``cop_room``), the balance law's ankle torque makes it decay and the footstep stays. Beyond, the centre of
pressure stops at the sole's edge, p = c + room ê, and the DCM runs away as ξ(τ) = p + (ξ − p) e^{ω τ}: the
footstep moves by what that adds to the plan's DCM at touchdown (less the room the new sole will have), within
what the legs can reach. The nominal landing time is kept while that footstep is reachable; otherwise the foot
lands sooner, where the DCM has gone less far. A footstep wanted across the stance foot (the DCM pushed to the
stance foot's side) cannot be taken without crossing the legs: the foot lands as soon as it may, beside the
stance foot, so that the other foot, the one on the side of the push, lifts sooner and steps out.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from bt_humanoid.control.walking.footsteps import SIDE_SIGN, Footstep, StepLimits

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


def needed_step(
    nominal: Footstep,
    stance: Footstep,
    dcm: np.ndarray,
    touchdown_dcm: np.ndarray,
    omega: float,
    duration: float,
    room: float,
    direction: np.ndarray,
) -> Footstep:
    """Where the swinging foot must land ``duration`` s from now to capture the DCM, wherever that is: the
    centre of pressure at the stance sole's edge towards ``direction`` (``room`` from its centre) until then,
    and the DCM at touchdown where the plan has it from ``nominal`` (``touchdown_dcm``), less the new sole's
    room. See ``capture_step`` for the arguments."""
    pivot = stance.position + room * direction
    needed = pivot + (dcm - pivot) * math.exp(omega * duration) - (touchdown_dcm - nominal.position) - room * direction
    return Footstep(nominal.side, float(needed[0]), float(needed[1]), nominal.yaw)


def crosses(step: Footstep, stance: Footstep, limits: StepLimits) -> bool:
    """Whether ``step`` lies across the stance foot from its own side, nearer than the feet may come
    (``StepLimits.narrowest``): where only a crossing step would go, and the other foot must step instead."""
    _, dy, dyaw = step.relative_to(stance)
    return SIDE_SIGN[step.side] * dy < limits.narrowest(dyaw) - REACH_TOLERANCE


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

    def wanted(duration: float) -> Footstep:
        return needed_step(nominal, stance, dcm, touchdown_dcm, omega, duration, room, direction)

    soonest = min(shortest, remaining)
    if crosses(wanted(remaining), stance, limits):
        # the DCM went to the stance foot's side: the other foot must catch it, and it lifts only once this one is
        # down, so this one lands as soon as it may, as near that side as it may
        return limits.clip(wanted(soonest), stance), soonest
    best: tuple[float, float, Footstep] | None = None
    for duration in np.linspace(remaining, soonest, TIMING_CANDIDATES):
        step = wanted(duration)
        target = limits.clip(step, stance)
        miss = float(np.linalg.norm(target.position - step.position))
        if best is None or miss < best[0] - REACH_TOLERANCE:
            best = (miss, float(duration), target)
        if miss <= REACH_TOLERANCE:
            break
    assert best is not None
    return best[2], best[1]
