#!/usr/bin/env bash
# Every evaluation figure quoted in the README and in the policy cards, from the shipped
# policies. Results land in out/eval/*.json (and a Markdown table per run on stdout).
#   scripts/evaluate_shipped.sh [SEEDS_FOR_THE_LARGE_GRID]   (default 0-49: 250 episodes each)
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${BIN:-.venv/bin}
LARGE=${1:-0-49}
OUT=out/eval
mkdir -p "$OUT"
STOPS=60-75,150-165
run() { local name=$1; shift; echo "== $name: explaindrive evaluate $*"; "$BIN/explaindrive" evaluate "$@" --json "$OUT/$name.json"; }

# The paper's grid: 5 seeds x 5 traffic levels.
run fast_25 fast --seeds 0-4
run comfort_25 comfort --seeds 0-4
run fast_stops_25 fast --seeds 0-4 --stop-schedule "$STOPS"
run comfort_stops_25 comfort --seeds 0-4 --stop-schedule "$STOPS"
run fast_noshield_25 fast --seeds 0-4 --no-shield
run comfort_noshield_25 comfort --seeds 0-4 --no-shield
run krauss_25 krauss --seeds 0-4
run idm_25 idm --seeds 0-4
# Far more episodes, with the paper's stop injections.
run fast_large fast --seeds "$LARGE" --stop-schedule "$STOPS"
run comfort_large comfort --seeds "$LARGE" --stop-schedule "$STOPS"
run merged_large merged --seeds "$LARGE" --commands "fast:0-90,stop:90-110,comfort:110-"
