"""Tracks, cars, the simulator, the policy and the limit lap."""

import math

import numpy as np
import pytest

import cdbo


def test_the_builtin_track_and_car_load_by_name_and_by_default():
    track = cdbo.Track.load("ridgeway")
    assert track.name == "Ridgeway" and track.length > 1000
    assert cdbo.Track.load().name == track.name
    assert "ridgeway" in cdbo.Track.builtin()
    line = track.centre_line()
    assert line["x"].shape == line["s"].shape and line["s"][-1] <= track.length
    car = cdbo.Car.load()
    assert car.name and car.mass > 500


def test_a_lap_with_trace_is_consistent_and_the_limit_bounds_it():
    sim = cdbo.Simulator(cdbo.Track.load("ridgeway"), cdbo.Car.load("spirit-300"))
    # With the engine brake modelled, the fit of the 15 m/s demonstration spins on Ridgeway
    # (x = 0.57); that of a 10 m/s one completes.
    demo, x, a = sim.demonstrate(10.0)
    assert demo.completed and x.shape == a.shape and np.all(np.diff(x) >= 0)
    policy = cdbo.Policy.fit(x, a, 30)
    lap = sim.lap(policy, trace=True)
    assert lap.completed and lap.failure is None and lap.x_fail is None
    assert lap.reward == sim.track.length / lap.time
    trace = lap.trace
    assert set(trace) >= {"t", "x", "speed", "pedal", "pos_x", "pos_y"}
    assert len({len(v) for v in trace.values()}) == 1
    assert trace["t"][-1] <= lap.time < trace["t"][-1] + 0.021
    assert np.all(np.abs(trace["pedal"]) <= 1.0)
    # Without a trace the lap is the same lap.
    assert sim.lap(policy).reward == lap.reward and sim.lap(policy).trace is None
    limit = cdbo.limit(sim.track, sim.car)
    assert limit.reward > lap.reward and limit.time < lap.time
    assert limit.speed.shape[0] >= len(sim.track.centre_line()["s"])


def test_full_braking_stalls_at_the_start():
    lap = cdbo.Simulator().lap(cdbo.Policy(-np.ones(8)))
    assert not lap.completed and lap.time is None and lap.reward == 0.0
    assert lap.failure == "stalled" and lap.x_fail < 0.05


def test_the_policy_is_the_papers_kernel_sum():
    w = np.array([0.5, -0.2, 0.9, 0.1])
    p = cdbo.Policy(w, 0.4)
    assert p.kernels == 4 and p.lengthscale == 0.4 and np.array_equal(p.weights, w)
    xs = np.linspace(0, 1, 11)
    centres = np.linspace(0, 1, 4)
    r = np.sqrt(3) * np.abs(xs[:, None] - centres[None, :]) / 0.4
    expected = np.clip(((1 + r) * np.exp(-r)) @ w, -1, 1)
    assert np.allclose(p.action(xs), expected, rtol=0, atol=1e-12)
    assert p.action(0.3) == pytest.approx(float(np.interp(0.3, xs, p.action(xs))), abs=0.05)
    # A fit of the policy's own table gives the policy back.
    fit = cdbo.Policy.fit(xs, p.action(xs), 4, lengthscale=0.4, ridge=1e-9)
    assert np.allclose(fit.weights, w, atol=1e-5)


def test_no_margin_keeps_the_reserve_a_race_learns_with():
    """`off_track_margin=None` is the reserve `cdbo.race` and `RaceEnv` learn with: on
    Ridgeway, whose verges are not known, the car's centre kept a metre inside the road, so a
    lap that runs wide fails there, before the game's rule (a metre outside) would end it."""
    pedal = cdbo.Policy(np.full(20, 0.4))
    kept = cdbo.Simulator(off_track_margin=None).lap(pedal)
    game = cdbo.Simulator().lap(pedal)
    assert kept.failure == game.failure == "off_track"
    assert kept.x_fail < game.x_fail
    assert cdbo.RaceEnv(kernels=20).simulator.lap(pedal).x_fail == kept.x_fail
    with pytest.raises(ValueError, match="off-track margin"):
        cdbo.Simulator(off_track_margin=math.nan)


def test_bad_input_raises_with_the_librarys_message(tmp_path):
    with pytest.raises(ValueError, match='unknown track "nowhere"'):
        cdbo.Track.load("nowhere")
    with pytest.raises(OSError, match="missing.xml"):
        cdbo.Track.load(tmp_path / "missing.xml")
    bad = tmp_path / "bad.xml"
    bad.write_text("<params name='x'><section name='Main Track'>")
    with pytest.raises(ValueError, match="bad.xml"):
        cdbo.Track.load(bad)
    with pytest.raises(ValueError, match="no-such-car"):
        cdbo.Car.load("no-such-car")
    with pytest.raises(ValueError, match="policy weight 1 (is|must be finite, got) NaN"):
        cdbo.Policy([0.0, math.nan, 0.0])
    with pytest.raises(ValueError, match="same length"):
        cdbo.Policy.fit([0.0, 0.5], [0.1], 4)
    with pytest.raises(ValueError, match=r"demonstration \(x, a\) pairs 0: must be at least 1"):
        cdbo.Policy.fit([], [], 4)
    with pytest.raises(TypeError):
        cdbo.Simulator().lap([0.1, 0.2])
