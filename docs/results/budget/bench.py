"""The budget benchmark: 6 seeds x 300 laps on four panels, the mean best reward, the mean
failed laps and the worst seed per panel.

    python3 docs/results/budget/bench.py OUT target/release/cdbo safe-pattern-search [--max-failed-laps N]

Run from the worktree root with the TORCS data at ../shared; two races at a time.
"""
import json
import os
import statistics
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

out, binary, method = sys.argv[1], sys.argv[2], sys.argv[3]
extra = sys.argv[4:]
panels = [("forza", 50), ("allondaz", 30), ("e-track-2", 30), ("forza", 100)]
seeds = range(int(os.environ.get("SEEDS", "6")))
os.makedirs(out, exist_ok=True)


def race(job):
    (track, kernels), seed = job
    folder = f"{out}/{track}-{kernels}-s{seed}"
    args = [binary, "--data-dir", "../shared", "race", "--track", track, "--kernels",
            str(kernels), "--seed", str(seed), "--method", method, "--json", "--out", folder]
    summary = json.loads(subprocess.run(args + extra, capture_output=True, text=True,
                                        check=True).stdout)
    return track, kernels, summary["best_reward_mps"], summary["failed_laps"]


with ThreadPoolExecutor(2) as pool:
    results = list(pool.map(race, [(p, s) for p in panels for s in seeds]))
for track, kernels in panels:
    rows = [r for r in results if r[:2] == (track, kernels)]
    best = [r[2] for r in rows]
    failed = [r[3] for r in rows]
    print(f"{track}-{kernels}: mean best {statistics.mean(best):.2f} m/s, worst seed "
          f"{min(best):.2f}, failed laps {statistics.mean(failed):.1f} a run (max {max(failed)})")
