"""bt-eval: suites, episode draws, the report's statistics, the smoke suite, and the Ray backend."""

from __future__ import annotations

import cProfile
import json
import math
import os
from pathlib import Path

import numpy as np
import pytest

from bt_humanoid.control.stance import deepest_reach
from bt_humanoid.errors import UserError
from bt_humanoid.evaluation.command import eval_main
from bt_humanoid.evaluation.episode import Draw, _probe
from bt_humanoid.evaluation.profiling import top_costs
from bt_humanoid.evaluation.report import summarize, wilson_interval
from bt_humanoid.evaluation.suite import load_suite
from bt_humanoid.testing.spots import REACH_SLACK, reachable_spot

BENCHMARKS = Path(__file__).resolve().parents[1] / "missions" / "benchmarks"


def test_wilson_interval_matches_published_values():
    # Wilson score intervals (z = 1.96), as in Brown, Cai & DasGupta (2001)
    assert wilson_interval(50, 100) == pytest.approx((0.4038, 0.5962), abs=1e-4)
    assert wilson_interval(0, 10) == pytest.approx((0.0, 0.2775), abs=1e-4)
    assert wilson_interval(10, 10) == pytest.approx((0.7225, 1.0), abs=1e-4)
    low, high = wilson_interval(190, 200)
    assert low < 0.95 < high and high - low < 0.07


@pytest.mark.parametrize("name", ["fetch", "fetch_faults", "faults", "smoke"])
def test_every_suite_in_the_repository_is_valid(name):
    suite, world = load_suite(BENCHMARKS / f"{name}.yaml")
    assert suite.episodes >= 1 and world.name == suite.world


def test_the_fetch_suite_meets_the_issue_s_shape():
    suite, _ = load_suite(BENCHMARKS / "fetch.yaml")
    assert suite.episodes >= 200
    assert len(set(suite.objects)) >= 3
    assert suite.faults.share >= 0.2
    faults = {fault.kind: fault.settings for fault in suite.faults.kinds}
    assert set(faults) == {
        "slip", "target_moved", "obstacle_dropped", "push", "arm_bump", "blind", "new_command", "off_centre",
        "way_closed",
    }  # fmt: skip
    assert faults["push"].impulse == (40.0, 80.0)  # N·s: issue 26's shoves
    assert faults["off_centre"].offset == (0.02, 0.04)  # m: a bottle grasped off its centre
    assert faults["blind"].seconds == (5.0, 10.0)


def test_draws_follow_from_the_seed_and_index_alone():
    suite, _ = load_suite(BENCHMARKS / "fetch.yaml")
    later = [Draw(suite, i) for i in (7, 3, 5)]  # another order, as another worker would draw them
    by_index = {i: Draw(suite, i) for i in (3, 5, 7)}
    for i, draw in zip((7, 3, 5), later, strict=True):
        same = by_index[i]
        assert (draw.obj, draw.task_index, draw.fault_index, draw.surface) == (
            same.obj,
            same.task_index,
            same.fault_index,
            same.surface,
        )
        assert draw.rng.uniform() == same.rng.uniform()
    faulted = sum(Draw(suite, i).fault_index is not None for i in range(suite.episodes))
    assert 0.12 * suite.episodes < faulted < 0.28 * suite.episodes  # share 0.2, drawn


def _suite(tmp_path: Path, text: str) -> Path:
    file = tmp_path / "suite.yaml"
    file.write_text(text)
    return file


def test_an_unknown_object_is_reported_at_its_line(tmp_path):
    file = _suite(
        tmp_path,
        "suite: s\nobjects: [red cube, banana]\ntasks:\n  - command: bring me the {object}\n"
        "    expect: [{delivered: '{object}'}]\n",
    )
    with pytest.raises(UserError) as error:
        load_suite(file)
    assert "suite.yaml:2" in str(error.value) and "banana" in str(error.value) and "red cube" in str(error.value)


def test_a_command_task_without_expectations_is_refused(tmp_path):
    file = _suite(tmp_path, "suite: s\nobjects: [red cube]\ntasks:\n  - command: bring me the {object}\n")
    with pytest.raises(UserError, match="needs expect"):
        load_suite(file)


