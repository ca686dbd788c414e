"""Fusing detections into tracked objects: how near is the same object, from near and from far."""

import numpy as np

from bt_humanoid.perception.detector import Detection
from bt_humanoid.perception.fusion import gate, integrate
from bt_humanoid.perception.rgbd_camera import RgbdFrame
from bt_humanoid.perception.world_model import WorldModel

BOTTLE = np.array([0.07, 0.07, 0.22])


def _frame(camera_x: float, time: float) -> RgbdFrame:
    """A camera on the x axis looking away from the objects (+x is behind it): nothing is judged missing."""
    depth = np.zeros((24, 32), dtype=np.float32)
    rgb = np.zeros((24, 32, 3), dtype=np.uint8)
    # camera axes in the world: x right, y up, looking along -z; here -z is world -x, away from the table at +x
    rotation = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    return RgbdFrame(rgb, depth, 30.0, (16.0, 12.0), np.array([camera_x, 0.0, 1.2]), rotation, time)


def _bottle(x: float, y: float, colour: str = "blue", kind: str = "bottle") -> Detection:
    return Detection(kind, colour, np.array([x, y, 0.86]), BOTTLE.copy(), 0.0, "table", 400)


def test_two_far_looks_at_one_bottle_some_centimetres_apart_are_one_object():
    belief = WorldModel()
    integrate(belief, [_bottle(4.0, 0.0)], _frame(0.0, 0.0))  # 4 m away
    integrate(belief, [_bottle(4.0, 0.08)], _frame(0.0, 1.0))  # 8 cm off: a far look's error
    assert list(belief.objects) == ["bottle-1"]


def test_near_looks_keep_things_a_few_centimetres_apart_apart():
    belief = WorldModel()
    integrate(belief, [_bottle(4.0, 0.0)], _frame(3.3, 0.0))  # 0.7 m away
    integrate(belief, [_bottle(4.0, 0.08)], _frame(3.3, 1.0))
    assert sorted(belief.objects) == ["bottle-1", "bottle-2"]


def test_the_gate_grows_with_the_range_of_the_look_and_of_the_track():
    belief = WorldModel()
    integrate(belief, [_bottle(4.0, 0.0)], _frame(0.0, 0.0))
    tracked = belief.objects["bottle-1"]
    assert gate(tracked, 0.6) > 0.1  # the track's own view was far
    tracked.seen_from = 0.6
    assert gate(tracked, 1.0) == gate(tracked, 0.5) == 0.06  # near looks at a near-seen track: 6 cm
    assert gate(tracked, 4.0) > gate(tracked, 1.0) + 0.05


def test_a_near_look_moves_a_far_estimate_more_than_a_far_look_moves_a_near_one():
    belief = WorldModel()
    integrate(belief, [_bottle(4.0, 0.05)], _frame(0.0, 0.0))  # from 4 m: 5 cm off
    integrate(belief, [_bottle(4.0, 0.0)], _frame(3.2, 1.0))  # from 0.8 m
    moved_by_near = 0.05 - belief.objects["bottle-1"].position[1]
    assert moved_by_near > 0.04  # the near look counts for most of it

    belief = WorldModel()
    integrate(belief, [_bottle(4.0, 0.0)], _frame(3.2, 0.0))
    integrate(belief, [_bottle(4.0, 0.05)], _frame(0.0, 1.0))
    assert belief.objects["bottle-1"].position[1] < 0.01


def test_two_bottles_seen_side_by_side_in_one_frame_are_two_even_from_afar():
    belief = WorldModel()
    integrate(belief, [_bottle(4.0, 0.0), _bottle(4.0, 0.075)], _frame(0.0, 0.0))
    integrate(belief, [_bottle(4.0, 0.0), _bottle(4.0, 0.075)], _frame(0.0, 1.0))
    assert len(belief.objects) == 2
    assert all(o.confidence > 0.5 for o in belief.objects.values())


def test_a_track_split_in_two_is_folded_into_the_older_which_plans_name():
    belief = WorldModel()
    integrate(belief, [_bottle(4.0, 0.0)], _frame(3.3, 0.0))
    integrate(belief, [_bottle(4.0, 0.08, kind="ball")], _frame(3.3, 1.0))  # near: a second track
    assert sorted(belief.objects) == ["ball-1", "bottle-1"]
    # a far look lands between them: the two are one object seen twice
    belief.objects["bottle-1"].seen_from = belief.objects["ball-1"].seen_from = 3.0
    integrate(belief, [_bottle(4.0, 0.04)], _frame(0.0, 2.0))
    assert list(belief.objects) == ["bottle-1"]
    assert belief.merged == {"ball-1": "bottle-1"}
    assert belief.object("ball-1").name == "blue bottle"  # two bottle votes to one ball


def test_things_of_two_colours_are_never_folded():
    belief = WorldModel()
    integrate(belief, [_bottle(4.0, 0.0), _bottle(4.0, 0.07, colour="red")], _frame(0.0, 0.0))
    integrate(belief, [_bottle(4.0, 0.0)], _frame(0.0, 1.0))
    assert len(belief.objects) == 2


