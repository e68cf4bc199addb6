"""The line from Python: `cdbo.race(line=...)` and `RaceEnv(line=...)` race what `cdbo race
--line` races, bit for bit."""

import json

import numpy as np
import pytest

import cdbo

# On the path tracker: the PI keeps no lap on this line a metre inside the road's edge, where
# a race learns by default.
LINE = dict(line="learn", line_kernels=8, line_start="min-curvature", steering="tracker")
FLAGS = ("--line", "learn", "--line-kernels", 8, "--line-start", "min-curvature")
FLAGS += ("--steering", "tracker")


def asked_and_told(env, opt, laps):
    """The rewards of `laps` laps of the README's loop: ask, drive, tell the whole lap."""
    rewards = []
    for _ in range(laps):
        w = opt.ask()
        lap = env.lap(w)
        opt.tell(w, lap)
        rewards.append(float(lap))
    return rewards


def test_a_learned_line_is_the_clis_and_the_envs_race(cli, tmp_path):
    laps = 30
    args = ("--method", "pattern-search", "--kernels", 12, "--laps", laps, "--seed", 1)
    summary = json.loads(cli("race", "--json", *args, *FLAGS, "--out", tmp_path))
    result = cdbo.race("ridgeway", method="pattern-search", kernels=12, laps=laps, seed=1, **LINE)
    assert result.best_reward == summary["best_reward_mps"] > 0
    # Both learned a metre inside the road's edge, the default.
    assert summary["off_track_margin_m"] == cdbo.LEARNING_OFF_TRACK_MARGIN == -1.0
    assert result.base_line == "min-curvature" == summary["base_line"]
    assert result.best_line.kernels == 8 and result.best.kernels == 12
    assert np.array_equal(
        result.best_weights, np.concatenate([result.best.weights, result.best_line.weights])
    )
    # A loop over the environment and the optimiser asks and drives the same laps.
    env = cdbo.RaceEnv("ridgeway", kernels=12, **LINE)
    assert (env.base_line, env.line_kernels) == ("min-curvature", 8)
    assert env.w0.shape == (20,) and not env.w0[12:].any()
    opt = env.optimizer("pattern-search", seed=1)
    assert asked_and_told(env, opt, laps) == [lap["reward"] for lap in result.laps]
    # The best policy's lap again, on the line it was raced on.
    # (A lap is judged at the game's rule; the best lap kept inside the reserve completes.)
    sim = cdbo.Simulator("ridgeway", line="min-curvature", steering="tracker")
    assert sim.lap(result.best, line=result.best_line).reward == result.best_reward
    assert cdbo.Simulator("ridgeway", steering="tracker").lap(
        result.best, line=result.best_line
    ).reward != (result.best_reward)


def test_a_fixed_line_and_bad_lines():
    env = cdbo.RaceEnv("ridgeway", kernels=10, line="min-curvature")
    assert (env.base_line, env.line_kernels) == ("min-curvature", None)
    assert env.w0.shape == (10,)
    centre = cdbo.RaceEnv("ridgeway", kernels=10)
    assert env.lap(env.w0).reward != centre.lap(centre.w0).reward
    with pytest.raises(ValueError, match="line"):
        cdbo.RaceEnv("ridgeway", kernels=10, line="apex")
    with pytest.raises(ValueError, match="line start"):
        cdbo.race("ridgeway", kernels=10, laps=2, line_start="min-curvature")
    with pytest.raises(ValueError, match="weights"):
        env.step(np.zeros(12))


def test_steering_and_the_off_track_margin_are_the_clis(cli, tmp_path):
    """`steering=` and `off_track_margin=` race what `cdbo race --steering --off-track-margin`
    races, bit for bit, in `cdbo.race` and a `RaceEnv` loop; bad values are refused."""
    laps = 20
    args = ("--method", "pattern-search", "--kernels", 20, "--laps", laps)
    flags = ("--steering", "tracker", "--off-track-margin", -0.5)
    summary = json.loads(cli("race", "--json", *args, *flags, "--out", tmp_path))
    how = dict(steering="tracker", off_track_margin=-0.5)
    result = cdbo.race("ridgeway", method="pattern-search", kernels=20, laps=laps, **how)
    assert result.best_reward == summary["best_reward_mps"] > 0
    assert result.best_reward != cdbo.race(
        "ridgeway", method="pattern-search", kernels=20, laps=laps, steering="tracker"
    ).best_reward
    env = cdbo.RaceEnv("ridgeway", kernels=20, **how)
    opt = env.optimizer("pattern-search")
    assert asked_and_told(env, opt, laps) == [lap["reward"] for lap in result.laps]
    with pytest.raises(ValueError, match="steering"):
        cdbo.RaceEnv("ridgeway", kernels=10, steering="stanley")
    with pytest.raises(ValueError, match="off-track margin"):
        cdbo.race("ridgeway", kernels=10, laps=2, off_track_margin=9.0)


def test_the_recommended_learner_in_the_readmes_loop_is_the_clis_race(cli, tmp_path):
    """The learner the README recommends for a car, `safe-pattern-search` on the path tracker,
    written as the README's loop (`env.optimizer(..., max_failed=B)`, ask, drive, tell the
    whole lap), asks the laps `cdbo race --method safe-pattern-search --steering tracker
    --max-failed-laps B --demo-speed 15` drives (the paper's demonstration, as the environment
    without a method), bit for bit, and keeps to its budget."""
    laps, budget = 60, 5
    args = ("--method", "safe-pattern-search", "--kernels", 20, "--laps", laps)
    flags = ("--steering", "tracker", "--max-failed-laps", budget, "--seed", 3, "--demo-speed", 15)
    summary = json.loads(cli("race", "--json", *args, *flags, "--out", tmp_path))
    env = cdbo.RaceEnv("ridgeway", kernels=20, steering="tracker")
    opt = env.optimizer("safe-pattern-search", seed=3, max_failed=budget)
    rewards = asked_and_told(env, opt, laps)
    assert max(rewards) == summary["best_reward_mps"] > float(env.lap(env.w0))
    failed = sum(r == 0.0 for r in rewards)
    assert failed == summary["failed_laps"]
    assert 0 < failed <= budget, "some laps fail, none past the budget"
