"""The walking benchmark's options: when the largest push comes, and what it refuses (no physics)."""

from __future__ import annotations

import pytest

from bt_humanoid.benchmarks.walking import FIRST_MOMENT, STRIDE, main, push_moments


def test_one_moment_is_the_benchmarks_old_moment_and_more_spread_over_one_stride():
    assert push_moments(1) == [2.5]
    moments = push_moments(8)
    assert moments[0] == FIRST_MOMENT
    assert len(set(moments)) == 8 and max(moments) < FIRST_MOMENT + STRIDE
    gaps = [b - a for a, b in zip(moments, moments[1:], strict=False)]
    assert max(gaps) - min(gaps) < 1e-3


@pytest.mark.parametrize("option", [["--phases", "0"], ["--push-time", "0"], ["--push-time", "3"]])
def test_a_push_option_out_of_range_is_refused_with_exit_code_2(option, capsys):
    with pytest.raises(SystemExit) as refused:
        main(["--largest-only", *option])
    assert refused.value.code == 2
    assert option[0] in capsys.readouterr().err
