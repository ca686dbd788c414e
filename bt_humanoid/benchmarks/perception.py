"""Perception benchmark: object detection from the head RGB-D camera over randomized scenes.

    python -m bt_humanoid.benchmarks.perception --scenes 100

Each scene puts one to four of the apartment's objects at random spots and
yaws on the dining table (the rest wait on the counter), paints each one a
random colour, scales and turns the light, and stands the robot 0.7 to 1.3 m
from a random side of the table, looking at it. Objects hide one another
partly. One frame is rendered and the detector runs on it.

Judged against the simulator: an object counts when its centre is in the
image and more than half of it is visible (its pixels in a segmentation
render, against a render with the other objects removed). A detection
matches the nearest such object within 5 cm. Prints recall, precision,
median 3-D position error, colour and kind accuracy, and the detector's
latency per frame (rendering timed apart). Pinned to one CPU core;
``--json PATH`` also writes the figures.
"""

from __future__ import annotations

import math
import statistics
import time
from dataclasses import dataclass
from functools import cache

import mujoco
import numpy as np

from bt_humanoid.benchmarks.common import benchmark_parser, parse_benchmark_args, save_figures
from bt_humanoid.engine.stack import RobotStack
from bt_humanoid.perception.depth_filter import cleaned_depth
from bt_humanoid.perception.detector import detect
from bt_humanoid.perception.rgbd_camera import RgbdCamera, RgbdFrame
from bt_humanoid.testing.scene import place_object

PALETTE = {
    "red": (0.85, 0.1, 0.1),
    "green": (0.1, 0.65, 0.2),
    "blue": (0.1, 0.25, 0.85),
    "yellow": (0.95, 0.85, 0.1),
    "orange": (0.95, 0.5, 0.1),
    "purple": (0.55, 0.2, 0.75),
    "white": (0.95, 0.95, 0.92),
}
SURFACE = "table"
MATCH_DISTANCE = 0.05  # m between a detection and the object it found
VISIBLE = 0.5  # fraction of an object that must be visible for it to count
RANGE = 3.0  # m from the camera within which an object counts (the counter is farther from every view)
SPACING = 0.12  # m between objects' centres
PARKING = [(8.45, 1.45), (8.45, 1.75), (8.45, 3.25), (8.45, 3.55), (8.45, 2.5)]


@dataclass
class Truth:
    name: str
    kind: str
    colour: str
    centre: np.ndarray
    visible: float
    in_image: bool


@cache
def _probe() -> RobotStack:
    """The bare apartment: its surfaces and objects, for drawing scenes."""
    stack = RobotStack.load("apartment", "wheeled_humanoid")
    stack.close()
    return stack


def build_scene(rng: np.random.Generator, seed: int = 0):
    """A robot stack set up as one random scene, and the colour each object on the table was painted; ``seed`` is
    the stack's (its sensors' noise), apart from ``rng``'s draw of the scene."""
    probe = _probe()
    table = probe.context.world_model.surface(SURFACE)
    names = list(probe.sim.object_bodies)  # the objects of the run: the world's, or its scene's
    chosen = list(rng.choice(names, size=int(rng.integers(1, 5)), replace=False))
    (x0, y0), (x1, y1) = table.region
    centre = np.array([(x0 + x1) / 2, (y0 + y1) / 2])
    footprint = probe.robot_config.base.footprint_radius
    while True:  # a start clear of the furniture: a base put down in the storage box is pushed out of it
        side = int(rng.integers(3))  # west, south, east: the chair blocks the north
        distance = rng.uniform(0.7, 1.3)
        along = rng.uniform(-0.3, 0.3)
        if side == 0:
            start = np.array([x0 - distance, centre[1] + along])
        elif side == 1:
            start = np.array([centre[0] + along, y0 - distance])
        else:
            start = np.array([x1 + distance, centre[1] + along])
        if probe.navigator.grid.clearance_at(start[None, :])[0] > footprint:
            break
    yaw = math.atan2(*(centre - start)[::-1]) + rng.uniform(-0.25, 0.25)
    run = RobotStack.load("apartment", "wheeled_humanoid", seed, robot_start=(*start, math.degrees(yaw)))
    spots: list[np.ndarray] = []
    while len(spots) < len(chosen):
        spot = np.array([rng.uniform(x0 + 0.08, x1 - 0.08), rng.uniform(y0 + 0.08, y1 - 0.08)])
        if all(np.hypot(*(spot - other)) >= SPACING for other in spots):
            spots.append(spot)
    parking = iter(PARKING)
    colours = {}
    model = run.sim.model
    for name in names:
        if name in chosen:
            spot = spots[chosen.index(name)]
            place_object(run, name, spot[0], spot[1], float(rng.uniform(-math.pi, math.pi)))
            colour = str(rng.choice(list(PALETTE)))
            body = model.body(run.sim.object_bodies[name]).id
            for geom in range(model.body_geomadr[body], model.body_geomadr[body] + model.body_geomnum[body]):
                model.geom_rgba[geom, :3] = PALETTE[colour]
            colours[name] = colour
        else:
            place_object(run, name, *next(parking), 0.0)
    # lighting: brighter or dimmer, the sun from another angle
    scale = rng.uniform(0.6, 1.3)
    model.light_diffuse[:] *= scale
    model.vis.headlight.diffuse[:] = np.array(model.vis.headlight.diffuse) * rng.uniform(0.6, 1.3)
    tilt = rng.uniform(-0.5, 0.5, size=2)
    direction = np.array([tilt[0], tilt[1], -1.0])
    model.light_dir[:] = direction / np.linalg.norm(direction)
    _look_at(run, np.array([*centre, table.height]))
    return run, colours


