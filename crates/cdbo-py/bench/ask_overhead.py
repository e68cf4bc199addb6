"""The binding's per-suggestion overhead: the wall time of `Optimizer.ask()` seen from Python
against the time the library spends in its own `ask` (`Optimizer.last_ask_s`), both in the
same call, for CDBO with 100 weights after 300 observations.

    python crates/cdbo-py/bench/ask_overhead.py [--dim 100] [--observations 300] [--repeats 30]

Each repeat loads the same saved optimiser and asks once, so every repeat times the same
suggestion. Prints the medians and the overhead (python - library) / library.
"""

import argparse
import statistics
import time

import numpy as np

import cdbo


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--method", default="cdbo")
    p.add_argument("--dim", type=int, default=100)
    p.add_argument("--observations", type=int, default=300)
    p.add_argument("--repeats", type=int, default=30)
    args = p.parse_args()
    rng = np.random.default_rng(0)
    centre = rng.uniform(-0.5, 0.5, args.dim)
    opt = cdbo.Optimizer(args.method, np.zeros(args.dim), seed=0)
    for _ in range(args.observations):
        w = opt.ask()
        opt.tell(w, -float(np.sum((w - centre) ** 2)))
    state = opt.save()
    wall, library = [], []
    for _ in range(args.repeats):
        o = cdbo.Optimizer.load(state)
        t0 = time.perf_counter()
        o.ask()
        wall.append(time.perf_counter() - t0)
        library.append(o.last_ask_s)
    overhead = [(w - r) / r for w, r in zip(wall, library)]
    print(
        f"{args.method}, {args.dim} weights, {args.observations} observations, "
        f"{args.repeats} repeats: ask from Python {1e3 * statistics.median(wall):.3f} ms, "
        f"in the library {1e3 * statistics.median(library):.3f} ms, "
        f"binding overhead {1e6 * statistics.median([w - r for w, r in zip(wall, library)]):.1f} us "
        f"= {100 * statistics.median(overhead):.3f} % (median)"
    )


if __name__ == "__main__":
    main()