@pytest.mark.parametrize(
    ("faults", "line"),
    [
        ("", 5),  # a task's expectation
        ("faults:\n  share: 1\n  kinds:\n    - new_command: {command: wave, expect: [{on: [red cube, floor]}]}\n", 9),
    ],
)
def test_an_expectation_naming_an_unknown_surface_is_reported_at_its_line(tmp_path, faults, line):
    expect = "[{on: ['{object}', floor]}]" if not faults else "[{delivered: '{object}'}]"
    file = _suite(
        tmp_path,
        f"suite: s\nobjects: [red cube]\ntasks:\n  - command: bring me the {{object}}\n    expect: {expect}\n{faults}",
    )
    with pytest.raises(UserError) as error:
        load_suite(file)
    assert f"suite.yaml:{line}" in str(error.value) and "unknown name 'floor'" in str(error.value)


def test_an_unknown_fault_kind_names_the_valid_ones(tmp_path):
    file = _suite(
        tmp_path,
        "suite: s\nobjects: [red cube]\ntasks:\n  - command: bring me the {object}\n"
        "    expect: [{delivered: '{object}'}]\nfaults:\n  share: 0.5\n  kinds:\n    - earthquake: {}\n",
    )
    with pytest.raises(UserError) as error:
        load_suite(file)
    assert "suite.yaml:9" in str(error.value) and "earthquake" in str(error.value)


def test_a_time_budget_per_robot_gives_each_robot_its_own(tmp_path):
    task = "tasks:\n  - command: bring me the {object}\n    expect: [{delivered: '{object}'}]\n"
    file = _suite(
        tmp_path, f"suite: s\nobjects: [red cube]\n{task}time_budget: {{wheeled_humanoid: 300, biped_humanoid: 900}}\n"
    )
    assert load_suite(file)[0].episode_budget == 300
    assert load_suite(file, robot="biped_humanoid")[0].episode_budget == 900
    only_wheels = _suite(tmp_path, f"suite: s\nobjects: [red cube]\n{task}time_budget: {{wheeled_humanoid: 300}}\n")
    with pytest.raises(UserError) as error:
        load_suite(only_wheels, robot="biped_humanoid")
    assert "suite.yaml:6" in str(error.value) and "biped_humanoid" in str(error.value)
    assert load_suite(BENCHMARKS / "smoke.yaml", robot="biped_humanoid")[0].episode_budget == 240  # one for all


