"""`bench peers`: race published optimisers on cdbo's simulator through `cdbo serve-sim`,
under the budget, start and box cdbo's own methods get: pycma (active CMA-ES, σ₀ given,
bounded to the box) and Optuna's TPE (the box as each weight's range).

    python crates/cdbo-py/bench/peers.py --track forza --kernels 50 --laps 300 --seeds 0-1 \\
        [--methods cma,tpe] [--sigma0 0.03] [--cdbo target/release/cdbo] [--data-dir ../shared]

Every run's lap 1 is w₀ (the demonstration's fitted policy, as for `cdbo race`); the
optimiser then gets the remaining laps; a failed lap's reward is 0, as for every cdbo
method. Optional: needs `pip install cma optuna`; a method whose package is missing is
skipped with a message. Prints one line per run and the mean best reward and failed laps per
method (JSON with --json).
"""

import argparse
import json
import statistics
import subprocess
import sys


class Laps:
    """A `cdbo serve-sim` process and a lap budget."""

    def __init__(self, cdbo, args, budget):
        self.proc = subprocess.Popen(
            [cdbo, "serve-sim", *args],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
        )
        self.info = self.request({"info": True})
        self.budget = budget
        self.driven = 0
        self.failed = 0
        self.best = 0.0

    def request(self, message):
        self.proc.stdin.write(json.dumps(message) + "\n")
        self.proc.stdin.flush()
        line = self.proc.stdout.readline()
        if not line:
            sys.exit(f"cdbo serve-sim ended: {self.proc.wait()}")
        answer = json.loads(line)
        if "error" in answer:
            raise RuntimeError(answer["error"])
        return answer

    def left(self):
        return self.budget - self.driven

    def lap(self, weights):
        """The reward of one lap (0 if it failed), counted against the budget."""
        assert self.left() > 0
        lo, hi = self.info["lower"], self.info["upper"]
        w = [min(max(float(v), a), b) for v, a, b in zip(weights, lo, hi)]
        reply = self.request({"weights": w})
        self.driven += 1
        self.failed += reply["failure"] is not None
        self.best = max(self.best, reply["reward_mps"])
        return reply["reward_mps"]

    def close(self):
        self.proc.stdin.close()
        self.proc.wait()


def run_cma(laps, seed, sigma0):
    import cma

    laps.lap(laps.info["w0"])
    es = cma.CMAEvolutionStrategy(
        laps.info["w0"],
        sigma0,
        {
            "bounds": [laps.info["lower"], laps.info["upper"]],
            "CMA_active": True,
            "seed": seed + 1,  # pycma's seed 0 means "from the clock"
            "verbose": -9,
        },
    )
    while laps.left() > 0:
        xs = es.ask()
        fs = []
        for x in xs:
            if laps.left() == 0:
                return
            fs.append(-laps.lap(x))
        es.tell(xs, fs)


def run_tpe(laps, seed, _sigma0):
    import optuna

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    lo, hi = laps.info["lower"], laps.info["upper"]
    names = [f"w{i}" for i in range(len(lo))]
    study = optuna.create_study(
        direction="maximize", sampler=optuna.samplers.TPESampler(seed=seed)
    )
    study.enqueue_trial(dict(zip(names, laps.info["w0"])))

    def objective(trial):
        return laps.lap([trial.suggest_float(n, a, b) for n, a, b in zip(names, lo, hi)])

    study.optimize(objective, n_trials=laps.left())


METHODS = {"cma": ("cma", run_cma), "tpe": ("optuna", run_tpe)}


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--track", default="forza")
    p.add_argument("--kernels", type=int, default=50)
    p.add_argument("--laps", type=int, default=300)
    p.add_argument("--seeds", default="0-1", help="FIRST-LAST")
    p.add_argument("--methods", default="cma,tpe")
    p.add_argument("--sigma0", type=float, default=0.03, help="pycma's σ₀")
    p.add_argument("--cdbo", default="cdbo", help="the cdbo binary")
    p.add_argument("--data-dir", default="../shared")
    p.add_argument("--json", action="store_true")
    args = p.parse_args()
    first, _, last = args.seeds.partition("-")
    seeds = range(int(first), int(last or first) + 1)
    sim_args = ["--track", args.track, "--kernels", str(args.kernels)]
    sim_args += ["--data-dir", args.data_dir]
    results = {}
    for name in args.methods.split(","):
        if name not in METHODS:
            sys.exit(f"--methods: unknown method {name!r}; choose from {', '.join(METHODS)}")
        package, run = METHODS[name]
        try:
            __import__(package)
        except ImportError:
            print(f"{name}: skipped, `pip install {package}` to run it", file=sys.stderr)
            continue
        for seed in seeds:
            laps = Laps(args.cdbo, sim_args, args.laps)
            run(laps, seed, args.sigma0)
            laps.close()
            row = {"method": name, "seed": seed, "best_mps": laps.best,
                   "failed": laps.failed, "laps": laps.driven}
            results.setdefault(name, []).append(row)
            if args.json:
                print(json.dumps(row))
            else:
                print(f"{name} {args.track}-{args.kernels} seed {seed}: best {laps.best:.2f} "
                      f"m/s, {laps.failed} of {laps.driven} laps failed", flush=True)
    for name, rows in results.items():
        best = [r["best_mps"] for r in rows]
        se = statistics.stdev(best) / len(best) ** 0.5 if len(best) > 1 else 0.0
        failed = statistics.mean(r["failed"] for r in rows)
        summary = {"method": name, "track": args.track, "kernels": args.kernels,
                   "runs": len(rows), "mean_best_mps": statistics.mean(best), "se": se,
                   "mean_failed": failed}
        if args.json:
            print(json.dumps(summary))
        else:
            print(f"{name}: {statistics.mean(best):.2f} ± {se:.2f} m/s over {len(rows)} runs, "
                  f"{failed:.0f} failed laps per run")


if __name__ == "__main__":
    main()
