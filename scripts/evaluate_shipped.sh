#!/usr/bin/env bash
# Every driving figure quoted in the README and the policy cards, from the shipped policies.
# Results land in out/eval/*.json, with each run's Markdown tables in out/eval/*.md.
#   scripts/evaluate_shipped.sh [SEEDS]   (default 0-49: 250 episodes per grid run)
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${BIN:-.venv/bin}
SEEDS=${1:-0-49}
OUT=out/eval
mkdir -p "$OUT"
STOPS=60-75,150-165
run() {
  local name=$1; shift
  echo "== $name: explaindrive evaluate $*"
  "$BIN/explaindrive" evaluate "$@" --no-episodes --json "$OUT/$name.json" | tee "$OUT/$name.md"
}

# The paper's grid (5 seeds x 5 traffic levels), shielded controller and baselines.
for p in fast comfort krauss idm; do run "${p}_25" "$p" --seeds 0-4; done
run merged_25 merged --seeds 0-4 --commands "fast:0-90,stop:90-110,comfort:110-"
# The bare networks on ten times the paper's episodes, with and without stops, and on a
# traffic level they were never trained on; then the shielded controller on the same grids.
for p in fast comfort; do
  run "${p}_bare" "$p" --seeds "$SEEDS" --no-shield
  run "${p}_bare_stops" "$p" --seeds "$SEEDS" --no-shield --stop-schedule "$STOPS"
  run "${p}_bare_175" "$p" --seeds "$SEEDS" --traffic 1.75 --no-shield
  run "${p}_bare_175_stops" "$p" --seeds "$SEEDS" --traffic 1.75 --no-shield --stop-schedule "$STOPS"
  run "${p}_shielded" "$p" --seeds "$SEEDS"
  run "${p}_shielded_stops" "$p" --seeds "$SEEDS" --stop-schedule "$STOPS"
done
run krauss_large krauss --seeds "$SEEDS"
run krauss_175 krauss --seeds "$SEEDS" --traffic 1.75
run idm_large idm --seeds "$SEEDS"
run merged_large merged --seeds "$SEEDS" --commands "fast:0-90,stop:90-110,comfort:110-"
