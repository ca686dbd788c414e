"""Walking: footsteps, the DCM plan through them, the swinging foot, all on the standing controller's QP.

A gait of fixed timing (robot.yaml ``legs.gait``, docs/walking.md): single support, one foot swinging; double
support, the weight passing from one foot to the other. On each new phase the controller plans the
next footsteps for its velocity command (``FootstepPlanner``), and through them a ZMP reference and the DCM that
goes with it (``DcmPlan``); every control step the balance law tracks that DCM (``BalanceController._track``) and
a frame task carries the swinging sole along its ``SwingTrajectory``. The soles' contacts follow the phase: both
stand in double support, the leaving foot's load ramped down to nothing by lift-off; one stands in single
support while the other transmits nothing.

A zero command stops: the foot in the air lands where it was going, and one more step brings the feet side by
side (``brake``: two steps at most), then the robot stands on the standing controller's law. A command that
comes back while it stops is taken up once it stands: the stopping plan's DCM heads for the middle of the feet,
and a walking plan begun from there asked the centre of pressure for more than a sole has (a route's stop and
go tipped the robot over).
"""

from __future__ import annotations

import math
from enum import Enum

import numpy as np
import pinocchio as pin

from bt_humanoid.control.walking.balance import DCM_GAIN, ORIENTATION_WEIGHT, BalanceController
from bt_humanoid.control.walking.dcm_plan import DcmPlan
from bt_humanoid.control.walking.footsteps import LEFT, RIGHT, Footstep, FootstepPlanner, StepLimits
from bt_humanoid.control.walking.stepping import Sole, capture_step, cop_room
from bt_humanoid.control.walking.swing import LIFT_SHARE, SwingTrajectory
from bt_humanoid.control.wbc.contact import MIN_NORMAL_FORCE
from bt_humanoid.control.wbc.id_tasks import FrameTask
from bt_humanoid.sim.simulation import Simulation

START_SHIFT = 0.4  # s moving the weight onto the first stance foot before the first step
END_SHIFT = 0.4  # s moving it back to the middle of the feet after the last
PLANNED_STEPS = 3  # footsteps planned ahead: the DCM plan's horizon (2.1 s, e^{−ωT} ≈ 4e-4)
# 1/s: walking's DCM gain. The plan's DCM moves, and a stiff law throws the centre of pressure to the soles'
# edges at every small error (the stance foot rolled onto its edge as the other landed); the softer gain lets a
# small error decay over a step. A pushed DCM gets the standing gain (10): with 6 throughout, the error ran on
# until the swinging foot could no longer catch it (13 of 24 random 30 N·s pushes survived against 19).
WALKING_DCM_GAIN = 6.0
# m of DCM error over which the gain passes from walking's to the standing one
DISTURBED = (0.03, 0.06)
# Walking, the pelvis and torso are held upright more firmly than standing (ORIENTATION_WEIGHT, soft, for the
# hip strategy). In single support a soft torso let the swinging leg's task pitch it forward to reach a far
# footstep, 2° more every 20 ms, until the robot jack-knifed over the stance foot (24 random pushes: 13 survived
# with 0.1, 16 with 1, 17 with 5 and 20). In double support a torso held that firmly made the leaving foot roll
# onto its edge as its load went (and the robot drift 11 cm sideways in 10 s); 0.1 there let the pelvis wobble 5°.
SINGLE_SUPPORT_ORIENTATION_WEIGHT = 5.0
DOUBLE_SUPPORT_ORIENTATION_WEIGHT = 1.0
SWING_WEIGHT = 30.0
SWING_GAINS = (400.0, 40.0)  # K_p (1/s²), K_d (1/s): the swing foot follows its path within millimetres
# share of the stance sole's reach of the centre of pressure that the ankles are counted on for; a DCM error
# beyond it moves the footstep (_adjust_step)
ROOM_SHARE = 0.8
# where a footstep may go to recover from a push: further than walking's steps, as far as the legs reach
RECOVERY_LIMITS = StepLimits(forward=(-0.25, 0.35), sideways=(0.14, 0.45), yaw=(-0.1, 0.4))
# s of double support after a footstep moved to recover (gait: 0.1): while the weight passes over, the pushed
# DCM runs on, and the next foot, which may be the one that must step out, waits
RECOVERY_DOUBLE_SUPPORT = 0.03
RECOVERING = 0.02  # m a footstep moved from its plan beyond which it was a recovery step
GOAL_TOLERANCE = 0.01  # m: a body this near its goal has arrived, and steps no more
GOAL_YAW_TOLERANCE = 0.01  # rad
SET_OFF_DISTANCE = 0.03  # m and rad from a goal beyond which a standing robot sets off towards it
SET_OFF_TURN = 0.05
STILL = 1e-3  # a command below this (m/s, rad/s) is no command


