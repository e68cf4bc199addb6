"""pycma's CMA-ES against cdbo's CDBO on the same race: the same start (the demonstration's
fitted policy w0), the same box [w0 - 1.5, w0 + 1.5], the same budget of laps, and the same
initial step (sigma0 = 0.03, cdbo's setting for every method).

    pip install ./crates/cdbo-py cma
    python examples/python/pycma_vs_cdbo.py [LAPS] [SEED]
"""

import sys

import cma

import cdbo

laps = int(sys.argv[1]) if len(sys.argv) > 1 else 300
seed = int(sys.argv[2]) if len(sys.argv) > 2 else 0
env = cdbo.RaceEnv("ridgeway", kernels=30)
low, high = env.low, env.high

# pycma minimises: the lap's reward L/T (m/s) with a minus sign, one lap per evaluation.
es = cma.CMAEvolutionStrategy(
    env.w0,
    0.03,
    {"bounds": [low, high], "seed": seed + 1, "maxfevals": laps, "verbose": -9},
)
best_cma, used = 0.0, 0
while used < laps:
    candidates = es.ask()[: laps - used]
    rewards = [env.lap(w) for w in candidates]
    used += len(candidates)
    best_cma = max(best_cma, *rewards)
    if len(candidates) < es.popsize:
        break
    es.tell(candidates, [-r for r in rewards])

# cdbo's CDBO through the same environment.
opt = cdbo.Optimizer("cdbo", env.w0, seed=seed)
for _ in range(laps):
    w = opt.ask()
    opt.tell(w, env.lap(w))

print(f"Ridgeway, 30 kernels, {laps} laps, seed {seed}: demonstration {env.demo.reward:.3f} m/s")
print(f"  pycma CMA-ES  best {best_cma:.3f} m/s")
print(f"  cdbo  CDBO    best {opt.best[1]:.3f} m/s")
