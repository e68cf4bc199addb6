"""Optuna's TPE against cdbo's CDBO on the same race: the same start (the demonstration's
fitted policy w0, Optuna's first trial), the same box [w0 - 1.5, w0 + 1.5] and the same
budget of laps.

    pip install ./crates/cdbo-py optuna
    python examples/python/optuna_vs_cdbo.py [LAPS] [SEED]
"""

import sys

import numpy as np
import optuna

import cdbo

laps = int(sys.argv[1]) if len(sys.argv) > 1 else 300
seed = int(sys.argv[2]) if len(sys.argv) > 2 else 0
env = cdbo.RaceEnv("ridgeway", kernels=30)
low, high = env.low, env.high
names = [f"w{i}" for i in range(len(env.w0))]


def objective(trial):
    w = np.array([trial.suggest_float(n, lo, hi) for n, lo, hi in zip(names, low, high)])
    return env.lap(w)


optuna.logging.set_verbosity(optuna.logging.WARNING)
study = optuna.create_study(direction="maximize", sampler=optuna.samplers.TPESampler(seed=seed))
study.enqueue_trial(dict(zip(names, env.w0)))
study.optimize(objective, n_trials=laps)

# cdbo's CDBO through the same environment.
opt = cdbo.Optimizer("cdbo", env.w0, seed=seed)
for _ in range(laps):
    w = opt.ask()
    opt.tell(w, env.lap(w))

print(f"Ridgeway, 30 kernels, {laps} laps, seed {seed}: demonstration {env.demo.reward:.3f} m/s")
print(f"  Optuna TPE  best {study.best_value:.3f} m/s")
print(f"  cdbo  CDBO  best {opt.best[1]:.3f} m/s")
