"""A 3-D recording of a run for Rerun's viewer (``bt-run … --rerun FILE.rrd``), on the simulation clock.

What is logged, and when (the timeline ``sim_time``; entity paths in docs/rerun.md):

- ``world/bodies/…``: every visible MuJoCo geom once; the moving bodies' poses at ``pose_rate``
  (viz/rerun_scene.py);
- ``world/head_camera``: the head camera's pose, intrinsics, RGB and depth, at each look perception takes
  (the frames it rendered anyway: nothing is rendered for the recording);
- ``world/perception/detections``: what each look detected; ``world/belief/…``: the WorldModel's objects
  and people, beside ``world/truth/objects`` (the simulator's, another colour), at ``belief_rate``;
- ``world/map/…``: the occupancy map's furniture (once) and what the camera added (when it changes);
  ``world/navigation/…``: the planned route and goal, when they change;
- ``world/hands/…``: a whole-body motion's hand target and the moving reference the hand follows;
- ``tree/status`` (a log) and ``tree/nodes/<node path>`` (a status per node as a scalar: 0 idle,
  1 running, 2 success, 3 failure), from the event log's status changes;
- ``log/said``, ``log/heard``, ``log/planned``, ``log/events``: words and milestones.

rerun-sdk is imported here only, so a run without ``--rerun`` never loads it. The per-control-step cost
is a time comparison; logging happens at the rates above, and body poses are sent in columns.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from bt_humanoid.engine.stack import RobotStack
from bt_humanoid.errors import UserError
from bt_humanoid.perception.detector import Detection
from bt_humanoid.perception.rgbd_camera import RgbdFrame
from bt_humanoid.sim.geometry import object_extents
from bt_humanoid.sim.simulation import Simulation
from bt_humanoid.viz.rerun_scene import BodyPoses, entity_part, log_geometry, xyzw

TIMELINE = "sim_time"
INSTALL_HINT = "pip install 'bt-humanoid[rerun]' (rerun-sdk)"
STATUS_CODES = {"INVALID": 0, "RUNNING": 1, "SUCCESS": 2, "FAILURE": 3}
STATUS_LEVELS = {"FAILURE": "WARN", "INVALID": "DEBUG"}
EVENT_LEVELS = {"safety": "ERROR", "timeout": "ERROR", "monitor": "WARN", "retry": "WARN", "replan": "WARN"}
BELIEF_COLOUR = (255, 140, 0)  # orange: what the robot believes
TRUTH_COLOUR = (40, 200, 80)  # green: where things are
DETECTION_COLOUR = (255, 230, 0)
ROUTE_COLOUR = (30, 144, 255)
TARGET_COLOUR = (220, 20, 60)
MAP_STATIC_COLOUR = (110, 110, 110)
MAP_SEEN_COLOUR = (200, 60, 200)
MAP_HEIGHT = 0.01  # m above the floor the map's cells are drawn
JPEG_QUALITY = 85
MAX_DEPTH_MM = 65_535
EYE_OFFSET = np.array([-2.2, -2.2, 2.6])  # m from the robot's start to where the 3-D view looks from


def import_rerun() -> Any:
    """rerun-sdk, or a UserError saying how to install it."""
    try:
        import rerun
    except ImportError:
        raise UserError("--rerun needs rerun-sdk, which is not installed", hint=INSTALL_HINT) from None
    return rerun


class RerunRecorder:
    """Records ``stack``'s runs to ``path`` until ``close()``; hooks itself to the stack's control steps, its
    event log and its perceiver's looks. A path that cannot be written is a UserError, before any physics."""

    def __init__(
        self,
        stack: RobotStack,
        path: Path,
        pose_rate: float = 20.0,
        belief_rate: float = 5.0,
        map_rate: float = 2.0,
        flush_period: float = 5.0,
    ) -> None:
        rr = import_rerun()
        path = Path(path)
        if path.suffix.lower() != ".rrd":
            raise UserError(f"--rerun {path}: a Rerun recording is a .rrd file", hint="e.g. --rerun run.rrd")
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            with path.open("wb"):
                pass  # Rerun's file sink reports a bad path only on a background thread: try it here
        except OSError as error:
            parent = path.parent
            reason = f"{parent} is not a folder" if parent.exists() and not parent.is_dir() else error.strerror
            raise UserError(f"--rerun {path}: cannot write it: {reason}") from None
        self.rr, self.stack, self.path = rr, stack, path
        self.sim = stack.sim
        self.rec = rr.RecordingStream("bt-humanoid")
        self.rec.set_log_time_enabled(False)  # the simulation clock is the timeline: no wall-clock stamps
        self.rec.set_log_tick_enabled(False)
        self.rec.save(path, default_blueprint=default_layout(stack.sim))
        self.periods = {"pose": 1.0 / pose_rate, "belief": 1.0 / belief_rate, "map": 1.0 / map_rate}
        self.periods["flush"] = flush_period
        self.due = dict.fromkeys(self.periods, -math.inf)
        self.poses = BodyPoses(self.sim)
        self._objects = self._truth_objects()
        self._grid: Any = None
        self._seen: np.ndarray | None = None
        self._route: Any = None
        self._hand_goal: Any = None
        self._pinhole_logged = False
        self._stamp()
        log_geometry(rr, self.rec, self.sim)
        self.rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
        stack.observers.append(self.on_control)
        stack.events.listeners.append(self.on_event)
        if stack.perceiver is not None:
            stack.perceiver.look_listeners.append(self.on_look)
        self.on_control()  # the first state, at the run's start

    # --- hooks ---------------------------------------------------------------------------------

    def on_control(self) -> None:
        """After a control period: log whatever is due."""
        now = self.sim.time
        if now < self.due["pose"]:
            return  # the common case: one comparison
        self._stamp()
        self._next("pose", now)
        self.poses.sample()
        self._log_hands()
        self._log_route()
        if now >= self.due["belief"]:
            self._next("belief", now)
            self._log_belief()
        if now >= self.due["map"]:
            self._next("map", now)
            self._log_map()
        if now >= self.due["flush"]:
            self._next("flush", now)
            self.poses.flush(self.rr, self.rec, TIMELINE)

    def on_look(self, frame: RgbdFrame, detections: list[Detection]) -> None:
        """A look of the head camera: the frame it rendered, and what it detected."""
        rr, rec = self.rr, self.rec
        self._stamp(frame.time)
        camera = "world/head_camera"
        if not self._pinhole_logged:
            height, width = frame.depth.shape
            pinhole = rr.Pinhole(
                focal_length=frame.focal,
                width=width,
                height=height,
                principal_point=frame.centre,
                camera_xyz=rr.ViewCoordinates.RUB,  # x right, y up, looking along -z (RgbdFrame's axes)
                image_plane_distance=0.5,
            )
            rec.log(camera, pinhole, static=True)
            self._pinhole_logged = True
        rec.log(camera, rr.Transform3D(translation=frame.position, mat3x3=frame.rotation))
        ok, jpeg = cv2.imencode(
            ".jpg", cv2.cvtColor(frame.rgb, cv2.COLOR_RGB2BGR), [cv2.IMWRITE_JPEG_QUALITY, JPEG_QUALITY]
        )
        if ok:
            rec.log(f"{camera}/rgb", rr.EncodedImage(contents=jpeg.tobytes(), media_type="image/jpeg"))
        depth = np.clip(frame.depth * 1000.0, 0, MAX_DEPTH_MM).astype(np.uint16)
        if frame.hidden is not None:
            depth[frame.hidden] = 0  # the robot's own body: no reading
        rec.log(f"{camera}/depth", rr.DepthImage(depth, meter=1000.0))
        path = "world/perception/detections"
        if not detections:
            rec.log(path, rr.Clear(recursive=False))
            return
        boxes = rr.Boxes3D(
            centers=[d.position for d in detections],
            half_sizes=[np.asarray(d.size) / 2 for d in detections],
            quaternions=[_yaw_quaternion(d.yaw) for d in detections],
            colors=DETECTION_COLOUR,
            labels=[f"{d.colour} {d.kind}" for d in detections],
        )
        rec.log(path, boxes)

    def on_event(self, event: dict[str, Any]) -> None:
        """An event of the log: a node's status, something said, a milestone."""
        rr, rec = self.rr, self.rec
        self._stamp(event["t"])
        kind = event["event"]
        if kind == "status":
            new = event["new"]
            feedback = f"  {event['feedback']}" if event.get("feedback") else ""
            rec.log(
                "tree/status", rr.TextLog(f"{new:<8} {event['node']}{feedback}", level=STATUS_LEVELS.get(new, "INFO"))
            )
            node = self.rr.escape_entity_path_part(event["node"])
            # the old status and the new one at the same moment: the plot steps instead of sloping
            rec.log(f"tree/nodes/{node}", rr.Scalars(STATUS_CODES.get(event["old"], 0)))
            rec.log(f"tree/nodes/{node}", rr.Scalars(STATUS_CODES.get(new, 0)))
        elif kind == "say":
            rec.log("log/said", rr.TextLog(event["text"]))
        else:
            details = ", ".join(f"{key}={value}" for key, value in event.items() if key not in ("t", "event"))
            rec.log("log/events", rr.TextLog(f"{kind}: {details}", level=EVENT_LEVELS.get(kind, "INFO")))

    def note(self, kind: str, text: str) -> None:
        """Something outside the event log, now: what was ``heard``, what was ``planned``."""
        self._stamp()
        self.rec.log(f"log/{kind}", self.rr.TextLog(text))

    def close(self) -> None:
        """Log the last state and finish the file."""
        self.due["pose"] = self.due["belief"] = self.due["map"] = -math.inf
        self.on_control()
        self.poses.flush(self.rr, self.rec, TIMELINE)
        stack = self.stack
        if self.on_control in stack.observers:
            stack.observers.remove(self.on_control)
        if self.on_event in stack.events.listeners:
            stack.events.listeners.remove(self.on_event)
        if stack.perceiver is not None and self.on_look in stack.perceiver.look_listeners:
            stack.perceiver.look_listeners.remove(self.on_look)
        self.rec.flush()
        self.rec.disconnect()  # closes the file sink, writing its footer

    # --- what is logged ----------------------------------------------------------------------------

    def _stamp(self, time: float | None = None) -> None:
        self.rec.set_time(TIMELINE, duration=self.sim.time if time is None else float(time))

    def _next(self, what: str, now: float) -> None:
        self.due[what] = now + self.periods[what] - 1e-9

    def _truth_objects(self) -> list[tuple[str, int, np.ndarray, np.ndarray]]:
        """(name, body, centre offset in the body, half extents) of each of the world's objects."""
        model = self.sim.model
        objects = []
        for name, body_name in self.sim.object_bodies.items():
            body = model.body(body_name).id
            try:
                low, high = object_extents(model, body)
            except ValueError:
                continue  # an object of shapes the extents do not cover: drawn by its geoms only
            objects.append((name, body, (low + high) / 2, (high - low) / 2))
        return objects

    def _log_belief(self) -> None:
        rr, rec = self.rr, self.rec
        belief = self.stack.context.world_model
        present = belief.present()
        if present:
            labels = [f"{o.name} (in {o.held_by} hand)" if o.held_by else o.name for o in present]
            boxes = rr.Boxes3D(
                centers=[o.position for o in present],
                half_sizes=[np.asarray(o.size) / 2 for o in present],
                quaternions=[_yaw_quaternion(o.yaw) for o in present],
                colors=BELIEF_COLOUR,
                labels=labels,
            )
            rec.log("world/belief/objects", boxes)
        else:
            rec.log("world/belief/objects", rr.Clear(recursive=False))
        if belief.people:
            people = list(belief.people.items())
            rec.log(
                "world/belief/people",
                rr.Points3D([p for _, p in people], colors=BELIEF_COLOUR, radii=0.08, labels=[n for n, _ in people]),
            )
        if self._objects:
            data = self.sim.data
            centres, halves, rotations, labels = [], [], [], []
            for name, body, offset, half in self._objects:
                rotation = data.xmat[body].reshape(3, 3)
                centres.append(data.xpos[body] + rotation @ offset)
                halves.append(half)
                rotations.append(xyzw(data.xquat[body]))
                labels.append(name)
            boxes = rr.Boxes3D(
                centers=centres, half_sizes=halves, quaternions=rotations, colors=TRUTH_COLOUR, labels=labels
            )
            rec.log("world/truth/objects", boxes)

    def _log_map(self) -> None:
        navigator = self.stack.navigator
        grid = navigator.grid
        rec = self.rec
        if grid is not self._grid:  # the first map, or the furniture was mapped again
            self._grid, self._seen = grid, None
            rec.log("world/map/furniture", self._cells(grid, grid.static, MAP_STATIC_COLOUR))
        if self._seen is not None and np.array_equal(grid.observed, self._seen):
            return
        self._seen = grid.observed.copy()
        rec.log("world/map/seen", self._cells(grid, grid.observed, MAP_SEEN_COLOUR))

    def _cells(self, grid: Any, occupied: np.ndarray, colour: tuple[int, int, int]) -> Any:
        rows, cols = np.nonzero(occupied)
        xy = grid.centre(rows, cols)
        points = np.column_stack([xy, np.full(len(xy), MAP_HEIGHT)])
        return self.rr.Points3D(points, colors=colour, radii=grid.resolution / 2)

    def _log_route(self) -> None:
        navigator = self.stack.navigator
        route = navigator.route if navigator.goal is not None else None
        if route is self._route:
            return
        self._route = route
        rr, rec = self.rr, self.rec
        if route is None:
            rec.log("world/navigation", rr.Clear(recursive=True))
            return
        line = np.column_stack([route.points, np.full(len(route.points), 2 * MAP_HEIGHT)])
        rec.log("world/navigation/route", rr.LineStrips3D([line], colors=ROUTE_COLOUR, radii=0.015))
        goal = navigator.goal
        rec.log(
            "world/navigation/goal", rr.Points3D([[goal[0], goal[1], 2 * MAP_HEIGHT]], colors=ROUTE_COLOUR, radii=0.05)
        )

    def _log_hands(self) -> None:
        whole_body = self.stack.robot.whole_body
        goal = whole_body.goal if whole_body is not None else None
        target = goal.target_pose if goal is not None else None
        rr, rec = self.rr, self.rec
        if target is None:
            if self._hand_goal is not None:
                rec.log("world/hands", rr.Clear(recursive=True))
                self._hand_goal = None
            return
        if goal is not self._hand_goal:
            self._hand_goal = goal
            rec.log("world/hands/target", rr.Points3D([target.translation], colors=TARGET_COLOUR, radii=0.02))
        if goal.frame_task is not None:
            reference = goal.frame_task.target.translation
            rec.log("world/hands/reference", rr.Points3D([reference], colors=TARGET_COLOUR, radii=0.01))


