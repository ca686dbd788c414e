"""The robot's belief of where its base is: odometry, corrected against the map by the base scanner.

An extended Kalman filter over (x, y, yaw). Each control step ``predict`` moves the belief by what the
odometry reports and widens it; each scan ``correct`` matches the scan to the map from the belief
(``match_scan``) and pulls the belief towards the match as far as the two covariances say. A match that
disagrees with the belief beyond what both allow is not used (a crowd, a moved sofa). The filter notices when
it no longer knows where it is:

- matches that fit the map well, far from the belief, for ``JUMP_AFTER`` seconds: the robot was moved
  (carried, pushed, its wheels spun): the belief jumps to the match (re-localised). Before that, each such
  match widens the belief, so a belief that was merely too sure of drifting odometry is pulled back by fusing;
- no match fits from the belief for ``LOST_AFTER`` seconds while the scanner sees enough of the map: a search
  of the whole map for the pose the scan fits best; a clear winner re-localises, otherwise the robot is
  ``lost`` until a later search succeeds (whoever drives it must stop and ask).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from bt_humanoid.localisation.odometry import apply_increment
from bt_humanoid.localisation.scan_map import ScanMap
from bt_humanoid.localisation.scan_matcher import Match, match_scan

MIN_POINTS = 20  # scan points that hit anything: fewer, and the scan says too little to match
GOOD_FIT = 0.5  # share of a scan's points on the map for a match to count
CLEAR_FIT = 0.75  # share for a match far from the belief, or a search's winner, to be believed
GATE = 16.3  # Mahalanobis² (3 dof, 99.9 %): a match farther from the belief than this is not fused
JUMP_AFTER = 1.0  # s of well-fitting matches away from the belief before it jumps to them
LOST_AFTER = 2.0  # s without a fitting match before searching the whole map
MATCH_FLOOR = np.array([0.003, 0.003, math.radians(0.2)]) ** 2  # a match is never more certain than this
DOUBT = 4.0  # the belief's covariance grows by this for each well-fitting match it rejects
ODOMETRY_SHARE = 0.05  # σ of each odometry increment, as a share of it: 2.5 σ of a calibrated base's scale error
ODOMETRY_FLOOR = np.array([1e-4, 1e-4, 1e-4]) ** 2  # per step, so the belief never stops widening in motion
SEARCH_STEP, SEARCH_YAWS, SEARCH_POINTS, SEARCH_CLEARANCE = 0.1, 72, 60, 0.2  # m, headings, points, m


class Localiser:
    """Belief (``pose``, ``covariance``) of the base on ``scan_map``, from a known start."""

    def __init__(
        self,
        scan_map: ScanMap,
        start: np.ndarray,
        on_event: Callable[[str, str], None] | None = None,
        odometry_share: float = ODOMETRY_SHARE,
    ) -> None:
        """``odometry_share``: σ of an odometry increment as a share of it (what the robot knows of its wheels)."""
        self.scan_map = scan_map
        self.odometry_share = odometry_share
        self.pose = np.asarray(start, dtype=float).copy()
        self.covariance = np.diag([0.02, 0.02, math.radians(1.0)]) ** 2
        self.lost = False
        self.last_match: Match | None = None
        self.on_event = on_event
        self._time = 0.0
        self._fitted_at = 0.0  # when a match last fitted the belief
        self._away_since: float | None = None  # since when well-fitting matches have lain away from the belief
        self.corrections = 0  # matches fused
        self.relocalisations = 0

    def predict(self, increment: np.ndarray) -> None:
        """Move the belief by an odometry ``body_increment`` and widen it by what odometry may get wrong."""
        forward, left, turn = (float(v) for v in increment)
        heading = float(self.pose[2]) + 0.5 * turn
        c, s = math.cos(heading), math.sin(heading)
        along = np.array([-s * forward - c * left, c * forward - s * left])
        moves = np.eye(3)
        moves[:2, 2] = along
        inputs = np.array([[c, -s, 0.5 * along[0]], [s, c, 0.5 * along[1]], [0.0, 0.0, 1.0]])
        spread = np.diag((self.odometry_share * np.abs(increment)) ** 2 + ODOMETRY_FLOOR)
        self.pose = apply_increment(self.pose, increment)
        self.covariance = moves @ self.covariance @ moves.T + inputs @ spread @ inputs.T

    def correct(self, points: np.ndarray, now: float) -> Match | None:
        """Match one scan (scanner frame = the base's frame, N × 2) and fuse it; the match, or None when the scan
        saw too little."""
        self._time = now
        if len(points) < MIN_POINTS:
            return None
        match = match_scan(self.scan_map, points, self.pose)
        self.last_match = match
        if match.fraction < GOOD_FIT or match.inliers < MIN_POINTS:
            self._unfitted(points, now)
            return match
        innovation = match.pose - self.pose
        innovation[2] = math.remainder(float(innovation[2]), 2 * math.pi)
        measurement = match.covariance + np.diag(MATCH_FLOOR)
        combined = self.covariance + measurement
        distance = float(innovation @ np.linalg.solve(combined, innovation))
        if distance > GATE:
            if match.fraction >= CLEAR_FIT:
                # a scan that fits the map well disagrees: the belief was surer than it had reason to be (the
                # wheels' scale errors are systematic); widen it, and the next such match will be fused
                self.covariance *= DOUBT
                self._away_since = now if self._away_since is None else self._away_since
                if now - self._away_since >= JUMP_AFTER:
                    self._relocalise(match, "the scan fits the map well away from where I thought I was")
            self._unfitted(points, now)
            return match
        self._away_since = None
        gain = self.covariance @ np.linalg.inv(combined)
        self.pose = self.pose + gain @ innovation
        self.covariance = (np.eye(3) - gain) @ self.covariance
        self.covariance = 0.5 * (self.covariance + self.covariance.T)
        self._fitted_at = now
        self.corrections += 1
        if self.lost:
            self.lost = False
            self._event("localised", "found my place on the map again")
        return match

    # --- losing and finding the place ----------------------------------------------------------------------------

    def _unfitted(self, points: np.ndarray, now: float) -> None:
        if now - self._fitted_at < LOST_AFTER:
            return
        found = search_map(self.scan_map, points)
        if found is not None:
            self._relocalise(found, "searched the whole map for where the scan fits")
            return
        self._fitted_at = now  # search again after another LOST_AFTER, not every scan
        if not self.lost:
            self.lost = True
            self._event("lost", "the scan fits nowhere on the map: I do not know where I am")

    def _relocalise(self, match: Match, why: str) -> None:
        self.pose = match.pose.copy()
        self.covariance = match.covariance + np.diag(MATCH_FLOOR)
        self._fitted_at, self._away_since = self._time, None
        self.relocalisations += 1
        self.lost = False
        self._event("relocalised", f"{why}: now at ({self.pose[0]:.2f}, {self.pose[1]:.2f})")

    def _event(self, kind: str, text: str) -> None:
        if self.on_event is not None:
            self.on_event(kind, text)


def search_map(scan_map: ScanMap, points: np.ndarray) -> Match | None:
    """The pose anywhere on the map where ``points`` fit best, if one fits clearly (``CLEAR_FIT``) and no other,
    away from it, fits nearly as well; None otherwise (a symmetric room, or a scan of things not on the map)."""
    if len(points) < MIN_POINTS:
        return None
    sample = points[np.linspace(0, len(points) - 1, min(SEARCH_POINTS, len(points))).astype(int)]
    stride = round(SEARCH_STEP / scan_map.resolution)
    free = scan_map.distance[::stride, ::stride] > SEARCH_CLEARANCE
    rows, cols = np.nonzero(free)
    centres = scan_map.origin + (np.stack([cols, rows], axis=1) * stride + 0.5) * scan_map.resolution
    magnitude = np.abs(scan_map.distance)
    shape = np.array(magnitude.shape)
    scores = np.zeros((SEARCH_YAWS, len(centres)))
    for k, yaw in enumerate(np.linspace(0.0, 2 * math.pi, SEARCH_YAWS, endpoint=False)):
        c, s = math.cos(yaw), math.sin(yaw)
        turned = sample @ np.array([[c, s], [-s, c]])
        cells = np.floor((centres[:, None, :] + turned[None] - scan_map.origin) / scan_map.resolution).astype(int)
        col, row = np.clip(cells[..., 0], 0, shape[1] - 1), np.clip(cells[..., 1], 0, shape[0] - 1)
        scores[k] = (magnitude[row, col] < 2 * SEARCH_STEP / 3).mean(axis=1)
    best = np.argsort(scores, axis=None)[::-1][:8]
    candidates = []
    for flat in best:
        k, i = np.unravel_index(flat, scores.shape)
        guess = np.array([*centres[i], 2 * math.pi * k / SEARCH_YAWS])
        candidates.append(match_scan(scan_map, points, guess, reach=SEARCH_STEP))
    candidates.sort(key=lambda m: -m.fraction)
    winner = candidates[0]
    if winner.fraction < CLEAR_FIT:
        return None
    for other in candidates[1:]:
        apart = np.hypot(*(other.pose[:2] - winner.pose[:2])) > 0.3 or abs(
            math.remainder(float(other.pose[2] - winner.pose[2]), 2 * math.pi)
        ) > math.radians(15)
        if apart and other.fraction > winner.fraction - 0.1:
            return None  # two places fit: do not guess
    return winner
