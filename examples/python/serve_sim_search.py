#!/usr/bin/env python3
"""Race on cdbo's simulator from Python through `cdbo serve-sim` (JSON lines on stdin/stdout).

A (1+1) evolution strategy in plain Python (no packages needed) improves the policy for a few
laps. Any optimiser plugs in the same way: with pycma, for example,

    es = cma.CMAEvolutionStrategy(info["w0"], 0.03)
    while not es.stop():
        xs = es.ask()
        es.tell(xs, [-lap(x)["reward_mps"] for x in xs])

Usage: python3 serve_sim_search.py [LAPS] [CDBO ARGS...]
       e.g. python3 serve_sim_search.py 40 --track forza --data-dir ../shared --kernels 30
"""
import json
import random
import subprocess
import sys

laps = int(sys.argv[1]) if len(sys.argv) > 1 else 30
extra = sys.argv[2:] or ["--kernels", "20"]
sim = subprocess.Popen(
    ["cdbo", "serve-sim", *extra], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
)


def request(message):
    sim.stdin.write(json.dumps(message) + "\n")
    sim.stdin.flush()
    answer = json.loads(sim.stdout.readline())
    if "error" in answer:
        raise RuntimeError(answer["error"])
    return answer


def lap(weights):
    return request({"weights": list(weights)})


info = request({"info": True})
print(f"{info['track']}: {info['length_m']:.0f} m, {info['dim']} weights, "
      f"limit {info['limit_reward_mps']:.2f} m/s")
rng = random.Random(0)
best_w = info["w0"]
best = lap(best_w)["reward_mps"]
print(f"lap 1: initial policy {best:.2f} m/s")
sigma = 0.03
for k in range(2, laps + 1):
    w = [min(max(b + rng.gauss(0.0, sigma), lo), hi)
         for b, lo, hi in zip(best_w, info["lower"], info["upper"])]
    result = lap(w)
    if result["reward_mps"] > best:
        best, best_w = result["reward_mps"], w
        sigma *= 1.5
    else:
        sigma *= 0.9
    failure = result["failure"]["reason"] if result["failure"] else "ok"
    print(f"lap {k}: {result['reward_mps']:.2f} m/s ({failure}), best {best:.2f} m/s")
sim.stdin.close()
sim.wait()