def _look_at(run, point: np.ndarray) -> None:
    """Point the head at ``point`` (set-up: the initial joint state)."""
    sim = run.sim
    mujoco.mj_forward(sim.model, sim.data)
    pan, tilt = sim.head_angles_towards(point)
    for joint, value in (("head_pan", pan), ("head_tilt", float(np.clip(tilt, -0.6, 1.1)))):
        sim.set_initial_joint(joint, value)
        sim.data.ctrl[sim.actuator_for_joint(joint)] = value
    mujoco.mj_forward(sim.model, sim.data)
    for _ in range(50):  # objects settle on the table
        sim.step()


def truths(run, camera: RgbdCamera, frame: RgbdFrame, names: list[str], colours: dict[str, str]) -> list[Truth]:
    """Every object with its centre, kind, colour and visible fraction in the camera image."""
    sim = run.sim
    model, data = sim.model, sim.data
    renderer = mujoco.Renderer(model, camera.height, camera.width)
    renderer.enable_segmentation_rendering()

    def pixels() -> dict[int, int]:
        renderer.update_scene(data, camera=camera.camera)
        segmentation = renderer.render()
        geoms = segmentation[..., 0][segmentation[..., 1] == int(mujoco.mjtObj.mjOBJ_GEOM)]
        bodies = model.geom_bodyid[geoms]
        return dict(zip(*np.unique(bodies, return_counts=True), strict=True))

    seen = pixels()
    result = []
    bodies = {name: model.body(body).id for name, body in run.sim.object_bodies.items()}
    for name in names:
        body = bodies[name]
        heights = {other: float(data.qpos[model.jnt_qposadr[model.body_jntadr[b]] + 2]) for other, b in bodies.items()}
        for other, b in bodies.items():  # alone in the scene: how big it would look unhidden
            if other != name:
                data.qpos[model.jnt_qposadr[model.body_jntadr[b]] + 2] = -10.0
        mujoco.mj_forward(model, data)
        alone = pixels().get(body, 0)
        for other, b in bodies.items():
            data.qpos[model.jnt_qposadr[model.body_jntadr[b]] + 2] = heights[other]
        mujoco.mj_forward(model, data)
        centre = run.truth.object_centre(name)
        declared = run.context.world.objects[run.sim.object_kinds[name]]
        result.append(
            Truth(
                name,
                declared.kind,
                colours.get(name, declared.colour),
                centre,
                min(seen.get(body, 0) / alone, 1.0) if alone else 0.0,
                frame.in_image(centre),
            )
        )
    renderer.close()
    return result


