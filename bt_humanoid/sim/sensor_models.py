"""What real sensors add to the simulator's exact readings: noise, missing returns, quantisation, exposure.

MuJoCo renders and ray-casts the scene exactly; a real robot never sees it so. Each model here takes an exact
reading and the sensor's own random stream (``Simulation.random_stream``, seeded from the run's seed, so the same
seed gives the same noise) and returns what the sensor would report. The figures are robot.yaml's ``sensors:``
(defaults below, each with where it comes from); ``--ideal-sensors`` (or ``BT_IDEAL_SENSORS=1``) turns every
model off for debugging. The base's planar joints are not encoders here: what the wheels measure is
``OdometryModel``'s, and where the base is comes from localisation (``bt_humanoid/localisation``).
"""

from __future__ import annotations

import math
import os

import numpy as np
from pydantic import Field, NonNegativeFloat, StrictBool

from bt_humanoid.strict_model import StrictModel

IDEAL_SENSORS_VARIABLE = "BT_IDEAL_SENSORS"  # set (to 1) by --ideal-sensors; worker processes inherit it


class DepthModel(StrictModel):
    """A structured-light depth camera. Axial noise after Nguyen, Izadi & Lovell, "Modeling Kinect sensor noise
    for improved 3D reconstruction and tracking" (3DIMPVT 2012): σ(z, θ) = a + b (z − c)² + d θ² / (√z (π/2 − θ)²),
    z the depth (m), θ the angle between the ray and the surface's normal. No return where the projector's
    pattern does not come back: beside a depth edge (the far side lies in the projector's shadow), on dark
    surfaces that absorb it, at grazing angles, and now and then anywhere."""

    enabled: StrictBool = True
    axial: tuple[NonNegativeFloat, NonNegativeFloat, NonNegativeFloat] = Field(
        (0.0012, 0.0019, 0.4), description="a (m), b (1/m), c (m) of σ(z)"
    )
    grazing_noise: float = Field(0.0001, ge=0, description="d (m^1.5) of σ's grazing-angle term")
    edge_jump: float = Field(0.05, gt=0, description="m between neighbouring pixels that makes a depth edge")
    edge_dropout: float = Field(0.5, ge=0, le=1, description="chance a pixel on the far side of an edge is lost")
    dark_level: float = Field(0.1, ge=0, le=1, description="mean colour (0-1) below which a surface is dark")
    dark_dropout: float = Field(0.5, ge=0, le=1, description="chance a dark pixel is lost")
    grazing_deg: float = Field(80.0, gt=0, le=90, description="viewing angle beyond which nothing returns")
    max_range: float = Field(6.0, gt=0, description="m beyond which the pattern is too faint to return")
    dropout: float = Field(0.002, ge=0, le=1, description="chance any pixel is lost")


class ColourModel(StrictModel):
    """The colour stream: per-pixel sensor noise and an auto-exposure that never settles exactly."""

    enabled: StrictBool = True
    noise: float = Field(2.0, ge=0, description="σ of the per-pixel noise, in 8-bit levels")
    exposure: float = Field(0.05, ge=0, description="σ of the frame's log brightness gain (5 %: auto-exposure)")


class RangeModel(StrictModel):
    """A time-of-flight range finder (the base's safety scanner): range noise and lost returns. σ 1.5 cm is of
    the order of a safety laser scanner's data sheet (statistical error of a few centimetres at most)."""

    enabled: StrictBool = True
    noise: float = Field(0.015, ge=0, description="σ of a range, m")
    dropout: float = Field(0.01, ge=0, le=1, description="chance a ray returns nothing")


class EncoderModel(StrictModel):
    """Joint encoders: positions come in counts (a 16-bit absolute encoder on the joint's output)."""

    enabled: StrictBool = True
    bits: int = Field(16, ge=8, le=24, description="counts per turn of a rotary joint: 2^bits")
    linear_resolution: float = Field(1e-5, gt=0, description="m per count of a sliding joint")


