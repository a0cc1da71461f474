#!/usr/bin/env bash
# Runs the calib CLI over the fixtures and simulated data and keeps every output, so that two
# builds can be compared byte for byte (a change that is not meant to change the CLI's outputs
# leaves them byte-identical on the fixtures):
#
#   xtask/scripts/golden.sh BEFORE_BINARY /tmp/golden-before
#   xtask/scripts/golden.sh target/debug/calib /tmp/golden-after
#   diff -r --no-dereference /tmp/golden-before /tmp/golden-after && echo BYTE-IDENTICAL
#
# Each step writes NAME.out (stdout), NAME.err (stderr) and NAME.rc (exit code), and the files it
# writes (CSV, RON, URDF, report) under the same directory. Wall times are printed by no command.
set -u
calib=$(realpath "$1")
out=$(realpath -m "$2")
repo=$(realpath "$(dirname "$0")/../..")
rm -rf "$out" && mkdir -p "$out"
# Relative paths only, so that the outputs do not name the directory they were made in.
ln -s "$repo/fixtures" "$out/fixtures"
cd "$out"
run() {
    local name=$1
    shift
    "$@" >"$name.out" 2>"$name.err"
    echo $? >"$name.rc"
}
irb=fixtures/robots/irb4400.ron
iiwa=fixtures/robots/iiwa7.ron

# Data: position-only, full pose, payloads with torques, a 7-axis campaign shape, a URDF robot.
run sim_pos "$calib" simulate --robot $irb --out "pos.csv" --rows 150 --seed 1
run sim_full "$calib" simulate --robot $irb --out "full.csv" --rows 150 --seed 2 --full-pose
run sim_test "$calib" simulate --robot $irb --out "test.csv" --rows 60 --seed 3 --full-pose
run sim_load "$calib" simulate --robot $irb --out "load.csv" --rows 200 --seed 4 --full-pose \
    --payloads 0,10,20 --torques
run sim_iiwa "$calib" simulate --robot $iiwa --out "iiwa.csv" --rows 120 --seed 5 --full-pose \
    --moving-joints 1,2 --fixed-jitter-mrad 2 --payloads 0,2.5,5 --tool-per-payload --torques
echo "()" >no_effects.ron
run sim_urdf "$calib" simulate --robot fixtures/robots/ur10.ron --out "urdf.csv" --rows 100 --seed 6 --effects no_effects.ron

# Every method on full-pose data, evaluated and predicted.
for method in base-tool poe poe-gp poe-gp-load; do
    run "fit_$method" "$calib" fit --robot $irb --data "full.csv" --method $method --out "$method.ron" --json
    run "eval_$method" "$calib" eval --model "$method.ron" --data "test.csv" --json
    run "evaltext_$method" "$calib" eval --model "$method.ron" --data "test.csv"
    run "predict_$method" "$calib" predict --model "$method.ron" --data "test.csv"
done
run fit_pos "$calib" fit --robot $irb --data "pos.csv" --method poe --out "pos.ron"
run eval_pos "$calib" eval --model "pos.ron" --data "pos.csv" --json

# Effects, named and chosen, with payloads and torques.
run fit_effects "$calib" fit --robot $irb --data "load.csv" --method poe \
    --effects joint_compliance,gear_periodic:2:4,backlash:3 --out "effects.ron" --json
run eval_effects "$calib" eval --model "effects.ron" --data "load.csv" --json
run predict_effects "$calib" predict --model "effects.ron" --data "load.csv"
run fit_auto "$calib" fit --robot $irb --data "load.csv" --method poe-gp-load --effects auto \
    --out "auto.ron" --json
run eval_auto "$calib" eval --model "auto.ron" --data "load.csv"
run fit_iiwa "$calib" fit --robot $iiwa --data "iiwa.csv" --method poe --effects auto --out "iiwa.ron"
run eval_iiwa "$calib" eval --model "iiwa.ron" --data "iiwa.csv" --json
run fit_urdf "$calib" fit --robot fixtures/robots/ur10.urdf --data "urdf.csv" --method poe --out "urdf.ron"

# The diagnosis, with its report directory.
run diagnose "$calib" diagnose --robot $irb --data "load.csv" --json
run diagnose_text "$calib" diagnose --robot $irb --data "load.csv" --report "diagnosis"

# The cell side: export, compensate, register, plan, report.
run export "$calib" export --model "poe.ron" --urdf "poe.urdf" --like fixtures/robots/irb4400.urdf --json
run compensate "$calib" compensate --model "poe.ron" --targets "test.csv"
head -n 21 "test.csv" >"few.csv"
run register "$calib" register --model "poe.ron" --data "few.csv" --out "moved.ron" --refit base,tools --json
run plan "$calib" plan --robot $irb --generate 400 --poses 12 --seed 7 --out "chosen.csv" --json
run report "$calib" report --model "effects.ron" --data "load.csv" --out "report"

# Refusals: a missing file, a bad effect item.
run refuse_file "$calib" fit --robot $irb --data "missing.csv" --method poe --out "x.ron"
run refuse_effect "$calib" fit --robot $irb --data "full.csv" --method poe --effects gear_periodic:2 --out "x.ron"

# The one wall time a command prints: `report`'s drawing time.
sed -i -E 's/[0-9.]+ s in all, [0-9.]+ s to draw/(time) s in all, (time) s to draw/' report.out
# `fit`'s phase times: the JSON's `timings` and the text's phases of a second or more.
for f in *.out *.err; do
    sed -i -E 's/,"timings":\[[^]]*\]//' "$f"
    sed -i '/^  time (phases of a second or more):$/,/^  wrote /{/^  wrote /!d}' "$f"
done
