#!/bin/sh
# Regenerates docs/results/beyond from scratch: every run of experiment.toml (96 runs, 6 seeds
# x 300 laps) into runs/beyond, then the report (results.md, table1.md, the figures) here.
# The old runs are removed first: `cdbo experiment` resumes a folder, and would otherwise keep
# runs made by an older learner. Run from the repository's root:
#   nice -n 5 sh docs/results/beyond/regenerate.sh
# CDBO: the binary (default target/release/cdbo); DATA: the data folder (default ../shared);
# JOBS: parallel runs (default 2).
set -eu
cdbo=${CDBO:-target/release/cdbo}
data=${DATA:-../shared}
rm -rf runs/beyond
"$cdbo" experiment docs/results/beyond/experiment.toml --data-dir "$data" --out runs/beyond --jobs "${JOBS:-2}"
"$cdbo" report runs/beyond --data-dir "$data" --out docs/results/beyond