class ImuModel(StrictModel):
    """A MEMS IMU's white noise per reading: gyro 0.004 rad/s and accelerometer 0.03 m/s² are a consumer-grade
    part's noise densities (about 0.014 °/s/√Hz and 175 µg/√Hz) over a 250 Hz bandwidth."""

    enabled: StrictBool = True
    gyro: float = Field(0.004, ge=0, description="σ of each gyro axis, rad/s")
    accelerometer: float = Field(0.03, ge=0, description="σ of each accelerometer axis, m/s²")


class OdometryModel(StrictModel):
    """The base's odometry: what its wheels say it moved. Each run draws a scale error per axis (worn or
    squashed wheels, a wrong track width; about 2 % is what calibrated mobile bases keep to) and every increment
    has white noise that grows with the distance moved (wheels slip on the floor). Localisation corrects it;
    with it off, the base's pose is exact."""

    enabled: StrictBool = True
    scale: float = Field(0.02, ge=0, description="σ of each axis's scale error, drawn once a run (x, y, yaw)")
    noise: float = Field(0.01, ge=0, description="m σ of the position error per √m moved")
    yaw_noise: float = Field(0.02, ge=0, description="rad σ of the heading error per √rad turned")


class SensorModels(StrictModel):
    """robot.yaml's ``sensors:``: how far each of the robot's sensors is from the truth (on by default)."""

    depth: DepthModel = DepthModel()
    colour: ColourModel = ColourModel()
    scanner: RangeModel = RangeModel()
    encoders: EncoderModel = EncoderModel()
    imu: ImuModel = ImuModel()
    odometry: OdometryModel = OdometryModel()

    @classmethod
    def ideal(cls) -> SensorModels:
        """Every sensor exact: the simulator's own readings."""
        return cls(
            depth=DepthModel(enabled=False),
            colour=ColourModel(enabled=False),
            scanner=RangeModel(enabled=False),
            encoders=EncoderModel(enabled=False),
            imu=ImuModel(enabled=False),
            odometry=OdometryModel(enabled=False),
        )


def ideal_sensors_requested() -> bool:
    """Whether this process (or the one that started it) asked for exact sensors (``--ideal-sensors``)."""
    return os.environ.get(IDEAL_SENSORS_VARIABLE, "") not in ("", "0")


def request_ideal_sensors() -> None:
    """Make every robot built from now on, in this process and the workers it starts, read exact sensors."""
    os.environ[IDEAL_SENSORS_VARIABLE] = "1"


def axial_sigma(model: DepthModel, depth: np.ndarray, angle: np.ndarray | float = 0.0) -> np.ndarray:
    """σ (m) of a depth reading ``depth`` (m) at viewing angle ``angle`` (rad from the surface's normal)."""
    a, b, c = model.axial
    angle = np.minimum(angle, math.radians(89.0))
    grazing = model.grazing_noise * angle**2 / (np.sqrt(np.maximum(depth, 0.1)) * (math.pi / 2 - angle) ** 2)
    return a + b * (depth - c) ** 2 + grazing


def depth_image(
    model: DepthModel, depth: np.ndarray, rgb: np.ndarray, focal: float, rng: np.random.Generator
) -> np.ndarray:
    """A rendered depth image (H × W, m along the optical axis) as the camera reports it: noisy, 0 where lost."""
    if not model.enabled:
        return depth
    depth = depth.astype(np.float32)  # millimetres matter, not the float64's digits: half the time
    angle = _viewing_angle(depth, focal)
    noisy = depth + rng.standard_normal(depth.shape, dtype=np.float32) * axial_sigma(model, depth, angle)
    chance = rng.random((3, *depth.shape), dtype=np.float32)
    lost = chance[0] < model.dropout
    lost |= (chance[1] < model.edge_dropout) & _far_side_of_edges(depth, model.edge_jump)
    dark = rgb.sum(axis=2, dtype=np.uint16) < 3 * 255 * model.dark_level
    lost |= (chance[2] < model.dark_dropout) & dark
    lost |= (angle > math.radians(model.grazing_deg)) | (depth > model.max_range)
    noisy[lost] = 0.0
    return noisy.astype(np.float64)


