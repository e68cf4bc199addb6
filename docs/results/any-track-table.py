"""Tabulates the runs of docs/results/any-track.sh: per circuit and configuration, the mean
over the seeds found of the best lap as % of the centre-line limit, the best against the
demonstration, the failed laps (largest), the first completed lap (latest) and the runs that
never completed one. Usage: python3 docs/results/any-track-table.py OUT CONFIG..."""

import json
import pathlib
import statistics
import sys


def runs(out, config):
    by_track = {}
    for f in sorted(pathlib.Path(out, config).glob("*.json")):
        track, _, _ = f.stem.rpartition("-s")
        by_track.setdefault(track, []).append(json.loads(f.read_text()))
    return by_track


def first_completed(summary):
    laps = pathlib.Path(summary["out"], "laps.csv").read_text().splitlines()[1:]
    for row in laps:
        cells = row.split(",")
        if float(cells[1]) > 0:
            return int(cells[0])
    return None


def main(out, configs):
    for config in configs:
        table = runs(out, config)
        print(f"\n{config} (seeds: {max((len(v) for v in table.values()), default=0)} a circuit)\n")
        print("| circuit | best / centre-line limit | best / demonstration | demonstration | failed laps (max) | first completed lap (latest) | no lap completed | wall (s) |")
        print("| --- | --- | --- | --- | --- | --- | --- | --- |")
        fractions, ratios = [], []
        for track, summaries in sorted(table.items()):
            f = [s["best_fraction_of_limit"] for s in summaries]
            r = [s["best_reward_mps"] / s["demo_reward_mps"] for s in summaries]
            firsts = [first_completed(s) for s in summaries]
            fractions += f
            ratios += r
            print(
                f"| {track} | {100 * statistics.mean(f):.1f} % (lowest {100 * min(f):.1f}) "
                f"| {statistics.mean(r):.2f}x (lowest {min(r):.2f}) "
                f"| {statistics.mean(s['demo_speed_mps'] for s in summaries):.2f} m/s "
                f"| {max(s['failed_laps'] for s in summaries)} "
                f"| {max((x for x in firsts if x), default='-')} "
                f"| {sum(x is None for x in firsts)} "
                f"| {statistics.mean(s['wall_s'] for s in summaries):.1f} |"
            )
        if fractions:
            print(
                f"| **all** | **{100 * statistics.mean(fractions):.1f} %** (lowest {100 * min(fractions):.1f}) "
                f"| {statistics.mean(ratios):.2f}x (lowest {min(ratios):.2f}) | | | | | |"
            )


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2:])
