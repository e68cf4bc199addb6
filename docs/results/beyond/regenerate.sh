#!/bin/sh
# Regenerates docs/results/beyond from scratch: every run of experiment.toml (96 runs, 6 seeds
# x 300 laps, the PI steering) into runs/beyond and of tracker/experiment.toml (48 runs, the
# path tracker) into runs/beyond-tracker, then each grid's report (results.md, table1.md, the
# figures) beside its experiment.toml. The old runs are removed first: `cdbo experiment`
# resumes a folder, and would otherwise keep runs made by an older learner. Run from the
# repository's root:
#   nice -n 5 sh docs/results/beyond/regenerate.sh
# CDBO: the binary (default target/release/cdbo); DATA: the data folder (default ../shared);
# JOBS: parallel runs (default 2).
set -eu
cdbo=${CDBO:-target/release/cdbo}
data=${DATA:-../shared}
grid() { # grid FOLDER RUNS
  rm -rf "$2"
  "$cdbo" experiment "$1/experiment.toml" --data-dir "$data" --out "$2" --jobs "${JOBS:-2}"
  "$cdbo" report "$2" --data-dir "$data" --out "$1"
}
grid docs/results/beyond runs/beyond
grid docs/results/beyond/tracker runs/beyond-tracker
