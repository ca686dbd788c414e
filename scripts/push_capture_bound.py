"""The largest sideways push a point-mass biped could capture by stepping, with the biped's legs (no physics).

A bound for docs/walking.md ("The fetch suite's shove"), not a controller: the linear inverted pendulum at the
biped's centre-of-mass height, pushed sideways with a constant force for ``--push-time`` s, steps as well as the
legs allow. At the best moment, the outer foot (on the push's side) lifts as the push begins. It lands after the
shortest swing as far out as the DCM needs, up to the recovery steps' reach. The inner foot then lands beside it,
``narrowest`` inside: the feet do not cross. The outer foot steps out again, and so on. The centre of pressure
is always as far towards the DCM as the standing soles let it go. Captured: the push is over and the DCM stands
over a sole.

    python scripts/push_capture_bound.py                    # the biped's figures: about 51 N·s
    python scripts/push_capture_bound.py --reach 0.6        # what longer legs would take
"""

from __future__ import annotations

import argparse
import math

from bt_humanoid.control.walking.walker import RECOVERY_DOUBLE_SUPPORT, RECOVERY_LIMITS
from bt_humanoid.sim.robot_config import load_robot_config

GRAVITY = 9.81
TIME_STEP = 1e-4  # s: the pendulum's integration step
GIVE_UP = 2.0  # m of DCM beyond the standing foot: it will not come back


def captured(impulse: float, args: argparse.Namespace) -> bool:
    """Whether a sideways push of ``impulse`` N·s over ``args.push_time`` s is captured (see the module's text)."""
    omega = math.sqrt(GRAVITY / args.com_height)
    force = impulse / args.push_time
    half_width = args.sole_width / 2
    stance, landed = 0.0, 0.0  # y of the standing foot and of the one that landed last (outwards is +y)
    dcm = half_width  # at the standing sole's outer edge: its most favourable start that the sole still holds
    phase, in_phase, outer_swinging = "single", 0.0, True
    t = 0.0
    while t < 10.0:
        pushing = t < args.push_time
        if phase == "single":
            low, high = stance - half_width, stance + half_width
            if not pushing and low <= dcm <= high:
                return True
            if in_phase >= args.shortest_swing:
                if outer_swinging:
                    landed = min(max(dcm, stance + args.narrowest), stance + args.reach)
                else:
                    landed = stance - args.narrowest
                phase, in_phase = "double", 0.0
                continue
        else:
            low = min(stance, landed) - half_width
            high = max(stance, landed) + half_width
            if in_phase >= args.double_support:
                stance, outer_swinging = landed, not outer_swinging
                phase, in_phase = "single", 0.0
                continue
        centre_of_pressure = min(max(dcm, low), high)
        pushed = force / (args.mass * omega) if pushing else 0.0
        dcm += TIME_STEP * (omega * (dcm - centre_of_pressure) + pushed)
        t += TIME_STEP
        in_phase += TIME_STEP
        if dcm - stance > GIVE_UP:
            return False
    return False


def main(argv: list[str] | None = None) -> int:
    legs = load_robot_config("biped_humanoid").legs
    assert legs is not None
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--push-time", type=float, default=0.3, help="s the push lasts (default 0.3: the fetch suite's)"
    )
    parser.add_argument("--mass", type=float, default=48.3, help="kg (default 48.3: the biped's)")
    parser.add_argument(
        "--com-height", type=float, default=0.712, help="m above the soles (default 0.712: the walker's, ω = 3.71)"
    )
    parser.add_argument(
        "--reach", type=float, default=RECOVERY_LIMITS.sideways[1], help="m a recovery step reaches out"
    )
    parser.add_argument("--narrowest", type=float, default=RECOVERY_LIMITS.sideways[0], help="m between soles, least")
    parser.add_argument("--shortest-swing", type=float, default=legs.gait.shortest_swing, help="s in the air, least")
    parser.add_argument("--double-support", type=float, default=RECOVERY_DOUBLE_SUPPORT, help="s after a step")
    parser.add_argument("--sole-width", type=float, default=legs.sole.width, help="m")
    args = parser.parse_args(argv)
    low, high = 0.0, 300.0
    while high - low > 0.25:
        middle = (low + high) / 2
        low, high = (middle, high) if captured(middle, args) else (low, middle)
    print(
        f"a {args.push_time:g} s sideways push of up to {low:.1f} N·s is captured at the best moment "
        f"(ω {math.sqrt(GRAVITY / args.com_height):.2f} s⁻¹, reach {args.reach:g} m, swing {args.shortest_swing:g} s)"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
