#!/usr/bin/env bash
# The scenario family's grid: the shipped networks, bare, and SUMO's Krauss on generated
# scenarios held out from training, and on a netgenerate grid with trips generated over it.
# Results land in out/family/*.json, with each run's Markdown tables in out/family/*.md.
#   [ROAD_SEEDS=0-99] [GRID_SEEDS=0-19] scripts/evaluate_family.sh [SCENARIOS] [SEEDS] [DRIVERS]
# SCENARIOS defaults to random:100-119, SEEDS to 0-4 and DRIVERS to "fast comfort krauss";
# traffic levels 0.5, 1.0 and 1.75, with and without stops at 60-75 and 150-165 s.
# The reference is the paper's road (road_*, with and without the stops) at the same levels
# on ROAD_SEEDS, as many episodes as the family by default (20 scenarios x 5 seeds); the
# grid runs on GRID_SEEDS.
# python scripts/family_ratios.py [out/family] prints every figure beside the reference.
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${BIN:-.venv/bin}
SCENARIOS=${1:-random:100-119}
SEEDS=${2:-0-4}
DRIVERS=" ${3:-fast comfort krauss} "
ROAD_SEEDS=${ROAD_SEEDS:-0-99}
GRID_SEEDS=${GRID_SEEDS:-0-19}
LEVELS=0.5,1.0,1.75
STOPS=60-75,150-165
OUT=out/family
mkdir -p "$OUT"
run() {
  local name=$1; shift
  echo "== $name: explaindrive evaluate $*"
  "$BIN/explaindrive" evaluate "$@" --no-episodes --json "$OUT/$name.json" > "$OUT/$name.md"
}
wanted() { [[ $DRIVERS == *" $1 "* ]]; }

# netgenerate's grid of the worked example in docs/scenario.md: the route A1B1 -> D1E1 runs
# through the lights B1, C1 and D1; without --demand the env generates trips over the grid.
export SUMO_HOME=${SUMO_HOME:-$("$BIN/python" -c "import sumo; print(sumo.SUMO_HOME)")}
GRID=$OUT/grid.net.xml
[[ -f $GRID ]] || "$SUMO_HOME/bin/netgenerate" --grid --grid.number 5 --grid.length 200 \
  --default-junction-type traffic_light --tls.default-type static --no-turnarounds true \
  -o "$GRID" > /dev/null

for p in fast comfort krauss; do
  wanted "$p" || continue
  bare=(); [[ $p == fast || $p == comfort ]] && bare=(--no-shield)
  run "road_${p}" "$p" --seeds "$ROAD_SEEDS" --traffic "$LEVELS" "${bare[@]}"
  run "road_${p}_stops" "$p" --seeds "$ROAD_SEEDS" --traffic "$LEVELS" "${bare[@]}" \
    --stop-schedule "$STOPS"
  run "family_${p}" "$p" --scenarios "$SCENARIOS" --seeds "$SEEDS" --traffic "$LEVELS" "${bare[@]}"
  run "family_${p}_stops" "$p" --scenarios "$SCENARIOS" --seeds "$SEEDS" --traffic "$LEVELS" \
    "${bare[@]}" --stop-schedule "$STOPS"
  run "grid_${p}" "$p" --net "$GRID" --route A1B1,D1E1 --seeds "$GRID_SEEDS" \
    --traffic "$LEVELS" "${bare[@]}"
  run "grid_${p}_stops" "$p" --net "$GRID" --route A1B1,D1E1 --seeds "$GRID_SEEDS" \
    --traffic "$LEVELS" "${bare[@]}" --stop-schedule "$STOPS"
done