class Phase(Enum):
    STANDING = "standing"
    DOUBLE = "double support"
    SINGLE = "single support"


class WalkingController(BalanceController):
    """Walks a legged robot at a commanded body velocity; stands when the command is zero.

    ``command(vx, vy, wz)``: forward and leftward speed (m/s) and turning rate (rad/s) in the body's frame, taken
    up at the next footstep. ``step()`` as ``BalanceController``: every physics step.
    """

    def __init__(self, sim: Simulation, posture: str = "home") -> None:
        super().__init__(sim, posture)
        legs = self.config.legs
        assert legs is not None
        self.gait = gait = legs.gait
        sole = self.contacts[0]
        self._sole = Sole(sole.length / 2 - sole.cop_margin, sole.width / 2 - sole.cop_margin)
        self.planner = FootstepPlanner(gait.width, gait.single_support + gait.double_support, StepLimits())
        self.swing_tasks = [
            FrameTask(contact.frame, SWING_WEIGHT, SWING_GAINS[0], SWING_GAINS[1]) for contact in self.contacts
        ]
        self._standing_tasks = list(self.tasks)
        self.velocity = np.zeros(3)
        self.phase = Phase.STANDING
        self.phase_start = 0.0
        self.phase_end = 0.0
        self.steps: list[Footstep] = []  # planned footsteps, the next (or the swinging foot's) first
        self.feet: list[Footstep] | None = None  # where each sole stands (measured when it lands)
        self.swing: SwingTrajectory | None = None
        self.plan: DcmPlan | None = None
        self.time = 0.0
        self.goal: np.ndarray | None = None  # a body pose to walk to (walk_to), instead of a velocity
        self.goal_speeds = (0.0, 0.0)
        self._nominal_step: Footstep | None = None  # the swinging foot's planned footstep, before adjustment
        self._touchdown_dcm = np.zeros(2)
        self.dcm_error = 0.0  # m between the DCM and the plan's, last computed in single support
        self.touchdowns: list[Footstep] = []  # every footstep taken, where the sole was at touchdown

    # --- the interface -------------------------------------------------------------------------------------------

    def command(self, vx: float, vy: float = 0.0, wz: float = 0.0) -> None:
        """Walk at this body velocity (m/s forward, m/s leftward, rad/s turning left) from the next footstep."""
        self.velocity = np.array([vx, vy, wz], dtype=float)
        self.goal = None

    def walk_to(self, x: float, y: float, yaw: float, max_speed: float, max_yaw_rate: float) -> None:
        """Walk until the middle of the feet stands at (x, y) facing ``yaw`` (world frame; within a centimetre
        and 0.6°), at most ``max_speed`` m/s and ``max_yaw_rate`` rad/s; then stand."""
        self.goal = np.array([x, y, yaw], dtype=float)
        self.goal_speeds = (max_speed, max_yaw_rate)

    def brake(self) -> None:
        """Stop walking: the swinging foot lands, one more step brings the feet together, and the robot stands."""
        self.velocity = np.zeros(3)
        self.goal = None

    def body(self) -> Footstep:
        """Where the feet put the body: the middle between them, facing half-way between their headings."""
        assert self.feet is not None
        left, right = self.feet
        middle = self._middle()
        return Footstep(LEFT, float(middle[0]), float(middle[1]), self._mean_yaw(left.yaw, right.yaw))

    @property
    def walking(self) -> bool:
        return self.phase is not Phase.STANDING

    # --- the control step ---------------------------------------------------------------------------------------

    def _balance(self) -> None:
        self.time = self.io.time
        if self.feet is None:
            self.feet = [self._measured(side) for side in (LEFT, RIGHT)]
        self._advance()
        if self.phase is Phase.STANDING:
            self._set_gains(DCM_GAIN, ORIENTATION_WEIGHT)
            super()._balance()
            return
        assert self.plan is not None
        _, dcm, rate = self.plan.at(self.time)
        disturbed = float(np.interp(np.linalg.norm(self.dcm() - dcm), DISTURBED, (0.0, 1.0)))
        self._set_gains(
            WALKING_DCM_GAIN + disturbed * (DCM_GAIN - WALKING_DCM_GAIN),
            SINGLE_SUPPORT_ORIENTATION_WEIGHT if self.phase is Phase.SINGLE else DOUBLE_SUPPORT_ORIENTATION_WEIGHT,
        )
        stance = [c.frame for c in self.contacts if c.active]
        floor = float(np.mean([self.dynamics.pose(frame).translation[2] for frame in stance]))
        yaw = self._heading()
        self._track(dcm, rate, floor, yaw)

    def _set_gains(self, dcm_gain: float, orientation_weight: float) -> None:
        """The balance law's DCM gain and the weight of the pelvis's and torso's upright tasks, this step."""
        self.dcm_gain = dcm_gain
        self.pelvis.weight = self.torso.weight = orientation_weight

    def _advance(self) -> None:
        """Move to the next phase when this one is over; keep the swinging foot's task on its path."""
        now = self.time
        if self.phase is Phase.STANDING:
            if self._moving(self._planning_velocity(self.body())) and not self._near_goal(self.body()):
                self._start_walking(now)
        elif self.phase is Phase.DOUBLE and now >= self.phase_end:
            if self.steps:
                self._lift(now)
            else:
                self._stand()
        elif self.phase is Phase.SINGLE and now >= self.phase_end:
            self._land(now)
        self._update_contacts(now)

    def _start_walking(self, now: float) -> None:
        assert self.feet is not None
        # the first step swings the foot on the side the robot is going (left for a left turn or sidestep)
        _, vy, wz = self._planning_velocity(self.body())
        first = LEFT if (wz > STILL or (abs(wz) <= STILL and vy > STILL)) else RIGHT
        stance = self.feet[1 - first]
        self.steps = self.planner.plan(stance, self._planning_velocity(self.planner.body(stance)), PLANNED_STEPS)
        self._double_support(now, START_SHIFT, self._middle(), start_dcm=self.dcm())

    def _double_support(
        self, now: float, duration: float, zmp_from: np.ndarray, start_dcm: np.ndarray | None = None
    ) -> None:
        """Begin a double support of ``duration`` moving the ZMP from ``zmp_from`` towards the next stance foot
        (or from where it starts the DCM at ``start_dcm``, a robot setting off)."""
        self.phase = Phase.DOUBLE
        self.phase_start, self.phase_end = now, now + duration
        self._plan_dcm(now, zmp_from, start_dcm)

    def _lift(self, now: float) -> None:
        step = self.steps[0]
        pose = self.dynamics.pose(self.contacts[step.side].frame)
        start = np.array([*pose.translation, _yaw(pose.rotation)])
        end = np.array([step.x, step.y, self._sole_height(1 - step.side), step.yaw])  # flat floor: the stance's
        self.swing = SwingTrajectory(start, end, self.gait.single_support, self.gait.step_height)
        self._nominal_step = step
        self.phase = Phase.SINGLE
        self.phase_start, self.phase_end = now, now + self.gait.single_support
        assert self.plan is not None
        self._touchdown_dcm = self.plan.at(self.phase_end)[1]  # where the plan has the DCM at touchdown

    def _land(self, now: float) -> None:
        assert self.feet is not None and self._nominal_step is not None
        step = self.steps.pop(0)
        recovering = float(np.linalg.norm(step.position - self._nominal_step.position)) > RECOVERING
        stopping = not self.steps  # the plan ended with this step: the robot is coming to a stand
        landed = self._measured(step.side)
        self.feet[step.side] = landed
        self.touchdowns.append(landed)
        self.swing = None
        velocity = self._planning_velocity(self.planner.body(landed))
        if self._moving(velocity) and not stopping:
            self.steps = self.planner.plan(landed, velocity, PLANNED_STEPS)
        elif self.planner.together(self.feet[LEFT], self.feet[RIGHT]):
            self.steps = []
        else:
            self.steps = [self.planner.closing_step(landed)]
        zmp_from = self.feet[1 - step.side].position
        if self.steps:
            self._double_support(now, RECOVERY_DOUBLE_SUPPORT if recovering else self.gait.double_support, zmp_from)
        else:
            self._double_support(now, END_SHIFT, zmp_from)

    def _stand(self) -> None:
        self.phase = Phase.STANDING
        self.plan = None
        self.steps = []

    # --- references -----------------------------------------------------------------------------------------------

    def _plan_dcm(self, now: float, zmp_from: np.ndarray, start_dcm: np.ndarray | None = None) -> None:
        """The ZMP knots from now through the planned footsteps to standing, and the DCM through them."""
        assert self.feet is not None
        times, zmps = [now], [np.asarray(zmp_from, dtype=float)]
        t = self.phase_end
        feet = list(self.feet)
        for step in self.steps:
            stance = feet[1 - step.side].position
            times += [t, t + self.gait.single_support]
            zmps += [stance, stance]
            t += self.planner.period
            feet[step.side] = step
        middle = (feet[LEFT].position + feet[RIGHT].position) / 2
        if self.steps:
            times.append(t - self.gait.double_support + END_SHIFT)
        else:
            times.append(t)
        zmps.append(middle)
        self.plan = DcmPlan(times, zmps, self.omega, start_dcm)

    def _update_contacts(self, now: float) -> None:
        """Which soles stand, how much the leaving one may still carry, and the swinging sole's target."""
        weight = self.dynamics.mass * self.dynamics.gravity
        self.tasks = list(self._standing_tasks)
        for contact in self.contacts:
            contact.active = True
            contact.min_normal_force = MIN_NORMAL_FORCE
            contact.max_normal_force = np.inf
        if self.phase is Phase.DOUBLE and self.steps:
            leaving = self.contacts[self.steps[0].side]
            share = (now - self.phase_start) / max(self.phase_end - self.phase_start, 1e-9)
            for contact in self.contacts:
                contact.min_normal_force = 0.0
            leaving.max_normal_force = max(weight * (1.0 - share), 0.0)
        elif self.phase is Phase.SINGLE:
            assert self.swing is not None
            self._adjust_step(now)
            side = self.steps[0].side
            self.contacts[side].active = False
            task = self.swing_tasks[side]
            pose, velocity, acceleration = self.swing.at(now - self.phase_start)
            target = pin.SE3(pin.rpy.rpyToMatrix(0.0, 0.0, pose[3]), pose[:3])
            task.set_target(
                target,
                np.array([*velocity[:3], 0.0, 0.0, velocity[3]]),
                np.array([*acceleration[:3], 0.0, 0.0, acceleration[3]]),
            )
            self.tasks.append(task)

    def _adjust_step(self, now: float) -> None:
        """Move the swinging foot's footstep, and land it sooner, where it captures the DCM (``capture_step``);
        once the foot is coming down, nothing changes."""
        elapsed, remaining = now - self.phase_start, self.phase_end - now
        single = self.gait.single_support
        if self.plan is None or self.feet is None or remaining < LIFT_SHARE * single:
            return
        nominal = self._nominal_step
        assert self.swing is not None and nominal is not None
        stance = self.feet[1 - nominal.side]
        dcm, dcm_reference = self.dcm(), self.plan.at(now)[1]
        error = dcm - dcm_reference
        self.dcm_error = float(np.linalg.norm(error))
        room = cop_room(stance, error / max(self.dcm_error, 1e-9), self._sole, ROOM_SHARE)
        shortest = max(self.gait.shortest_swing - elapsed, LIFT_SHARE * single)
        adjusted = capture_step(
            nominal,
            stance,
            dcm,
            dcm_reference,
            self._touchdown_dcm,
            self.omega,
            remaining,
            shortest,
            room,
            RECOVERY_LIMITS,
        )
        if adjusted is None:
            return
        target, duration = adjusted
        if target != self.steps[0] or duration < remaining - 1e-9:
            self.steps[0] = target
            self.phase_end = now + duration
            self.swing.retarget(elapsed, np.array([target.x, target.y, target.yaw]), elapsed + duration)

    def _planning_velocity(self, body: Footstep) -> np.ndarray:
        """The body velocity the next footsteps are planned for, from a body at ``body``: the command, or what
        takes the body to the goal. Towards a goal one step moves the body forward by v T and a pair of steps
        sideways and round by 2 v T (``FootstepPlanner``), so the velocity that lands on the goal is the
        distance over one period forward and over two sideways and round; it is scaled as a whole to what the
        legs can do (``capabilities``), so the body goes straight to the goal, turning as it goes, as a wheeled
        base does."""
        if self.goal is None:
            return self.velocity
        dx, dy, dyaw = Footstep(LEFT, *self.goal).relative_to(body)
        if abs(dx) < GOAL_TOLERANCE and abs(dy) < GOAL_TOLERANCE and abs(dyaw) < GOAL_YAW_TOLERANCE:
            return np.zeros(3)
        period = self.planner.period
        velocity = np.array([dx / period, dy / (2 * period), dyaw / (2 * period)])
        forward, backward, sideways, turning = self.capabilities()
        caps = np.array([forward if dx >= 0 else backward, sideways, turning])
        caps[0] = min(caps[0], self.goal_speeds[0])
        caps[2] = min(caps[2], self.goal_speeds[1])
        scale = min(1.0, float(np.min(caps / np.maximum(np.abs(velocity), 1e-9))))
        return velocity * scale

    def capabilities(self) -> tuple[float, float, float, float]:
        """The fastest the footsteps can carry the body: forward, backward, sideways (m/s) and turning (rad/s)."""
        limits, period = self.planner.limits, self.planner.period
        return (
            limits.forward[1] / period,
            -limits.forward[0] / period,
            (limits.sideways[1] - self.planner.width) / (2 * period),
            limits.yaw[1] / (2 * period),
        )

    def _near_goal(self, body: Footstep) -> bool:
        """Standing this near a goal, the robot does not set off: the goal's small shifts (the arms moving the
        pelvis over the feet) are not worth a step. Once walking, it steps to within ``GOAL_TOLERANCE``."""
        if self.goal is None:
            return False
        dx, dy, dyaw = Footstep(LEFT, *self.goal).relative_to(body)
        return math.hypot(dx, dy) < SET_OFF_DISTANCE and abs(dyaw) < SET_OFF_TURN

    @staticmethod
    def _moving(velocity: np.ndarray) -> bool:
        return bool(np.any(np.abs(velocity) > STILL))

    @staticmethod
    def _mean_yaw(a: float, b: float) -> float:
        return b + math.remainder(a - b, 2 * math.pi) / 2

    def _heading(self) -> float:
        """The pelvis's yaw: half-way between the feet, the swinging one where its path has it now."""
        assert self.feet is not None
        yaws = [self.feet[LEFT].yaw, self.feet[RIGHT].yaw]
        if self.phase is Phase.SINGLE and self.swing is not None:
            side = self.steps[0].side
            yaws[side] = float(self.swing.at(self.time - self.phase_start)[0][3])
        return self._mean_yaw(yaws[LEFT], yaws[RIGHT])

    def _middle(self) -> np.ndarray:
        assert self.feet is not None
        return (self.feet[LEFT].position + self.feet[RIGHT].position) / 2

    def _measured(self, side: int) -> Footstep:
        pose = self.dynamics.pose(self.contacts[side].frame)
        return Footstep(side, float(pose.translation[0]), float(pose.translation[1]), _yaw(pose.rotation))

    def _sole_height(self, side: int) -> float:
        return float(self.dynamics.pose(self.contacts[side].frame).translation[2])


def _yaw(rotation: np.ndarray) -> float:
    return math.atan2(rotation[1, 0], rotation[0, 0])
