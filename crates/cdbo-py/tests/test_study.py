"""cdbo.Study: the same SQLite file as `cdbo study`, driven from Python and the command line."""

import json
import math

import numpy as np
import pytest

import cdbo


def test_a_study_written_in_python_is_read_and_driven_by_the_cli_and_back(cli, tmp_path):
    db = tmp_path / "car.cdbo.db"
    w0 = np.linspace(0.2, 0.8, 6)
    study = cdbo.Study.create(db, w0, seed=2)
    assert study.config["kernels"] == 6 and np.array_equal(study.config["w0"], w0)
    first = study.ask()
    assert first.id == 1 and np.array_equal(first.weights, w0)
    assert study.tell(first, lap_time=50.0, length=1000.0) == 20.0
    second = study.ask()
    assert study.tell(second.id, failed=True, at=0.25, reason="spun") == 0.0
    third = study.ask()

    # The command line sees the same trials and the same pending suggestion.
    history = json.loads(cli("study", "history", "car", "--db", db, "--json"))
    assert [t["id"] for t in history] == [1, 2, 3]
    assert history[0]["reward"] == 20.0 and history[0]["lap_time_s"] == 50.0
    assert history[1]["failure"] == "spun" and history[1]["x_fail"] == 0.25
    asked = json.loads(cli("study", "ask", "car", "--db", db))
    assert asked["trial"] == 3 and asked["weights"] == list(third.weights)
    cli("study", "tell", "car", "--db", db, "--trial", 3, "--reward", 21.5)

    # And Python sees what the command line told, and continues from it.
    again = cdbo.Study.open(db)
    assert again.told == 3
    assert again.best.id == 3 and again.best.reward == 21.5
    fourth = again.ask()
    assert fourth.id == 4
    status = json.loads(cli("study", "status", "car", "--db", db, "--json"))
    assert status["pending_trial"] == 4 and status["best_reward"] == 21.5


def test_a_study_asks_what_the_optimizer_asks():
    w0 = np.zeros(5)
    study = cdbo.Study.create(
        __import__("tempfile").mkdtemp() + "/s.db", w0, method="cmaes", seed=4
    )
    opt = cdbo.Optimizer("cmaes", w0, seed=4)
    for i in range(8):
        t = study.ask()
        w = opt.ask()
        assert np.array_equal(t.weights, w)
        study.tell(t, reward=float(-i))
        opt.tell(w, float(-i))


def test_a_study_told_the_laps_length_asks_what_the_optimizer_asks(tmp_path):
    env = cdbo.RaceEnv("ridgeway", kernels=12)
    told = dict(lengthscale=env.lengthscale, track_length=env.track_length, seed=3)
    study = cdbo.Study.create(tmp_path / "s.db", env.w0, method="pattern-search", **told)
    opt = cdbo.Optimizer("pattern-search", env.w0, **told)
    failed = 0
    for _ in range(12):
        t = study.ask()
        w = opt.ask()
        assert np.array_equal(t.weights, w)
        _, reward, _, _, info = env.step(w)
        if info["completed"]:
            study.tell(t, reward)
        else:
            failed += 1
            study.tell(t, failed=True, at=info["x_fail"], reason=info["failure"])
        opt.tell(w, reward, failed_at=info["x_fail"], too_slow=info["too_slow"])
    assert failed > 0
    for bad in (0.0, -5.0, math.nan):
        with pytest.raises(ValueError, match="lap's length"):
            cdbo.Study.create(tmp_path / "bad.db", env.w0, track_length=bad)
        assert not (tmp_path / "bad.db").exists()


def test_history_is_a_list_of_dicts_or_a_dataframe(tmp_path):
    study = cdbo.Study.create(tmp_path / "h.db", np.zeros(3))
    t = study.ask()
    study.tell(t, 1.5)
    study.ask()
    rows = study.history(as_frame=False)
    assert [r["id"] for r in rows] == [1, 2]
    assert rows[0]["reward"] == 1.5 and rows[1]["reward"] is None
    pandas = pytest.importorskip("pandas")
    frame = study.history()
    assert isinstance(frame, pandas.DataFrame) and list(frame["id"]) == [1, 2]