def test_bt_eval_exits_2_with_one_line_for_bad_input(tmp_path, capsys):
    assert eval_main([str(tmp_path / "missing.yaml")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "missing.yaml" in err and "not found" in err
    assert eval_main(["smoke", "--workers", "0"]) == 2
    assert "--workers 0" in capsys.readouterr().err


def episode(i: int, success: bool, fault: str | None, contacts: int = 0, moving: bool = False, fell=False) -> dict:
    """An episode's record as ``run_episode`` returns it."""
    return {
        "episode": i,
        "task": "bring me the {object}",
        "command": "bring me the red cube",
        "object": "red cube",
        "fault": fault,
        "success": success,
        "failure": None if success else "safety stop: collision",
        "sim_time": 60.0,
        "wall_s": 10.0,
        "person_contacts": contacts,
        "fell": fell,
        "collision": not success,
        "ended_moving": moving,
        "moving_after_brake": False,
        "plan_ms": [30.0],
        "stop_latency_s": 0.4 if fault == "new_command" else None,
        "look_ms_median": 25.0,
        "qp_ms_median": 0.4,
        "qp_ms_p95": 0.6,
    }


def test_summary_counts_what_the_episodes_report():
    episodes = [
        episode(0, True, None),
        episode(1, False, "push", contacts=3, fell=True),
        episode(2, True, "new_command", moving=True),
    ]
    figures = summarize(episodes, wall_s=20.0, workers=2)
    assert figures["episodes_with_fall"] == 1
    assert figures["success"]["successes"] == 2 and figures["success"]["episodes"] == 3
    assert figures["by_fault"]["push"]["rate"] == 0.0
    assert figures["episodes_with_person_contact"] == 1
    assert figures["episodes_with_collision_stop"] == 1
    assert figures["episodes_ended_moving"] == 1 and figures["episodes_moving_after_brake"] == 0
    assert figures["stop_latency_s"]["count"] == 1
    assert figures["real_time_factor_per_core"] == pytest.approx(6.0)
    assert [f["episode"] for f in figures["failures"]] == [1]


def test_a_fault_counts_as_handled_when_recovered_or_stopped_safely_with_the_thing_off_the_floor():
    episodes = [
        episode(0, True, "slip") | {"object_on_floor": False},
        episode(1, False, "slip") | {"object_on_floor": False},  # failed, at rest, the thing on a surface
        episode(2, False, "slip") | {"object_on_floor": True},  # dropped
        episode(3, False, "push", contacts=1) | {"object_on_floor": False},  # touched someone
        episode(4, False, "push") | {"object_on_floor": False, "moving_after_brake": True},  # not at rest
        episode(5, False, "push", moving=True) | {"object_on_floor": False},  # failed mid-motion, braked to rest
    ]
    figures = summarize(episodes, wall_s=20.0, workers=1)
    handled = figures["by_fault_recovered_or_safe"]
    assert (handled["slip"]["successes"], handled["slip"]["episodes"]) == (2, 3)
    assert (handled["push"]["successes"], handled["push"]["episodes"]) == (1, 3)
    assert "by_fault_recovered_or_safe" not in summarize([episode(0, True, "slip")], wall_s=1.0, workers=1)


def test_real_time_factor_counts_cpu_time_where_every_episode_has_it():
    shared = [episode(0, True, None) | {"cpu_s": 5.0}, episode(1, True, None) | {"cpu_s": 7.5}]
    assert summarize(shared, wall_s=20.0, workers=1)["real_time_factor_per_core"] == pytest.approx(120 / 12.5)
    older = [shared[0], episode(1, True, None)]  # a part saved before CPU time was recorded: wall time for all
    assert summarize(older, wall_s=20.0, workers=1)["real_time_factor_per_core"] == pytest.approx(6.0)


def save_run(path: Path, episodes: list[dict], **run) -> Path:
    """A run saved as ``bt-eval --json`` saves it (suite fetch, seed 0, the biped, commit abc1234 unless given)."""
    saved = {"suite": "fetch", "file": "missions/benchmarks/fetch.yaml", "seed": 0, "robot": "biped_humanoid"}
    saved |= {"commit": "abc1234", "command": f"bt-eval fetch --first {episodes[0]['episode']}", **run}
    path.write_text(json.dumps({**saved, **summarize(episodes, wall_s=20.0, workers=2), "episodes": episodes}))
    return path


def test_first_runs_the_episodes_from_that_index(tmp_path, monkeypatch):
    ran: list[int] = []

    def run(file, indices, seed, args, console):  # the episodes' records, without running them
        ran.extend(indices)
        return [episode(i, True, None) for i in indices], 1.0

    monkeypatch.setattr("bt_humanoid.evaluation.command._run", run)
    out = tmp_path / "part.json"
    assert eval_main(["smoke", "--first", "5", "--episodes", "3", "--json", str(out)]) == 0
    assert ran == [5, 6, 7]
    assert [e["episode"] for e in json.loads(out.read_text())["episodes"]] == [5, 6, 7]
    assert eval_main(["smoke", "--first", "-1"]) == 2


def test_merge_joins_parts_of_one_run_into_its_figures(tmp_path, capsys):
    first = save_run(tmp_path / "a.json", [episode(0, True, None), episode(1, False, "push", fell=True)])
    second = save_run(tmp_path / "b.json", [episode(2, True, None)])
    out = tmp_path / "all.json"
    assert eval_main([str(second), "--merge", str(first), "--json", str(out)]) == 0
    joined = json.loads(out.read_text())
    assert [e["episode"] for e in joined["episodes"]] == [0, 1, 2]
    assert joined["success"]["successes"] == 2 and joined["success"]["episodes"] == 3
    assert joined["episodes_with_fall"] == 1 and joined["wall_s"] == 40.0
    assert joined["commit"] == "abc1234" and joined["command"].splitlines() == [
        "bt-eval fetch --first 2",
        "bt-eval fetch --first 0",
    ]
    assert "joined 3 episodes of 2 runs" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("other", "says"),
    [
        ({"seed": 1}, "seed 1"),
        ({"robot": "wheeled_humanoid"}, "robot 'wheeled_humanoid'"),
        ({"sensors": "ideal"}, "sensors 'ideal'"),
        ({"commit": "abc1234 + uncommitted changes"}, "is not known"),
        ({"first": 1}, "episode 1 is in"),
    ],
)
def test_merge_refuses_parts_of_other_runs_in_one_line(tmp_path, capsys, other, says):
    first = save_run(tmp_path / "a.json", [episode(0, True, None), episode(1, True, None)])
    index = other.pop("first", 2)
    second = save_run(tmp_path / "b.json", [episode(index, True, None)], **other)
    assert eval_main([str(first), "--merge", str(second), "--json", str(tmp_path / "all.json")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and says in err and "b.json" in err
    assert not (tmp_path / "all.json").exists()


@pytest.mark.slow
@pytest.mark.sim
def test_the_smoke_suite_runs_end_to_end(tmp_path, capsys):
    out = tmp_path / "smoke.json"
    affinity = os.sched_getaffinity(0)
    assert eval_main(["smoke", "--json", str(out)]) == 0
    assert os.sched_getaffinity(0) == affinity, "one worker pins itself to a core, and lets go afterwards"
    report = json.loads(out.read_text())
    assert len(report["episodes"]) == 2
    assert report["success"]["successes"] == 2, report["failures"]
    assert report["episodes_with_person_contact"] == 0 and report["episodes_ended_moving"] == 0
    assert report["real_time_factor_per_core"] > 1.0
    printed = capsys.readouterr().out
    assert "success with 95 % confidence interval" in printed and "real-time factor per core" in printed


@pytest.mark.slow
def test_the_ray_backend_runs_episodes_on_a_local_ray_instance():
    ray = pytest.importorskip("ray")
    from bt_humanoid.evaluation.backends import run_ray

    try:
        records = list(run_ray(str(BENCHMARKS / "smoke.yaml"), [1], 3, None))
    finally:
        ray.shutdown()
    assert [r["episode"] for r in records] == [1]
    assert records[0]["success"], records[0]["failure"]


def test_the_results_sections_in_docs_are_generated_from_the_committed_runs():
    from bt_humanoid.evaluation.report import markdown

    root = BENCHMARKS.parents[1]
    results = (root / "docs" / "results.md").read_text()
    runs = sorted((root / "results").glob("fetch-seed*.json"))
    assert [run.name for run in runs][:2] == ["fetch-seed0.json", "fetch-seed1.json"]
    for run in runs:
        saved = json.loads(run.read_text())
        tag = "fetch" if run.stem == "fetch-seed0" else run.stem
        begin = f"<!-- results:{tag}:begin (bt-eval results/{run.name} --markdown) -->\n"
        end = f"<!-- results:{tag}:end -->"
        section = results[results.index(begin) + len(begin) : results.index(end)]
        assert section == markdown(saved, saved["command"]), run.name
        assert len(saved["episodes"]) == saved["success"]["episodes"] >= 200
        assert saved["commit"] and "uncommitted" not in saved["commit"], "a committed run names a clean commit"


def test_spots_are_drawn_where_the_robot_s_own_hand_reaches():
    probe = _probe("apartment", "biped_humanoid")
    base, world = probe.context.robot_config.base, probe.world
    table = probe.context.world_model.surface("table")
    (x0, y0), (x1, y1) = table.region
    rng = np.random.default_rng(3)
    args = (table, probe.navigator.grid, base.footprint_radius, np.array(world.bounds), [])
    deepest = deepest_reach(base)
    for _ in range(30):
        x, y = reachable_spot(*args, rng, deepest)
        assert min(x - x0, x1 - x, y - y0, y1 - y) <= deepest - REACH_SLACK + 1e-9
    # the wheeled robot's reach is deeper: some of its spots are out of the biped's
    wheeled = [reachable_spot(*args, rng) for _ in range(30)]
    assert max(min(x - x0, x1 - x, y - y0, y1 - y) for x, y in wheeled) > deepest - REACH_SLACK


@pytest.mark.sim
def test_a_biped_knocked_over_is_counted_fallen_and_one_standing_is_not():
    from bt_humanoid.evaluation.episode import watch_balance
    from bt_humanoid.testing.scenario import build_run

    run = build_run(
        {"world": "apartment", "robot": "biped_humanoid", "mission": "stand", "tree": {"wait": {"seconds": 9}}}
    )
    fallen = watch_balance(run, run.stack)

    def advance(seconds: float) -> None:
        end = run.sim.time + seconds
        while run.sim.time < end:
            run.executor.advance()

    advance(1.0)
    assert fallen == []
    pelvis = run.sim.model.body(run.sim.robot_root).id
    run.sim.data.xfrc_applied[pelvis, :3] = (0.0, 600.0, 0.0)  # a shove far beyond what a step recovers
    advance(0.3)
    run.sim.data.xfrc_applied[pelvis, :3] = 0.0
    advance(2.5)
    run.stack.close()
    assert fallen and fallen[0] > 1.0


def test_a_run_logged_to_a_file_says_each_episode_as_it_ends(tmp_path, monkeypatch, capsys):
    def run_local(file, indices, seed, workers, scene, plan_only, robot):  # records, without running them
        for i in indices:
            yield episode(i, i != 1, None)

    monkeypatch.setattr("bt_humanoid.evaluation.backends.run_local", run_local)
    assert eval_main(["smoke", "--episodes", "3", "--json", str(tmp_path / "run.json")]) == 0
    said = capsys.readouterr().out
    assert "episode 0: succeeded (1/3 done)" in said and "episode 2: succeeded (3/3 done)" in said
    assert "episode 1 (bring me the red cube): safety stop: collision" in said


def test_localisation_error_is_summarised_over_the_episodes_that_localise():
    localised = [
        episode(0, True, None) | {"localisation_p95_cm": 1.0, "localisation_max_cm": 2.0},
        episode(1, True, None) | {"localisation_p95_cm": 3.0, "localisation_max_cm": 7.5},
        episode(2, True, None) | {"localisation_p95_cm": None, "localisation_max_cm": None},  # --ideal-sensors
        episode(3, True, None),  # saved before localisation was watched
    ]
    figures = summarize(localised, wall_s=20.0, workers=1)
    assert figures["localisation_p95_cm_median"] == pytest.approx(2.0)
    assert figures["localisation_max_cm"] == 7.5
    assert summarize([episode(0, True, None)], wall_s=1.0, workers=1)["localisation_max_cm"] is None


def test_profile_needs_this_process_to_run_the_episodes(tmp_path, capsys):
    assert eval_main(["smoke", "--workers", "2", "--profile", str(tmp_path / "run.prof")]) == 2
    assert "--workers 1" in capsys.readouterr().err
    assert not (tmp_path / "run.prof").exists()


def test_top_costs_are_per_simulated_second_and_ordered_by_their_own_time():
    def busy(n: int) -> float:
        return sum(math.sqrt(i) for i in range(n))

    def idle() -> None:
        pass

    profile = cProfile.Profile()
    profile.enable()
    busy(200_000)
    for _ in range(10):
        idle()
    profile.disable()
    costs = top_costs(profile, simulated=2.0, count=50)
    assert [c.own_ms for c in costs] == sorted((c.own_ms for c in costs), reverse=True)
    named = {c.function.split("(")[-1].rstrip(")"): c for c in costs}
    assert named["idle"].calls == pytest.approx(5.0)  # 10 calls over 2 simulated seconds
    assert named["busy"].total_ms >= named["busy"].own_ms > named["idle"].own_ms
