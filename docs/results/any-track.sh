#!/usr/bin/env bash
# Races every circuit of a folder with the configurations of docs/results/any-track.md, one
# run at a time at low priority, each run's summary kept as OUT/CONFIG/TRACK-sSEED.json (a run
# already there is skipped, so the script resumes). Usage:
#   docs/results/any-track.sh OUT "SEEDS" "CONFIGS" [TRACKS_DIR]
# CONFIGS from: recommended cdbo pattern-search budget10-METHOD (any method of `cdbo race`);
# NICE sets the niceness (default 19), CDBO the binary (default target/release/cdbo).
set -u
out=$1; seeds=$2; configs=$3; dir=${4:-../shared/tracks/csv}
cdbo=${CDBO:-target/release/cdbo}
for config in $configs; do
  case $config in
    recommended) args="--method safe-pattern-search --steering tracker --line min-curvature --max-failed-laps 30" ;;
    budget10-*) args="--method ${config#budget10-} --max-failed-laps 10" ;;
    *) args="--method $config" ;;
  esac
  mkdir -p "$out/$config"
  for seed in $seeds; do
    for file in "$dir"/*.csv; do
      track=$(basename "$file" .csv)
      json="$out/$config/$track-s$seed.json"
      [ -s "$json" ] && continue
      nice -n "${NICE:-19}" "$cdbo" race --track "$file" $args --seed "$seed" --laps 300 --kernels 30 \
        --json --out "$out/runs/$config-$track-s$seed" > "$json.tmp" 2> "$json.err" \
        && mv "$json.tmp" "$json"
    done
  done
done
