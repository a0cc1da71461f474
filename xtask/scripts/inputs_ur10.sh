#!/usr/bin/env bash
# The UR10's own signals as GP inputs and as weights: series B and C,
# even → odd rows and early → late (the first half of the series in file order against the
# second), poe-gp four ways: plain, --inputs temp_c, the tracker's stated σ as weights (std_*
# columns), both. Prints one line per fit with the held-out mean errors.
#
#   xtask/scripts/inputs_ur10.sh CALIB DIR
#
# DIR holds {B,C}_{even,odd,early,late}.csv with the std_* columns (`cargo xtask convert-ur10`
# keeps them) and the same files without them as *_plain.csv.
set -u
calib=$(realpath "$1")
dir=$(realpath "$2")
robot=$(realpath "$(dirname "$0")/../../fixtures/robots/ur10.ron")
mkdir -p "$dir/runs"
for s in C B; do
    for split in "even odd" "early late"; do
        set -- $split
        for v in plain temp std stdtemp; do
            case $v in
                plain | temp) train=$dir/${s}_$1_plain.csv test=$dir/${s}_$2_plain.csv ;;
                *) train=$dir/${s}_$1.csv test=$dir/${s}_$2.csv ;;
            esac
            extra=()
            case $v in *temp) extra=(--inputs temp_c) ;; esac
            out=$dir/runs/${s}_$1_$v
            "$calib" fit --robot "$robot" --data "$train" --method poe-gp "${extra[@]}" --out "$out.ron" --json >"$out.json" 2>"$out.err"
            "$calib" eval --model "$out.ron" --data "$test" --json 2>/dev/null |
                python3 -c "import json,sys; d=json.load(sys.stdin); print('$s $1->$2 $v: %.4f mm %.4f mrad' % (d['mean_position_error_mm'], d['mean_rotation_error_mrad'] or 0))"
        done
    done
done
