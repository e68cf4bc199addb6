"""`preset="fast-safe"`: the recommended stack by one name, as `cdbo race --preset fast-safe`,
is its long form bit for bit in `cdbo.race`, `Study.create` and `RaceEnv`, and never mixes
with an argument of its stack."""

import json

import numpy as np
import pytest

import cdbo

LONG_FORM = dict(method="safe-pattern-search", steering="tracker", line="min-curvature")


def rewards(result):
    return [lap["reward"] for lap in result.laps]


def test_the_preset_races_as_its_long_form_and_the_clis_preset(cli, tmp_path):
    preset = cdbo.race("ridgeway", laps=30, preset="fast-safe")
    long = cdbo.race("ridgeway", laps=30, **LONG_FORM)
    assert rewards(preset) == rewards(long)
    assert preset.best_reward == long.best_reward
    assert preset.base_line == "min-curvature"
    summary = json.loads(
        cli("race", "--json", "--laps", 30, "--preset", "fast-safe", "--out", tmp_path)
    )
    assert preset.best_reward == summary["best_reward_mps"]
    assert sum(lap["failure"] is not None for lap in preset.laps) == summary["failed_laps"]
    assert rewards(cdbo.race("ridgeway", laps=30)) != rewards(preset)
    budget = cdbo.race("ridgeway", laps=30, preset="fast-safe", max_failed=2)
    assert sum(lap["failure"] is not None for lap in budget.laps) <= 2


@pytest.mark.parametrize(
    "given",
    [
        dict(method="cdbo"),
        dict(steering="pi"),
        dict(line="centre"),
        dict(line_kernels=4),
        dict(line_start="centre"),
    ],
)
def test_the_preset_beside_an_argument_of_its_stack_is_refused(given, tmp_path):
    (argument,) = given
    with pytest.raises(ValueError, match=f"preset=.*not both.*{argument}="):
        cdbo.race("ridgeway", laps=2, preset="fast-safe", **given)
    with pytest.raises(ValueError, match=f"not both.*{argument}="):
        cdbo.Study.create(tmp_path / "s.cdbo.db", np.zeros(6), preset="fast-safe", **given)
    assert not (tmp_path / "s.cdbo.db").exists()


def test_an_unknown_preset_is_refused_naming_the_presets():
    assert cdbo.PRESETS == ["fast-safe", "fast"]
    with pytest.raises(ValueError, match="fastest.*fast-safe"):
        cdbo.race("ridgeway", laps=2, preset="fastest")


def test_a_study_of_the_preset_stores_its_stack_and_asks_as_its_long_form(cli, tmp_path):
    w0 = np.linspace(0.2, 0.8, 6)
    preset = cdbo.Study.create(tmp_path / "p.cdbo.db", w0, preset="fast-safe")
    long = cdbo.Study.create(tmp_path / "l.cdbo.db", w0, **LONG_FORM)
    config = preset.config
    assert config["method"] == "safe-pattern-search"
    assert config["steering"] == "tracker"
    assert config["base_line"] == "min-curvature"
    for _ in range(3):
        a, b = preset.ask(), long.ask()
        assert np.array_equal(a.weights, b.weights)
        preset.tell(a, failed=True, at=0.5)
        long.tell(b, failed=True, at=0.5)
    status = json.loads(cli("study", "status", "p", "--db", tmp_path / "p.cdbo.db", "--json"))
    assert (status["method"], status["steering"], status["line"]) == (
        "safe-pattern-search",
        "tracker",
        "min-curvature",
    )


def test_an_environment_of_the_preset_is_the_races_preset():
    laps = 20
    result = cdbo.race("ridgeway", kernels=20, laps=laps, preset="fast-safe")
    env = cdbo.RaceEnv("ridgeway", kernels=20, preset="fast-safe")
    assert env.base_line == "min-curvature"
    assert np.array_equal(env.w0, result.initial.weights)
    opt = env.optimizer()
    assert opt.method == "safe-pattern-search"
    told = []
    for _ in range(laps):
        w = opt.ask()
        lap = env.lap(w)
        opt.tell(w, lap)
        told.append(lap.reward)
    assert told == rewards(result)
    with pytest.raises(ValueError, match="not both.*method="):
        env.optimizer("cdbo")
    with pytest.raises(ValueError, match="not both.*steering="):
        cdbo.RaceEnv("ridgeway", kernels=20, preset="fast-safe", steering="pi")
    assert cdbo.RaceEnv("ridgeway", kernels=20).optimizer().method == "cdbo"


def test_the_presets_best_policy_asks_for_a_speed_and_drives_again_with_it():
    result = cdbo.race("ridgeway", kernels=20, laps=20, preset="fast-safe")
    target = result.best_target
    assert set(target) == {"profile", "length", "scale", "span"}
    assert target["span"] == 0.25 and 0 < target["scale"] <= 1
    sim = cdbo.Simulator("ridgeway", line="min-curvature", steering="tracker")
    assert sim.lap(result.best, target=target).reward == result.best_reward
    # Without its target the same weights are an open-loop pedal: another lap.
    assert sim.lap(result.best).reward != result.best_reward
    assert cdbo.race("ridgeway", laps=2).best_target is None
    with pytest.raises(ValueError, match='target: no "span"'):
        sim.lap(result.best, target={k: v for k, v in target.items() if k != "span"})
    with pytest.raises(ValueError, match="scale"):
        sim.lap(result.best, target={**target, "scale": -1.0})
