"""The centre of mass's plan for a footstep sequence: a ZMP reference and the DCM that goes with it.

The linear inverted pendulum, c̈ = ω² (c − p) with the centre of mass c at a constant height and p the zero-moment
point (ZMP), has a divergent component of motion (DCM) ξ = c + ċ/ω that obeys ξ̇ = ω (ξ − p), while c follows ξ
(ċ = −ω (c − ξ)). The plan's ZMP is piecewise linear in time: still at the stance sole's centre in single
support, moving from one sole to the next in double support, and to the middle of the feet at the end, where
the robot stands. On a segment where p(t) = p_0 + ṗ (t − t_0), ξ(t) = p(t) + ṗ/ω + e^{ω (t − t_1)} (ξ_1 − p_1 − ṗ/ω)
exactly, so one backward pass from the end (ξ = p: standing still) gives the one DCM trajectory that does not
diverge (Englsberger, Ott and Albu-Schäffer, "Three-dimensional bipedal walking control based on divergent
component of motion", IEEE T-RO 2015).
"""

from __future__ import annotations

import itertools
import math

import numpy as np


class DcmPlan:
    """ZMP and DCM references through the knots (t_i, p_i): p linear between knots, held after the last."""

    def __init__(
        self, times: list[float], zmps: list[np.ndarray], omega: float, start_dcm: np.ndarray | None = None
    ) -> None:
        """``start_dcm``: the DCM the plan must start from (a robot standing still, about to walk); the first
        knot's ZMP is then chosen to give it, instead of the one given."""
        if len(times) != len(zmps) or not times:
            raise ValueError("a DCM plan needs one ZMP per knot time, and at least one")
        if any(b < a for a, b in itertools.pairwise(times)):
            raise ValueError("knot times must not decrease")
        self.omega = omega
        self.times = np.asarray(times, dtype=float)
        self.zmps = np.array([np.asarray(p, dtype=float) for p in zmps])
        # ξ at each knot, backwards from the end where the robot stands still over its last ZMP
        dcms = np.empty_like(self.zmps)
        dcms[-1] = self.zmps[-1]
        for i in range(len(times) - 2, -1, -1):
            duration = self.times[i + 1] - self.times[i]
            if duration <= 0.0:
                dcms[i] = dcms[i + 1]
                continue
            slope = (self.zmps[i + 1] - self.zmps[i]) / duration
            dcms[i] = (
                self.zmps[i]
                + slope / omega
                + math.exp(-omega * duration) * (dcms[i + 1] - self.zmps[i + 1] - slope / omega)
            )
        if start_dcm is not None and len(times) > 1 and self.times[1] > self.times[0]:
            # ξ_0 is affine in p_0 on the first segment: ξ_0 = a p_0 + b, with ωΔ = r and e^{−r} = d,
            # a = 1 − (1 − d)/r and b = p_1 (1 − d)/r + d (ξ_1 − p_1): solve for the p_0 that starts at start_dcm
            r = omega * (self.times[1] - self.times[0])
            d = math.exp(-r)
            a = 1.0 - (1.0 - d) / r
            b = self.zmps[1] * (1.0 - d) / r + d * (dcms[1] - self.zmps[1])
            self.zmps[0] = (np.asarray(start_dcm, dtype=float) - b) / a
            dcms[0] = np.asarray(start_dcm, dtype=float)
        self.dcms = dcms

    def at(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(p, ξ, ξ̇) at time ``t``: the ZMP, the DCM and its rate."""
        times = self.times
        if t >= times[-1]:
            return self.zmps[-1].copy(), self.dcms[-1].copy(), np.zeros_like(self.dcms[-1])
        i = max(int(np.searchsorted(times, t, side="right")) - 1, 0)
        t = max(t, float(times[0]))
        duration = times[i + 1] - times[i]
        slope = (self.zmps[i + 1] - self.zmps[i]) / duration
        zmp = self.zmps[i] + slope * (t - times[i])
        dcm = (
            zmp
            + slope / self.omega
            + math.exp(self.omega * (t - times[i + 1])) * (self.dcms[i + 1] - self.zmps[i + 1] - slope / self.omega)
        )
        return zmp, dcm, self.omega * (dcm - zmp)
