"""Kitchen perception benchmark: the learned detector on random kitchen views it was not trained on.

    python -m bt_humanoid.benchmarks.kitchen_perception --scenes 200

Each scene is a random view (``bt_humanoid/training/views.py``) from the
benchmark's own seed stream (training and validation use two others): three
to eight of the sixteen objects on one surface, sometimes a few on another,
and up to two pieces of clutter (plain shapes in random sizes and colours,
none of the sixteen), partly hiding one another; the robot 0.4 to 1.7 m from the surface, looking at
it; the light scaled and turned. The detector runs on the rendered frame, as
in a run (the robot's own body masked out).

Judged against the simulator: an object counts when its centre is in the
image, it is within 3 m and more than half of it is visible (its pixels,
against a render of it alone). A detection matches the nearest object within
5 cm; a detection of clutter is a false one. Prints recall, precision, identity accuracy (which of the sixteen),
median 3-D position error and the detector's time per frame on one core,
split into the network (crops and inference) and geometry (segmentation and
poses). ``--json PATH`` also writes the figures.
"""

from __future__ import annotations

import statistics
import time
from pathlib import Path

import mujoco
import numpy as np
import torch

from bt_humanoid.benchmarks.common import benchmark_parser, parse_benchmark_args, save_figures
from bt_humanoid.perception.learned_detector import LearnedDetector
from bt_humanoid.sim.ground_truth import GroundTruth
from bt_humanoid.training.detector import BENCHMARK_STREAM, view_rng
from bt_humanoid.training.views import ViewMaker

MATCH_DISTANCE = 0.05  # m between a detection and the object it found
VISIBLE = 0.5  # fraction of an object that must be visible for it to count
RANGE = 3.0  # m from the camera


def visible_shares(maker: ViewMaker, used: list[int]) -> dict[int, float]:
    """Each placed instance's visible pixels over its pixels when alone in the view."""
    data = maker.sim.data
    _, shown = maker.capture()
    together = {i: int(np.count_nonzero(shown == i)) for i in used}
    shares = {}
    saved = data.qpos.copy()
    for index in used:
        for other in used:
            if other != index:
                address = maker.instances[other].qpos
                data.qpos[address : address + 3] = (0.5 * other, 0.0, 60.0)
        mujoco.mj_forward(maker.sim.model, data)
        _, alone = maker.capture()
        pixels = int(np.count_nonzero(alone == index))
        shares[index] = together[index] / pixels if pixels else 0.0
        data.qpos[:] = saved
    mujoco.mj_forward(maker.sim.model, data)
    return shares


def main(argv: list[str] | None = None) -> int:
    parser = benchmark_parser(__doc__, "scenes", 200, "random kitchen views")
    parser.add_argument("--detector", type=Path, help="a trained detector's folder (default: the kitchen's own)")
    args = parse_benchmark_args(parser, argv, "scenes")
    torch.set_num_threads(1)
    maker = ViewMaker("kitchen")
    detector = LearnedDetector.for_world(maker.sim.world, args.detector)
    truth = GroundTruth(maker.sim)
    names = list(maker.sim.object_bodies)  # in the order of maker.instances
    print(f"bt-humanoid kitchen perception benchmark: {args.scenes} views, seed {args.seed} (one core)")
    started = time.perf_counter()
    eligible = matched = detections_total = false_positives = identity_ok = 0
    errors: list[float] = []
    network_ms: list[float] = []
    geometry_ms: list[float] = []
    misses: list[str] = []
    confusions: dict[tuple[str, str], int] = {}
    for index in range(args.scenes):
        used = maker.arrange(view_rng(args.seed, BENCHMARK_STREAM, index))
        frame, _ = maker.capture()
        found = detector.detect(frame, maker.surfaces)
        network_ms.append(detector.times.network_ms)
        geometry_ms.append(detector.times.geometry_ms)
        shares = visible_shares(maker, used)
        eye = frame.position
        centres = {i: truth.object_centre(names[i]) for i in used}
        counted = {
            i
            for i in used
            if not maker.instances[i].clutter
            and shares[i] > VISIBLE
            and np.linalg.norm(centres[i] - eye) < RANGE
            and frame.in_image(centres[i])
        }
        eligible += len(counted)
        detections_total += len(found)
        taken: set[int] = set()
        for detection in found:
            distances = {i: float(np.linalg.norm(detection.position - c)) for i, c in centres.items()}
            best = min(distances, key=distances.get) if distances else None
            if best is None or distances[best] > MATCH_DISTANCE or best in taken or maker.instances[best].clutter:
                false_positives += 1
                misses.append(f"view {index}: a {detection.identity} at {np.round(detection.position, 2)} is not there")
                continue
            taken.add(best)
            if best in counted:
                matched += 1
                errors.append(distances[best])
                real = maker.instances[best].name
                if detection.identity == real:
                    identity_ok += 1
                else:
                    confusions[(real, str(detection.identity))] = confusions.get((real, str(detection.identity)), 0) + 1
                    misses.append(f"view {index}: the {real} taken for the {detection.identity}")
        for i in counted - taken:
            misses.append(f"view {index}: missed the {maker.instances[i].name} ({shares[i]:.0%} visible)")
        if (index + 1) % 20 == 0:
            print(f"  view {index + 1}/{args.scenes}: {eligible} objects to find so far", flush=True)
    maker.close()
    figures = {
        "scenes": args.scenes,
        "seed": args.seed,
        "objects_to_find": eligible,
        "recall": matched / eligible if eligible else None,
        "precision": (detections_total - false_positives) / detections_total if detections_total else None,
        "identity_accuracy": identity_ok / matched if matched else None,
        "median_position_error_cm": statistics.median(errors) * 100 if errors else None,
        "detect_median_ms": statistics.median(n + g for n, g in zip(network_ms, geometry_ms, strict=True)),
        "network_median_ms": statistics.median(network_ms),
        "geometry_median_ms": statistics.median(geometry_ms),
        "confusions": {f"{a} → {b}": n for (a, b), n in sorted(confusions.items(), key=lambda kv: -kv[1])},
        "misses": misses,
        "wall_s": round(time.perf_counter() - started, 1),
    }
    print()
    print(f"  objects to find (in view, over half visible): {eligible}")
    print(f"  recall {figures['recall']:.1%} (≥ 97 %), precision {figures['precision']:.1%} (≥ 97 %)")
    print(f"  identity (which of the sixteen) {figures['identity_accuracy']:.1%} correct (≥ 97 %)")
    print(f"  median 3-D position error {figures['median_position_error_cm']:.2f} cm (≤ 1 cm)")
    print(
        f"  detector per 320×240 frame, one core: median {figures['detect_median_ms']:.1f} ms (≤ 15 ms): "
        f"network {figures['network_median_ms']:.1f} ms, geometry {figures['geometry_median_ms']:.1f} ms"
    )
    for miss in misses[:15]:
        print(f"    {miss}")
    save_figures(args.json, figures)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