def test_things_told_apart_by_look_are_never_folded():
    belief = WorldModel()
    coke, cherry = _bottle(4.0, 0.0, colour="red", kind="can"), _bottle(4.0, 0.07, colour="red", kind="can")
    coke.identity, cherry.identity = "coke", "cherry coke"
    integrate(belief, [coke], _frame(3.3, 0.0))
    integrate(belief, [cherry], _frame(3.3, 1.0))
    belief.objects["can-1"].seen_from = belief.objects["can-2"].seen_from = 3.0
    integrate(belief, [coke], _frame(0.0, 2.0))
    assert len(belief.objects) == 2


def test_two_things_once_seen_side_by_side_stay_two_when_one_hides_the_other():
    belief = WorldModel()
    integrate(belief, [_bottle(4.0, 0.0), _bottle(4.0, 0.075)], _frame(0.0, 0.0))  # both, from 4 m
    integrate(belief, [_bottle(4.0, 0.07)], _frame(0.0, 1.0))  # now one is behind the other: one shows
    assert len(belief.objects) == 2
    integrate(belief, [], _frame(0.0, 2.0))  # out of view: nothing new to fold on
    assert len(belief.objects) == 2


def test_a_thing_of_another_colour_beside_it_is_not_the_far_object():
    belief = WorldModel()
    integrate(belief, [_bottle(5.0, 0.0)], _frame(0.0, 0.0))  # a blue bottle from 5 m
    integrate(belief, [_bottle(5.0, 0.12, colour="white", kind="mug")], _frame(0.0, 1.0))  # a white mug 12 cm off
    assert belief.objects["bottle-1"].name == "blue bottle"
    assert sorted(belief.objects) == ["bottle-1", "mug-1"]


def test_the_gate_has_a_ceiling():
    belief = WorldModel()
    integrate(belief, [_bottle(9.0, 0.0)], _frame(0.0, 0.0))  # from 9 m
    assert gate(belief.objects["bottle-1"], 9.0) <= 0.15


def test_a_few_near_looks_outvote_many_far_ones():
    """From 3 m a mug with its handle turned away reads as a white ball; from 1 m its handle shows."""
    belief = WorldModel()
    for time in range(6):
        integrate(belief, [_bottle(4.0, 0.0, colour="white", kind="ball")], _frame(0.6, float(time)))
    assert belief.objects["ball-1"].kind == "ball"
    for time in range(6, 9):
        integrate(belief, [_bottle(4.0, 0.0, colour="white", kind="mug")], _frame(3.0, float(time)))
    assert belief.objects["ball-1"].kind == "mug"
    assert belief.object("white mug").id == "ball-1"  # plans that named the ball still find it


def _frame_facing(camera_x: float, time: float) -> RgbdFrame:
    """A camera on the x axis looking along +x at the objects, nothing in front of them: each should be seen."""
    depth = np.full((48, 64), 10.0, dtype=np.float32)
    rgb = np.zeros((48, 64, 3), dtype=np.uint8)
    # camera axes in the world: x right (world -y), y up (world z), looking along -z (world +x)
    rotation = np.array([[0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    return RgbdFrame(rgb, depth, 60.0, (32.0, 24.0), np.array([camera_x, 0.0, 0.86]), rotation, time)


def test_one_thing_a_frame_saw_as_two_is_one_again_under_the_id_plans_hold():
    """A mug's body and its handle, seen as a mug and a bottle side by side in one frame, then as the mug alone."""
    belief = WorldModel()
    for time in range(3):  # from across the room: the plan takes this one
        integrate(belief, [_bottle(4.0, -0.03, colour="white", kind="mug")], _frame_facing(1.0, float(time)))
    near = [_bottle(4.0, 0.02, colour="white", kind="mug"), _bottle(4.0, -0.03, colour="white")]
    integrate(belief, near, _frame_facing(2.9, 3.0))
    assert len(belief.objects) == 2
    for time in range(4, 10):  # the mug alone: the split-off track should be in view and is not
        integrate(belief, [_bottle(4.0, 0.02, colour="white", kind="mug")], _frame_facing(2.9, float(time)))
    assert list(belief.objects) == ["mug-1"]
    assert belief.objects["mug-1"].kind == "mug" and belief.objects["mug-1"].confidence > 0.5
    assert abs(belief.objects["mug-1"].position[1] - 0.02) < 0.005


def test_a_view_that_takes_a_mug_for_a_box_says_nothing_of_where_its_handle_points():
    belief = WorldModel()
    mug = _bottle(4.0, 0.0, colour="white", kind="mug")
    mug.yaw, mug.yaw_known = 1.0, True  # its handle seen
    for time in range(3):
        integrate(belief, [mug], _frame(3.3, float(time)))
    box = _bottle(4.0, 0.0, colour="white", kind="cube")
    box.yaw, box.yaw_known = -0.4, True  # a box's yaw from its outline
    integrate(belief, [box], _frame(3.3, 3.0))
    assert belief.objects["mug-1"].kind == "mug"
    assert belief.objects["mug-1"].yaw == 1.0
