#!/usr/bin/env bash
# An experiment, not the committed gains: a jump with a countermovement, searched while the
# walk scores it (docs/JOURNAL.md "The jump's falls, traced and tried"). From stage w4 of
# scripts/tune_gains.sh (the gains before the jump was adopted; START),
# by hand (links of the chain with their provenance, set_by_hand): the jump's corner aims the
# thighs straight down (theta0 0; 0.22 put every landing ahead of the centre of mass), crouches
# to -0.5 rad outside the extensor burst (it stood at -0.15: the legs stayed straight) and holds
# the trunk nearer upright (pitch target 0.1 rad, was 0.24). Then a CMA-ES stage of the jump's
# corner scored on the jump alone (8 conditions), and one of the same corner scored on the walk
# and the jump (conditions 1-8 and 21-24, whose CPG states start the walk network in a jump's
# rhythm); then two stages of the walk's corner (w5, w6). About 45 minutes on 2 cores.
# Results: OUT/<stage>/ (default out/jump_experiment); drive the body with one as
# scripts/tune_run_experiment.sh says.
# Usage: bash scripts/tune_jump_experiment.sh [OUT] [START]
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-out/jump_experiment}
START=${2:-out/tune_chain/w4/gains.json}
if [ ! -f "$START" ]; then
  echo "tune_jump_experiment: $START is missing: it starts from the chain's stage w4 (the gains" >&2
  echo "before the jump was adopted); run scripts/tune_gains.sh, or name a start file" >&2
  exit 2
fi
python3 scripts/jump_countermovement.py "$START" "$OUT"
prev="$OUT/set2/gains.json"
stage() {  # stage NAME ARGS...: one tune run started from the previous stage's gains
  local name=$1; shift
  echo "tune_jump_experiment: $name: cpgbiped tune $* --start $prev"
  cpgbiped tune "$@" --start "$prev" --out "$OUT/$name" --quiet
  prev="$OUT/$name/gains.json"
}
stage j1 --gait jump --conditions 8 --gens 60 --pop 24 --sigma 0.2 --seed 62
stage j2 --gait walk,jump --only 'synchronous.*' --conditions 1-8,21-24 --gens 30 --pop 16 --sigma 0.05 --seed 63
# Then the walk's corner, to win back the walk (README: after j2 it passed 11/13 test conditions
# and fell from 2 of 30 census states): scored with the jump over every Morris-Lecar and
# transient condition (no walk falls in the tests, but its duty sinks to the criterion's edge),
# then the walk alone on a finer step. About 20 minutes more.
stage w5 --gait walk,jump --only 'alternating.*' --conditions 1-16,21-24 --gens 20 --pop 16 --sigma 0.05 --seed 66
stage w6 --gait walk --only 'alternating.*' --conditions 1-8,21-24 --gens 20 --pop 16 --sigma 0.03 --seed 67
echo "tune_jump_experiment: gains in $prev"