def depth_ranges(model: DepthModel, ranges: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Ray-cast depth ranges (m, inf: nothing) with the camera's axial noise and random losses (inf).

    The rays are sparse, so edges and colours are not known here: only the distance term and chance losses."""
    if not model.enabled:
        return ranges
    seen = np.isfinite(ranges)
    noisy = ranges.copy()
    noisy[seen] += rng.standard_normal(int(seen.sum())) * axial_sigma(model, ranges[seen])
    noisy[(rng.random(ranges.shape) < model.dropout) | (ranges > model.max_range)] = np.inf
    return noisy


def colour_image(model: ColourModel, rgb: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """A rendered colour image (H × W × 3 uint8) with the frame's exposure and per-pixel noise."""
    if not model.enabled:
        return rgb
    gain = math.exp(rng.normal(0.0, model.exposure))
    noisy = rgb.astype(np.float32) * gain + rng.standard_normal(rgb.shape, dtype=np.float32) * model.noise
    return np.clip(np.rint(noisy), 0, 255).astype(np.uint8)


def scanner_ranges(model: RangeModel, ranges: np.ndarray, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """A scan's ranges (m) with noise, and which rays still returned (a lost ray returns nothing)."""
    if not model.enabled:
        return ranges, np.ones(ranges.shape, dtype=bool)
    returned = rng.random(ranges.shape) >= model.dropout
    return np.maximum(ranges + rng.standard_normal(ranges.shape) * model.noise, 0.0), returned


def encoder_steps(model: EncoderModel, rotary: np.ndarray) -> np.ndarray | None:
    """Per joint, the size of one encoder count (rad for ``rotary`` joints, m for sliding ones); None when ideal."""
    if not model.enabled:
        return None
    return np.where(rotary, 2 * math.pi / 2**model.bits, model.linear_resolution)


def quantise(positions: np.ndarray, steps: np.ndarray | None) -> np.ndarray:
    """Joint positions as whole encoder counts (unchanged when ``steps`` is None)."""
    if steps is None:
        return positions
    return np.rint(positions / steps) * steps


def _viewing_angle(depth: np.ndarray, focal: float) -> np.ndarray:
    """Per pixel, the angle (rad) between the pixel's ray and the surface's normal, from the depth's slope.

    With z(u, v) the depth at pixel offsets (u, v) from the centre, the surface's normal is along
    (−f ∂z/∂u, −f ∂z/∂v, z + u ∂z/∂u + v ∂z/∂v) and its dot product with the ray (u, v, f) is f z. Each way the
    slope is taken towards the neighbour nearer in depth, so a pixel at an object's rim takes the object's own
    surface, not the jump to what lies behind it."""
    height, width = depth.shape
    u = (np.arange(width, dtype=np.float32) + 0.5 - width / 2)[None, :]
    v = (np.arange(height, dtype=np.float32) + 0.5 - height / 2)[:, None]
    z = depth.astype(np.float32, copy=False)
    slope_u, slope_v = _gentler_difference(z, 1), _gentler_difference(z, 0)
    normal = np.sqrt((focal * slope_u) ** 2 + (focal * slope_v) ** 2 + (z + u * slope_u + v * slope_v) ** 2)
    cosine = focal * z / np.maximum(normal * np.sqrt(u**2 + v**2 + focal**2), 1e-12)
    return np.arccos(np.clip(cosine, 0.0, 1.0))


def _gentler_difference(depth: np.ndarray, axis: int) -> np.ndarray:
    """The depth's change to the next pixel along ``axis``, forwards or backwards, whichever is smaller."""
    step = np.diff(depth, axis=axis)
    before = np.concatenate([step.take([0], axis=axis), step], axis=axis)  # from the previous pixel (edge: reused)
    after = np.concatenate([step, step.take([-1], axis=axis)], axis=axis)  # to the next pixel
    return np.where(np.abs(before) < np.abs(after), before, after)


def _far_side_of_edges(depth: np.ndarray, jump: float) -> np.ndarray:
    """Pixels that lie more than ``jump`` behind one of their four neighbours: the projector's shadow side."""
    padded = np.pad(depth, 1, mode="edge")
    nearest = np.minimum.reduce([padded[:-2, 1:-1], padded[2:, 1:-1], padded[1:-1, :-2], padded[1:-1, 2:]])
    return depth - nearest > jump