def test_bad_input_raises_and_loses_nothing(tmp_path):
    db = tmp_path / "s.db"
    study = cdbo.Study.create(db, np.zeros(3))
    with pytest.raises(FileExistsError, match="already exists"):
        cdbo.Study.create(db, np.zeros(3))
    assert isinstance(FileExistsError(), OSError)
    with pytest.raises(OSError, match="no such study"):
        cdbo.Study.open(tmp_path / "missing.db")
    (tmp_path / "notes.db").write_text("x,a\n0,1\n")
    with pytest.raises(OSError, match="not a cdbo study|not an SQLite database"):
        cdbo.Study.open(tmp_path / "notes.db")
    with pytest.raises(ValueError, match="unknown method"):
        cdbo.Study.create(tmp_path / "m.db", np.zeros(3), method="nope")
    assert not (tmp_path / "m.db").exists()
    t = study.ask()
    with pytest.raises(ValueError, match="reward must be a finite number"):
        study.tell(t, math.inf)
    with pytest.raises(ValueError, match="lap time must be a positive"):
        study.tell(t, lap_time=-1.0, length=100.0)
    with pytest.raises(ValueError, match="tell one of"):
        study.tell(t, 1.0, failed=True)
    with pytest.raises(ValueError, match="with failed=True"):
        study.tell(t, 1.0, at=0.5)
    with pytest.raises(ValueError, match="no trial 9"):
        study.tell(9, 1.0)
    assert study.told == 0
    study.tell(t, 3.0)
    with pytest.raises(ValueError, match="already told"):
        study.tell(t, 4.0)
    assert study.best.reward == 3.0


def test_a_study_keeps_the_race_settings_and_its_budget(tmp_path):
    env = cdbo.RaceEnv("ridgeway", kernels=8, line="learn", line_start="min-curvature")
    study = cdbo.Study.create(
        tmp_path / "line.db", env.w0, method="pattern-search", line="learn",
        line_start="min-curvature", steering="tracker", max_failed=1,
    )
    c = study.config
    assert (c["kernels"], c["line_kernels"], c["max_failed_laps"]) == (8, 8, 1)
    assert (c["base_line"], c["steering"]) == ("min-curvature", "tracker")
    first = study.ask()
    assert np.array_equal(first.weights, env.w0)
    study.tell(first, 10.0)
    second = study.ask()
    assert not np.array_equal(second.weights, env.w0)
    study.tell(second, failed=True, at=0.5, reason="off_track")
    # The budget of one failed lap is spent: only the best lap is driven again.
    assert np.array_equal(study.ask().weights, env.w0)
    with pytest.raises(ValueError, match="too few for a line of 16 kernels"):
        cdbo.Study.create(tmp_path / "short.db", env.w0, line="learn", line_kernels=16)
    with pytest.raises(ValueError, match="line kernels of line centre"):
        cdbo.Study.create(tmp_path / "centre.db", env.w0, line_kernels=4)
    with pytest.raises(ValueError, match="steering"):
        cdbo.Study.create(tmp_path / "steer.db", env.w0, steering="wheel")
    assert not any((tmp_path / f).exists() for f in ("short.db", "centre.db", "steer.db"))


def test_bounds_are_stored_and_bound_every_trial(tmp_path):
    """`bounds=` is `cdbo study create --box-radius`: stored with the study, named in its
    config, and every trial of a random search whose σ reaches far past it stays on the box
    w0 ± bounds; a box that is not a positive number is refused and writes nothing."""
    w0 = np.linspace(-0.2, 0.2, 6)
    study = cdbo.Study.create(tmp_path / "box.db", w0, method="random", knob=1.0, bounds=0.05)
    assert study.config["box_radius"] == 0.05
    farthest = 0.0
    for i in range(5):
        trial = study.ask()
        farthest = max(farthest, float(np.max(np.abs(trial.weights - w0))))
        study.tell(trial, float(i))
    assert abs(farthest - 0.05) < 1e-12
    assert cdbo.Study.open(tmp_path / "box.db").config["box_radius"] == 0.05
    for bad in (0.0, -1.0, float("nan")):
        with pytest.raises(ValueError, match="search-box radius"):
            cdbo.Study.create(tmp_path / "bad.db", w0, bounds=bad)
    assert not (tmp_path / "bad.db").exists()
