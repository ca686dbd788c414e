"""What the recogniser sees of one region: a square RGB-D crop around it, and its size in metres.

The same function makes the crops the network is trained on (from rendered
scenes) and the crops it judges at run time, so the two cannot drift apart.
A crop has five channels: colour (3), the region's own pixels (1, a mask) and
depth relative to the region's median (1). Scale is lost when a crop is
resized, so three numbers go with it: how tall the region stands above its
surface, how wide it is across the line of sight, and how far it is.
"""

from __future__ import annotations

import cv2
import numpy as np

from bt_humanoid.perception.detector import Region, across, extent
from bt_humanoid.perception.rgbd_camera import RgbdFrame

CROP = 40  # pixels: side of the square crop the network sees
CHANNELS = 5
FEATURES = 3
MARGIN = 1.25  # the crop's side over the region's bounding box's longer side
DEPTH_SPAN = 0.2  # m of depth either side of the region's median mapped to [-1, 1]


def region_features(region: Region, eye: np.ndarray) -> np.ndarray:
    """Height above its surface, width across the line of sight and distance from the camera (m)."""
    heights = region.points[:, 2] - region.surface.height
    xy = region.points[:, :2]
    width = extent(xy, across(xy, eye)) if len(xy) >= 2 else 0.0
    distance = float(np.linalg.norm(region.points.mean(axis=0) - eye))
    return np.array([float(heights.max()), width, distance], dtype=np.float32)


def region_crop(frame: RgbdFrame, region: Region) -> np.ndarray:
    """The (CHANNELS, CROP, CROP) float32 crop centred on the region."""
    r0, r1 = int(region.rows.min()), int(region.rows.max()) + 1
    c0, c1 = int(region.cols.min()), int(region.cols.max()) + 1
    side = int(max(r1 - r0, c1 - c0) * MARGIN) + 4
    top, left = (r0 + r1 - side) // 2, (c0 + c1 - side) // 2
    rgb = _window(frame.rgb, top, left, side).astype(np.float32) / 255.0
    mask = np.zeros((side, side), dtype=np.float32)  # the window holds the whole region: it is centred, and wider
    mask[region.rows - top, region.cols - left] = 1.0
    median = float(np.median(frame.depth[region.rows, region.cols]))
    depth = np.clip((_window(frame.depth, top, left, side, fill=median) - median) / DEPTH_SPAN, -1.0, 1.0)
    extra = np.stack([mask, depth.astype(np.float32)], axis=2)
    size = (CROP, CROP)
    resized = np.concatenate(  # OpenCV resizes at most four channels at once
        [cv2.resize(rgb, size, interpolation=cv2.INTER_AREA), cv2.resize(extra, size, interpolation=cv2.INTER_AREA)],
        axis=2,
    )
    return np.ascontiguousarray(resized.transpose(2, 0, 1))


def _window(image: np.ndarray, top: int, left: int, side: int, fill: float = 0.0) -> np.ndarray:
    """``image[top:top+side, left:left+side]``, ``fill`` beyond the image's edges."""
    height, width = image.shape[:2]
    window = np.full((side, side, *image.shape[2:]), fill, dtype=image.dtype)
    rt, rb = max(top, 0), min(top + side, height)
    cl, cr = max(left, 0), min(left + side, width)
    if rt < rb and cl < cr:
        window[rt - top : rb - top, cl - left : cr - left] = image[rt:rb, cl:cr]
    return window
