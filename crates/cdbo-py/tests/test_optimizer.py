"""cdbo.Optimizer: every method, ask/tell, save/load, bad input."""

import math

import numpy as np
import pytest

import cdbo


def sphere_reward(w, centre):
    return -float(np.sum((np.asarray(w) - centre) ** 2))


@pytest.mark.parametrize("method", cdbo.METHODS)
def test_every_method_asks_and_learns_a_sphere(method):
    w0 = np.zeros(12)
    centre = np.full(12, 0.2)
    opt = cdbo.Optimizer(method, w0, seed=3)
    assert opt.method == method and opt.dim == 12
    first = sphere_reward(w0, centre)
    for _ in range(30):
        w = opt.ask()
        assert isinstance(w, np.ndarray) and w.shape == (12,) and w.dtype == np.float64
        # Asking again before telling returns the same weights.
        assert np.array_equal(opt.ask(), w)
        opt.tell(w, sphere_reward(w, centre))
    assert opt.evaluations == 30
    best_w, best_r = opt.best
    assert best_r == pytest.approx(sphere_reward(best_w, centre))
    assert best_r >= first


@pytest.mark.parametrize("method", cdbo.METHODS)
def test_save_and_load_continue_bit_for_bit(method):
    centre = np.linspace(-0.3, 0.3, 8)
    opt = cdbo.Optimizer(method, np.zeros(8), seed=1)
    for _ in range(15):
        w = opt.ask()
        opt.tell(w, sphere_reward(w, centre))
    state = opt.save()
    assert isinstance(state, bytes)
    copy = cdbo.Optimizer.load(state)
    assert copy.save() == state
    for _ in range(10):
        a, b = opt.ask(), copy.ask()
        assert np.array_equal(a, b)
        r = sphere_reward(a, centre)
        opt.tell(a, r)
        copy.tell(b, r)
    assert opt.best[1] == copy.best[1]


def test_the_same_seed_asks_the_same_weights_and_another_does_not():
    def run(seed):
        opt = cdbo.Optimizer("cdbo", np.zeros(6), seed=seed)
        asked = []
        for _ in range(12):
            w = opt.ask()
            asked.append(w)
            opt.tell(w, sphere_reward(w, 0.1))
        return np.array(asked)

    assert np.array_equal(run(7), run(7))
    assert not np.array_equal(run(7), run(8))


def test_weights_stay_in_the_box():
    opt = cdbo.Optimizer("random", np.zeros(5), seed=0, bounds=0.25, sigma0=1.0)
    for _ in range(40):
        w = opt.ask()
        assert np.all(np.abs(w) <= 0.25)
        opt.tell(w, float(w.sum()))


def test_lists_are_accepted_like_arrays():
    opt = cdbo.Optimizer("cdbo", [0.0, 0.5, 1.0], seed=0)
    w = opt.ask()
    opt.tell(list(w), 1.0)
    assert opt.best[1] == 1.0


def test_bad_input_raises_value_error_with_the_librarys_message():
    with pytest.raises(ValueError, match="unknown method"):
        cdbo.Optimizer("cbdo", np.zeros(3))
    for bounds in (-1.0, 1e308):
        with pytest.raises(ValueError, match=r"search-box radius must be in \(0, 1000\]"):
            cdbo.Optimizer("cmaes", np.zeros(3), bounds=bounds)
    with pytest.raises(ValueError, match="1-D array or a sequence of numbers"):
        cdbo.Optimizer("cdbo", "abc")
    opt = cdbo.Optimizer("cdbo", np.zeros(3), seed=0)
    w = opt.ask()
    with pytest.raises(ValueError, match="expected 3 weights, got 2"):
        opt.tell(w[:2], 1.0)
    with pytest.raises(ValueError, match="reward must be finite"):
        opt.tell(w, math.nan)
    with pytest.raises(ValueError, match="weight 1 (is|must be finite, got) inf"):
        opt.tell(np.array([0.0, math.inf, 0.0]), 1.0)
    # Refused input changes nothing.
    assert opt.evaluations == 0 and opt.best is None
    opt.tell(w, 2.0)
    assert opt.evaluations == 1
    with pytest.raises(ValueError, match="not a saved cdbo optimiser"):
        cdbo.Optimizer.load(b"{not json")


@pytest.mark.parametrize("method", ["pattern-search", "random", "cmaes"])
def test_a_failed_lap_budget_caps_the_failures(method):
    """On a cliff (laps fail where the weights sum past 0.1), max_failed=3 keeps the failed
    laps to 3 over 60; without it the same run fails more."""

    def run(max_failed):
        opt = cdbo.Optimizer(method, np.zeros(4), seed=1, max_failed=max_failed)
        failed = 0
        for _ in range(60):
            w = opt.ask()
            if w.sum() > 0.1:
                failed += 1
                opt.tell(w, 0.0, failed_at=0.5)
            else:
                opt.tell(w, 10.0 + w.sum())
        return failed, opt.best[1]

    free, _ = run(None)
    capped, best = run(3)
    assert free > 3, free
    assert capped <= 3 and best > 10.0, (capped, best)
