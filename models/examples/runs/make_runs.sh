#!/usr/bin/env bash
# Regenerate the blind GyroWheel calibration runs of this folder and their truths
# (models/examples/truth/runs/<name>.yaml), from the repository's root:
#   bash models/examples/runs/make_runs.sh [turntable-pin command, default .venv/bin/turntable-pin]
# Every run: the paper's table, grid:30 (144 positions), latitude 45.75 deg, noise 0.002 deg/h on
# both channels, 120 s per position, its own seed; the data say nothing of the truth.
set -euo pipefail
tp=${1:-.venv/bin/turntable-pin}
common=(--run --positions grid:30 --latitude-deg 45.75 --noise-dph 0.002 --dwell-s 120 --hide-truth)
make() {
    local name=$1
    shift
    "$tp" simulate "${common[@]}" "$@" -o "models/examples/runs/$name.csv" \
        --truth "models/examples/truth/runs/$name.yaml"
}
make run_clean --seed 101
make run_orthogonality --error deps_x=60 --seed 102
make run_inner_wobble --effect inner_wobble_harmonics:x_c1=60 --seed 103
make run_mount --effect instrument_tilt:mx=60,my=-40 --seed 104
make run_bias_drift --effect bias_drift:x=0.004,y=-0.003 --seed 105
make run_temperature --effect temperature_coefficient:x=0.003 --temperature 20,1,2.5,3 --seed 106
make run_g_squared --effect g_squared_terms:x_xz=0.03 --seed 107
make run_outliers --outliers 3 --seed 108