def default_layout(sim: Simulation) -> Any:
    """What the viewer shows on opening a recording: the world in 3-D from behind and above the robot's start,
    following it, beside the head camera, the tree's statuses over time and the log; the time panel on the
    simulation clock."""
    import rerun.blueprint as rrb

    root = sim.model.body(sim.robot_root).id
    start = sim.data.xpos[root]
    eye = rrb.EyeControls3D(
        position=start + EYE_OFFSET,
        look_target=start + np.array([0.0, 0.0, 0.5]),
        eye_up=[0.0, 0.0, 1.0],
        tracking_entity=f"world/bodies/{entity_part(sim.robot_root)}",
    )
    world = rrb.Spatial3DView(origin="world", name="world (orange: belief, green: truth)", eye_controls=eye)
    side = rrb.Vertical(
        rrb.Spatial2DView(origin="world/head_camera", name="head camera"),
        rrb.TimeSeriesView(origin="tree/nodes", name="tree: 0 idle, 1 running, 2 success, 3 failure"),
        rrb.TextLogView(origin="/", contents=["tree/status", "log/**"], name="tree and words"),
        row_shares=[2, 2, 2],
    )
    return rrb.Blueprint(
        rrb.Horizontal(world, side, column_shares=[3, 2]),
        rrb.TimePanel(timeline=TIMELINE),
        collapse_panels=True,
    )


def _yaw_quaternion(yaw: float) -> np.ndarray:
    """A rotation about z, (x, y, z, w)."""
    return np.array([0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)], dtype=np.float32)
