#!/usr/bin/env bash
# An experiment, not the committed gains: the run's corner moved out of the bounding basin
# (docs/JOURNAL.md "The run's duty, tried after the walk"). From the committed gains file (its start-up
# gains included), the run's ankle balance reflex is unsaturated and its push softened by hand
# (a link of the chain with its provenance, set_by_hand), the landing yield started at 0.5,
# then CMA-ES stages of the run's corner (every gain, the yield included) over 4 and 8 tuning
# conditions of 10 s, and one over 8 conditions of 20 s (after the 10 s stages the run leaned
# further forward every stride and fell at 13-14 s, just after the tuned window), then one of
# the run's corner scored on the walk and the run with the walk guarded (g1). About 35
# minutes on 2 cores. Results: OUT/<stage>/ (default out/run_experiment). To drive the body
# with a result (the commands read the committed file):
#     python3 -c 'from cpgbiped.cpg.network import build; from cpgbiped.envs.gaits.validate
#     import validate; from cpgbiped.envs.control.controller import read_gains
#     print(validate(build("ml", "run"), "run", 20.0,
#                    params=read_gains("out/run_experiment/g1/gains.json")[0]).summary())'
# Usage: bash scripts/tune_run_experiment.sh [OUT]
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-out/run_experiment}
mkdir -p "$OUT/set"
ALL=$(python3 -c "from cpgbiped.envs.control.control_kernel import BLENDED; print(','.join(BLENDED))")
python3 scripts/run_unsaturated.py envs/control/gains.json "$OUT/set/gains.json"
prev="$OUT/set/gains.json"
stage() {  # stage NAME ARGS...: one tune run started from the previous stage's gains
  local name=$1; shift
  echo "tune_run_experiment: $name: cpgbiped tune $* --start $prev"
  cpgbiped tune --pop 16 "$@" --start "$prev" --out "$OUT/$name" --quiet
  prev="$OUT/$name/gains.json"
}
stage r2 --gait run --conditions 4 --gens 80 --sigma 0.1 --seed 53 --only "$ALL"
stage r3 --gait run --conditions 8 --gens 100 --sigma 0.06 --seed 54 --only "$ALL"
stage r5 --gait run --conditions 8 --gens 40 --sigma 0.04 --seconds 20 --seed 57 --only "$ALL"
# The run's corner once more, with the walk guarded against the committed gains (the walk's
# start-up blends a quarter of every corner), 20 s windows: the candidate for adoption.
stage g1 --gait walk,run --only 'alternating_coactive.*' --guard walk \
    --guard-gains envs/control/gains.json --conditions 1-8 --seconds 20 --gens 20 --sigma 0.03 \
    --seed 58
echo "tune_run_experiment: gains in $prev"
