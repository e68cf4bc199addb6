"""The race loop: cdbo.race and a Python loop over Optimizer + RaceEnv give the command line's
results bit for bit."""

import json

import numpy as np
import pytest

import cdbo


def test_race_ridgeway_300_laps_is_the_clis_race_bit_for_bit(cli, tmp_path):
    summary = json.loads(cli("race", "--json", "--laps", 300, "--seed", 0, "--out", tmp_path))
    result = cdbo.race("ridgeway", laps=300, seed=0)
    assert result.best_reward == summary["best_reward_mps"]
    assert result.demo.reward == summary["demo_reward_mps"]
    assert result.limit.reward == summary["limit_reward_mps"]
    assert sum(lap["failure"] is not None for lap in result.laps) == summary["failed_laps"]


def test_a_knob_is_the_clis_knob_and_changes_the_race(cli, tmp_path):
    args = ("race", "--json", "--laps", 40, "--kernels", 10, "--method", "linebo")
    summary = json.loads(cli(*args, "--knob", 0.1, "--out", tmp_path))
    result = cdbo.race("ridgeway", method="linebo", kernels=10, laps=40, seed=0, knob=0.1)
    assert result.best_reward == summary["best_reward_mps"]
    tuned = cdbo.race("ridgeway", method="linebo", kernels=10, laps=40, seed=0)
    assert [lap["reward"] for lap in tuned.laps] != [lap["reward"] for lap in result.laps]
    with pytest.raises(ValueError, match="linebo"):
        cdbo.race("ridgeway", method="linebo", kernels=10, laps=2, knob=-1.0)


def test_bounds_are_the_clis_box_radius_and_change_the_race(cli, tmp_path):
    """`bounds=` is `cdbo race --box-radius`: the same laps, bit for bit; not the default box's
    laps; a box that is not a positive number is refused before a lap is driven."""
    args = ("race", "--json", "--laps", 40, "--kernels", 10, "--method", "pattern-search")
    summary = json.loads(cli(*args, "--box-radius", 0.1, "--out", tmp_path))
    how = dict(method="pattern-search", kernels=10, laps=40)
    result = cdbo.race("ridgeway", bounds=0.1, **how)
    assert result.best_reward == summary["best_reward_mps"]
    default = cdbo.race("ridgeway", **how)
    assert [lap["reward"] for lap in default.laps] != [lap["reward"] for lap in result.laps]
    for bad in (0.0, -1.0, float("nan")):
        with pytest.raises(ValueError, match="search-box radius"):
            cdbo.race("ridgeway", bounds=bad, **how)


@pytest.mark.parametrize(
    ("method", "knob"), [("cdbo", None), ("pattern-search", None), ("turbo", 0.1)]
)
def test_a_python_loop_over_optimizer_and_env_is_the_librarys_race(method, knob):
    if method not in cdbo.METHODS:
        pytest.skip(f"{method} is not in this build")
    laps = 40
    result = cdbo.race("ridgeway", method=method, kernels=20, laps=laps, seed=5, knob=knob)
    env = cdbo.RaceEnv("ridgeway", kernels=20)
    assert np.array_equal(env.w0, result.initial.weights)
    opt = cdbo.Optimizer(
        method,
        env.w0,
        seed=5,
        knob=knob,
        lengthscale=env.lengthscale,
        track_length=env.track_length,
    )
    rewards = []
    for _ in range(laps):
        env.reset()
        w = opt.ask()
        lap = env.lap(w)
        assert (lap.failure is None) == lap.completed
        opt.tell(w, lap)
        rewards.append(lap.reward)
    assert rewards == [lap["reward"] for lap in result.laps]
    assert opt.best[1] == result.best_reward
    # The best policy drives the best lap again.
    assert cdbo.Simulator("ridgeway").lap(result.best).reward == result.best_reward


def test_cmaes_race_drives_the_start_then_the_loops_laps():
    """CMA-ES samples around w0 rather than asking for it: the race's first lap is the start's,
    counted in its best, and its laps 2 to N are the loop's first N - 1."""
    laps = 20
    result = cdbo.race("ridgeway", method="cmaes", kernels=20, laps=laps, seed=5)
    env = cdbo.RaceEnv("ridgeway", kernels=20)
    opt = env.optimizer("cmaes", seed=5)
    rewards = []
    for _ in range(laps - 1):
        w = opt.ask()
        lap = env.lap(w)
        opt.tell(w, lap)
        rewards.append(float(lap))
    raced = [lap["reward"] for lap in result.laps]
    assert raced[0] == float(env.lap(env.w0)) > 0.0
    assert raced[1:] == rewards
    assert result.best_reward == max(raced)


def test_the_readmes_loop_tells_the_whole_lap_and_is_the_librarys_race():
    """`opt.tell(w, env.lap(w))`, as the README writes it, passes each failure's place and
    reason: the pattern search, which repairs there, asks what `cdbo.race` asks."""
    laps = 60
    result = cdbo.race("ridgeway", method="pattern-search", kernels=20, laps=laps, seed=2)
    env = cdbo.RaceEnv("ridgeway", kernels=20)
    opt = env.optimizer("pattern-search", seed=2)
    told = []
    for _ in range(laps):
        w = opt.ask()
        lap = env.lap(w)
        opt.tell(w, lap)
        told.append(lap)
    assert [float(lap) for lap in told] == [r["reward"] for r in result.laps]
    assert opt.best[1] == result.best_reward
    failed = [lap for lap in told if not lap.completed]
    assert failed, "a pattern search of 60 laps fails some: the failures are what is tested"
    assert all(lap.x_fail is not None and lap.reward == 0.0 for lap in failed)
    assert any(lap.too_slow == (lap.failure in ("stalled", "time_limit")) for lap in failed)


