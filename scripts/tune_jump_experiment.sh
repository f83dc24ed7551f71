#!/usr/bin/env bash
# An experiment, not the committed gains: a jump with a countermovement, searched while the
# walk scores it (README "The jump's falls, traced and tried"). From the committed gains file,
# by hand (links of the chain with their provenance, set_by_hand): the jump's corner aims the
# thighs straight down (theta0 0; 0.22 put every landing ahead of the centre of mass), crouches
# to -0.5 rad outside the extensor burst (it stood at -0.15: the legs stayed straight) and holds
# the trunk nearer upright (pitch target 0.1 rad, was 0.24). Then a CMA-ES stage of the jump's
# corner scored on the jump alone (8 conditions), and one of the same corner scored on the walk
# and the jump (conditions 1-8 and 21-24, whose CPG states start the walk network in a jump's
# rhythm); then two stages of the walk's corner (w5, w6). About 45 minutes on 2 cores.
# Results: OUT/<stage>/ (default out/jump_experiment); drive the body with one as
# scripts/tune_run_experiment.sh says.
# Usage: bash scripts/tune_jump_experiment.sh [OUT]
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-out/jump_experiment}
mkdir -p "$OUT/set1" "$OUT/set2"
python3 - "$OUT" <<'PY'
import sys
from cpgbiped.envs.search.controller_tuning import set_by_hand
out = sys.argv[1]
set_by_hand("envs/control/gains.json", {"synchronous.theta0": 0.0}, f"{out}/set1/gains.json",
            "the jump corner aims the thighs straight down (theta0 0.22 put each landing ahead "
            "of the centre of mass: backward drift and falls)")
set_by_hand(f"{out}/set1/gains.json", {"synchronous.knee_crouch": -0.5,
                                       "synchronous.pitch_d": 0.1}, f"{out}/set2/gains.json",
            "a countermovement: the jump corner crouches to -0.5 rad outside the extensor burst "
            "(it stood at -0.15: the legs stayed straight and only the ankles pushed), with the "
            "trunk nearer upright (pitch target 0.1 rad, was 0.24) so that the take-off does "
            "not pitch it forward")
PY
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