def main(argv: list[str] | None = None) -> int:
    parser = benchmark_parser(__doc__, "scenes", 100, "random scenes")
    args = parse_benchmark_args(parser, argv, "scenes")
    rng = np.random.default_rng(args.seed)
    print(f"bt-humanoid perception benchmark: {args.scenes} scenes, seed {args.seed} (one core)")
    started = time.perf_counter()
    eligible = matched = detections_total = false_positives = 0
    errors: list[float] = []
    kind_ok = colour_ok = 0
    detect_ms: list[float] = []
    render_ms: list[float] = []
    misses: list[str] = []
    for index in range(args.scenes):
        run, colours = build_scene(rng, seed=args.seed * 1_000_000 + index)
        camera = RgbdCamera(run.sim, "head_camera", 320, 240)
        camera.capture()  # the first frame of a renderer compiles its shaders
        t0 = time.perf_counter()
        frame = camera.capture()
        t1 = time.perf_counter()
        frame.depth = cleaned_depth(frame.depth)  # as the robot's perceiver does
        found = detect(frame, list(run.context.world_model.surfaces.values()))
        t2 = time.perf_counter()
        render_ms.append((t1 - t0) * 1000)
        detect_ms.append((t2 - t1) * 1000)
        objects = truths(run, camera, frame, list(run.sim.object_bodies), colours)
        camera.close()
        run.close()
        eye = frame.position
        counted = [t for t in objects if t.in_image and t.visible > VISIBLE and np.linalg.norm(t.centre - eye) < RANGE]
        eligible += len(counted)
        detections_total += len(found)
        taken: set[int] = set()
        for detection in found:
            distances = [float(np.linalg.norm(detection.position - t.centre)) for t in objects]
            best = int(np.argmin(distances)) if distances else -1
            if best < 0 or distances[best] > MATCH_DISTANCE or best in taken:
                false_positives += 1
                misses.append(
                    f"scene {index}: {detection.colour} {detection.kind} at {np.round(detection.position, 2)}"
                )
                continue
            taken.add(best)
            truth = objects[best]
            if truth in counted:
                matched += 1
                errors.append(distances[best])
                kind_ok += detection.kind == truth.kind
                colour_ok += detection.colour == truth.colour
                if detection.kind != truth.kind or detection.colour != truth.colour:
                    misses.append(
                        f"scene {index}: {truth.colour} {truth.kind} seen as {detection.colour} {detection.kind}"
                    )
        for number, truth in enumerate(objects):
            if truth in counted and number not in taken:
                misses.append(f"scene {index}: missed the {truth.colour} {truth.kind} ({truth.visible:.0%} visible)")
        print(
            f"  scene {index + 1}/{args.scenes}: {len(counted)} objects to find, {len(found)} detections, "
            f"render {render_ms[-1]:.0f} ms, detect {detect_ms[-1]:.0f} ms",
            flush=True,
        )
    figures = {
        "scenes": args.scenes,
        "objects_to_find": eligible,
        "recall": matched / eligible if eligible else None,
        "precision": (detections_total - false_positives) / detections_total if detections_total else None,
        "median_position_error_cm": statistics.median(errors) * 100 if errors else None,
        "kind_accuracy": kind_ok / matched if matched else None,
        "colour_accuracy": colour_ok / matched if matched else None,
        "detect_median_ms": statistics.median(detect_ms),
        "render_median_ms": statistics.median(render_ms),
        "misses": misses,
        "wall_s": round(time.perf_counter() - started, 1),
    }
    print()
    print(f"  objects to find (in view, over half visible): {eligible}")
    print(f"  recall {figures['recall']:.1%} (≥ 98 %), precision {figures['precision']:.1%} (≥ 98 %)")
    print(f"  median 3-D position error {figures['median_position_error_cm']:.2f} cm (≤ 1 cm)")
    print(f"  kind {figures['kind_accuracy']:.1%}, colour {figures['colour_accuracy']:.1%} correct (≥ 98 %)")
    print(
        f"  detector latency per 320×240 frame: median {figures['detect_median_ms']:.1f} ms (≤ 30 ms); "
        f"rendering the frame: median {figures['render_median_ms']:.1f} ms"
    )
    for miss in misses[:15]:
        print(f"    {miss}")
    save_figures(args.json, figures)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
