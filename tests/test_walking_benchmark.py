"""The walking benchmark's options: when the largest push comes, and what it refuses (no physics)."""

from __future__ import annotations

import itertools
import subprocess
import sys

import pytest

from bt_humanoid.benchmarks.walking import FIRST_MOMENT, STRIDE, main, push_moments


def test_one_moment_is_the_benchmarks_old_moment_and_more_spread_over_one_stride():
    assert push_moments(1) == [2.5]
    moments = push_moments(8)
    assert moments[0] == FIRST_MOMENT
    assert len(set(moments)) == 8 and max(moments) < FIRST_MOMENT + STRIDE
    gaps = [b - a for a, b in itertools.pairwise(moments)]
    assert max(gaps) - min(gaps) < 1e-3


@pytest.mark.parametrize("option", [["--phases", "0"], ["--push-time", "0"], ["--push-time", "3"]])
def test_a_push_option_out_of_range_is_refused_with_exit_code_2(option, capsys):
    with pytest.raises(SystemExit) as refused:
        main(["--largest-only", *option])
    assert refused.value.code == 2
    assert option[0] in capsys.readouterr().err


def _bound(project_root, *options: str) -> float:
    script = project_root / "scripts" / "push_capture_bound.py"
    printed = subprocess.run([sys.executable, str(script), *options], capture_output=True, text=True, check=True)
    return float(printed.stdout.split("up to ")[1].split(" N·s")[0])


def test_the_capture_bound_grows_with_the_legs_reach_and_falls_with_a_longer_swing(project_root):
    biped = _bound(project_root)
    assert 40.0 < biped < 65.0  # the biped's legs: docs/walking.md cites about 51 N·s
    assert _bound(project_root, "--reach", "0.6") > biped + 5.0
    assert _bound(project_root, "--shortest-swing", "0.3") < biped - 5.0