def test_tell_takes_a_lap_or_a_number_not_both_kinds_of_failure():
    env = cdbo.RaceEnv("ridgeway", kernels=10)
    opt = cdbo.Optimizer("random", env.w0, seed=0)
    w = opt.ask()
    lap = env.lap(w + 5.0)  # full throttle everywhere: the car leaves the road
    assert not lap.completed and lap.x_fail is not None
    with pytest.raises(ValueError, match="already says where and why it failed"):
        opt.tell(w, lap, failed_at=0.5)
    with pytest.raises(TypeError, match="a LapResult or a reward"):
        opt.tell(w, "fast")
    opt.tell(w, lap)
    assert opt.evaluations == 1


def test_progress_is_called_after_every_lap_and_its_errors_propagate():
    seen = []
    result = cdbo.race(laps=5, kernels=10, progress=seen.append)
    assert [r["lap"] for r in seen] == [1, 2, 3, 4, 5]
    assert seen == result.laps
    assert seen[-1]["best"] == result.best_reward

    def fail(record):
        raise RuntimeError(f"stop at lap {record['lap']}")

    with pytest.raises(RuntimeError, match="stop at lap 1"):
        cdbo.race(laps=3, kernels=10, progress=fail)


def test_race_refuses_bad_settings():
    with pytest.raises(ValueError, match="at least one lap|laps.*at least 1"):
        cdbo.race(laps=0)
    with pytest.raises(ValueError, match="unknown method"):
        cdbo.race(method="nope", laps=2)
    with pytest.raises(ValueError, match="demonstration does not complete"):
        cdbo.race(demo_speed=80.0, laps=2)


def test_the_environment_works_without_gymnasium_and_registers_with_it():
    env = cdbo.RaceEnv(kernels=10)
    assert env.action_space.shape == (10,)
    assert np.array_equal(env.action_space.low, -np.ones(10))
    assert np.array_equal(env.action_space.high, np.ones(10))
    assert np.array_equal(env.low, env.w0 - cdbo.DEFAULT_BOX_RADIUS)
    obs, info = env.reset(seed=0)
    _, reward, terminated, truncated, info = env.step(np.zeros(10))
    assert terminated and not truncated and info["completed"]
    assert reward == cdbo.Simulator().lap(cdbo.Policy(env.w0, env.lengthscale)).reward
    edge = np.full(10, -1.0)
    assert env.step(edge)[1] == env.lap(env.low).reward
    gymnasium = pytest.importorskip("gymnasium")
    made = gymnasium.make("cdbo/Race-v0", kernels=10)
    made.reset(seed=0)
    assert made.step(np.zeros(10))[1] == reward


def test_gymnasiums_check_passes_without_a_warning():
    """gymnasium's own ``check_env`` finds the action space symmetric and normalised and the
    environment well formed: every warning it gives fails here."""
    import warnings

    gymnasium = pytest.importorskip("gymnasium")
    from gymnasium.utils.env_checker import check_env

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(cdbo.RaceEnv(kernels=10), skip_render_check=True)


def test_the_gil_is_released_while_laps_run():
    """With a switch interval of 100 s a thread gives up the GIL only when it blocks or a
    call releases it: the main thread, woken by the first lap's callback, runs while the race
    is still in its second lap only if the library runs laps without the GIL."""
    import sys
    import threading

    laps, seen, woken = 8, [], threading.Event()
    ran_after = []

    def progress(record):
        seen.append(record["lap"])
        if record["lap"] == 1:
            woken.set()

    old = sys.getswitchinterval()
    sys.setswitchinterval(100.0)
    try:
        racer = threading.Thread(target=cdbo.race, kwargs=dict(laps=laps, kernels=10, progress=progress))
        racer.start()
        woken.wait()
        ran_after.append(len(seen))
        racer.join()
    finally:
        sys.setswitchinterval(old)
    assert seen == list(range(1, laps + 1))
    assert ran_after[0] < laps, f"the main thread ran only after {ran_after[0]} laps"


def test_flying_is_the_clis_flying_lap(cli, tmp_path):
    """`flying=True` is `cdbo race --flying`: the same laps, bit for bit, and not the standing
    laps' race."""
    args = ("race", "--json", "--laps", 30, "--preset", "fast-safe")
    summary = json.loads(cli(*args, "--flying", "--out", tmp_path))
    result = cdbo.race("ridgeway", laps=30, preset="fast-safe", flying=True)
    assert result.best_reward == summary["best_reward_mps"]
    assert summary["best_lap_time_s"] == summary["best_flying_lap_s"]
    standing = cdbo.race("ridgeway", laps=30, preset="fast-safe")
    assert standing.best_reward != result.best_reward
