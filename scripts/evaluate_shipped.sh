#!/usr/bin/env bash
# Every driving figure quoted in the README and the policy cards, from the shipped policies.
# Results land in out/eval/*.json, with each run's Markdown tables in out/eval/*.md.
#   scripts/evaluate_shipped.sh [SEEDS] [DRIVERS]
# SEEDS defaults to 0-49 (250 episodes per grid run); DRIVERS to all of
# "fast comfort krauss idm paper" (paper: the networks trained on the paper's rewards).
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${BIN:-.venv/bin}
SEEDS=${1:-0-49}
DRIVERS=" ${2:-fast comfort krauss idm paper} "
OUT=out/eval
mkdir -p "$OUT"
STOPS=60-75,150-165
run() {
  local name=$1; shift
  echo "== $name: explaindrive evaluate $*"
  "$BIN/explaindrive" evaluate "$@" --no-episodes --json "$OUT/$name.json" | tee "$OUT/$name.md"
}
wanted() { [[ $DRIVERS == *" $1 "* ]]; }

# The paper's grid (5 seeds x 5 traffic levels), shielded controller and baselines.
for p in fast comfort krauss idm; do wanted "$p" && run "${p}_25" "$p" --seeds 0-4; done
if wanted fast && wanted comfort; then
  run merged_25 merged --seeds 0-4 --commands "fast:0-90,stop:90-110,comfort:110-"
fi
# The bare networks and SUMO's Krauss and IDM on the same episodes: ten times the paper's
# grid, with and without stops, and a traffic level no policy was trained on.
for p in fast comfort krauss idm; do
  wanted "$p" || continue
  bare=(); [[ $p == fast || $p == comfort ]] && bare=(--no-shield)
  run "${p}_bare" "$p" --seeds "$SEEDS" "${bare[@]}"
  run "${p}_bare_stops" "$p" --seeds "$SEEDS" "${bare[@]}" --stop-schedule "$STOPS"
  run "${p}_bare_175" "$p" --seeds "$SEEDS" --traffic 1.75 "${bare[@]}"
  run "${p}_bare_175_stops" "$p" --seeds "$SEEDS" --traffic 1.75 "${bare[@]}" --stop-schedule "$STOPS"
done
# The networks trained on the paper's rewards (preset safe; shipped until commit PAPER_REF),
# bare, on the same episodes.
PAPER_REF=${PAPER_REF:-f1fcf2a}
if wanted paper; then
  for p in fast comfort; do
    dir=out/paper-rewards/$p
    mkdir -p "$dir"
    for f in pt json; do
      git show "$PAPER_REF:src/explaindrive/agent/policies/$p.$f" > "$dir/policy.$f"
    done
    run "${p}_paper_bare" "$dir" --seeds "$SEEDS" --no-shield
    run "${p}_paper_bare_stops" "$dir" --seeds "$SEEDS" --no-shield --stop-schedule "$STOPS"
  done
fi
# The bare networks with sensor noise on what they see.
for p in fast comfort; do
  wanted "$p" || continue
  for noise in 1,0.3 2,0.6 3,0.9; do
    run "${p}_bare_noise_${noise/,/_}" "$p" --seeds "$SEEDS" --no-shield --obs-noise "$noise"
  done
  run "${p}_bare_noise_1_0.3_stops" "$p" --seeds "$SEEDS" --no-shield --obs-noise 1,0.3 \
    --stop-schedule "$STOPS"
done
