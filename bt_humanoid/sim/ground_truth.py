"""The simulator's answer key: object poses, contacts, what rests on what.

Only tests, evaluation, success conditions and fault injection may use this;
skills and planners read the robot's WorldModel instead.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from bt_humanoid.sim.geometry import geoms_touching, object_extents, rotation_of
from bt_humanoid.sim.people import person_hand
from bt_humanoid.sim.simulation import Simulation

UPRIGHT_TOLERANCE_DEG = 15.0
RESTING_SPEED = 0.05  # m/s


class GroundTruth:
    def __init__(self, sim: Simulation) -> None:
        self.sim = sim
        self.model, self.data = sim.model, sim.data
        self.robot_bodies = sim.robot_bodies

    def _object_body(self, name: str) -> int:
        return self.model.body(self.sim.object_bodies[name]).id

    def object_position(self, name: str) -> np.ndarray:
        return self.data.xpos[self._object_body(name)].copy()

    def object_centre(self, name: str) -> np.ndarray:
        """Centre of an object's bounding box (caps and handles included in height), world frame."""
        body = self._object_body(name)
        low, high = object_extents(self.model, body)
        return self.data.xpos[body] + rotation_of(self.data.xquat[body]) @ ((low + high) / 2)

    def object_speed(self, name: str) -> float:
        body = self._object_body(name)
        velocity = np.zeros(6)
        mujoco.mj_objectVelocity(self.model, self.data, mujoco.mjtObj.mjOBJ_BODY, body, velocity, 0)
        return float(np.linalg.norm(velocity[3:]))

    def person_position(self, name: str) -> np.ndarray:
        """Where a person of world.yaml (or a walker) is now."""
        people = self.sim.world.people
        body = people[name].body if name in people else name
        return self.data.xpos[self.model.body(body).id].copy()

    def robot_pose(self) -> tuple[float, float, float]:
        """(x, y, yaw in radians) of the base (a legged robot's: its pelvis)."""
        if self.sim.robot.base.floating:
            position, rotation, _, _ = self.floating_base()
            return float(position[0]), float(position[1]), math.atan2(rotation[1, 0], rotation[0, 0])
        joints = self.sim.robot.base.joints
        qpos = self.data.qpos
        return tuple(float(qpos[self.model.joint(joints[a]).qposadr[0]]) for a in ("x", "y", "yaw"))  # type: ignore[return-value]

    def floating_base(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """A legged robot's pelvis: position, rotation (3 × 3), linear and angular velocity, all world frame."""
        joint = self.model.joint(self.sim.robot.base.root_joint)
        q = self.data.qpos[joint.qposadr[0] : joint.qposadr[0] + 7]
        v = self.data.qvel[joint.dofadr[0] : joint.dofadr[0] + 6]
        rotation = rotation_of(q[3:7])
        return q[:3].copy(), rotation, v[:3].copy(), rotation @ v[3:6]  # MuJoCo's free joint: ω in the body frame

    def bodies_in_contact(self, body: int) -> set[int]:
        """Bodies touching ``body`` now."""
        touching = set()
        for contact in self.data.contact[: self.data.ncon]:
            b1, b2 = self.model.geom_bodyid[contact.geom1], self.model.geom_bodyid[contact.geom2]
            if b1 == body:
                touching.add(int(b2))
            elif b2 == body:
                touching.add(int(b1))
        return touching

    def geoms_in_contact(self, body: int) -> set[int]:
        return geoms_touching(self.model, self.data, body)

    def rests_on(self, obj: str, surface: str) -> bool:
        """The object touches the surface's top geom, lies above it and is (nearly) still."""
        geom = self.model.geom(self.sim.world.surfaces[surface].geom).id
        if geom not in self.geoms_in_contact(self._object_body(obj)):
            return False
        top = self.data.geom_xpos[geom][2] + self.model.geom_size[geom][2]
        return bool(self.object_position(obj)[2] > top and self.object_speed(obj) < RESTING_SPEED)

    def on_floor(self, obj: str) -> bool:
        """The object touches the floor (the world's geom named "floor") and no hand holds it: dropped, not put
        down, handed over or binned."""
        if self.in_hand(obj) is not None or self.held_by_person(obj) is not None:
            return False
        floor = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_GEOM, "floor")
        return floor >= 0 and floor in self.geoms_in_contact(self._object_body(obj))

    def inside(self, obj: str, container: str) -> bool:
        """The object's centre lies within the container's opening (in plan) and below the top of its walls."""
        bin_ = self.sim.world.containers[container]
        (x0, y0), (x1, y1) = bin_.opening
        x, y, z = self.object_centre(obj)
        return bool(x0 <= x <= x1 and y0 <= y <= y1 and z < bin_.height)

    def upright(self, obj: str) -> bool:
        z_axis = self.data.xmat[self._object_body(obj)].reshape(3, 3)[:, 2]
        return bool(math.degrees(math.acos(np.clip(z_axis[2], -1, 1))) < UPRIGHT_TOLERANCE_DEG)

    def held_by_person(self, obj: str) -> str | None:
        """The person (world.yaml's name) whose two fingertips are both on the object, else None."""
        body = self._object_body(obj)
        return next((name for name, person in self.sim.people.items() if person.holding(body)), None)

    def in_hand(self, obj: str) -> str | None:
        """The side whose two finger pads both touch the object, else None."""
        touching = self.geoms_in_contact(self._object_body(obj))
        for side in ("left", "right"):
            if set(self.pad_geoms(side)) <= touching:
                return side
        return None

    def pad_geoms(self, side: str) -> tuple[int, int]:
        """The geoms of a hand's two finger pads (``l_pad_a``, ``l_pad_b``; ``r_`` on the right)."""
        prefix = side[0]
        return self.model.geom(f"{prefix}_pad_a").id, self.model.geom(f"{prefix}_pad_b").id

    def gripper_width(self, side: str) -> float:
        joints = self.sim.robot.grippers[side].joints
        return float(sum(self.data.qpos[self.model.joint(j).qposadr[0]] for j in joints))

    def people_bodies(self) -> set[int]:
        """Bodies of the world's people (their arms too) and walkers."""
        names = [p.body for p in self.sim.world.people.values()] + list(self.sim.world.walkers)
        roots = {self.model.body(name).id for name in names}
        return {b for b in range(self.model.nbody) if self.model.body_rootid[b] in roots}

    def hand_geoms(self) -> np.ndarray:
        """Per geom: is it on a hand, the robot's (below a gripper's wrist) or a person's (``sim/people.py``)? A
        hand-over brings the two together, and their touching is part of it, not a collision."""
        hands = {self.model.site(g.grip_site).bodyid[0] for g in self.sim.robot.grippers.values()}
        robot = {b for b in range(self.model.nbody) if self._below(b, hands)}
        people = {self.model.body(name).id for p in self.sim.world.people.values() for name in person_hand(p.body)}
        return np.isin(self.model.geom_bodyid, sorted(robot | people))

    def _below(self, body: int, ancestors: set[int]) -> bool:
        while body > 0:
            if body in ancestors:
                return True
            body = int(self.model.body_parentid[body])
        return False

    def robot_contacts(self) -> list[tuple[str, str]]:
        """Contacts between the robot and anything else, as (robot geom, other geom) names."""
        result = []
        for contact in self.data.contact[: self.data.ncon]:
            g1, g2 = contact.geom1, contact.geom2
            in1 = self.model.geom_bodyid[g1] in self.robot_bodies
            in2 = self.model.geom_bodyid[g2] in self.robot_bodies
            if in1 != in2:
                robot_geom, other = (g1, g2) if in1 else (g2, g1)
                result.append((self.model.geom(robot_geom).name, self.model.geom(other).name))
        return result
