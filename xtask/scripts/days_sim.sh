#!/bin/bash
# An effect carried to another day (docs/results/days.md). Usage:
#   xtask/scripts/days_sim.sh CALIB ROBOT EFFECTS.ron SEED OUTDIR
# Simulates day 0 (300 full-pose rows, the cell from 20 degC warming by 3 degC) and days 1, 2, 3
# and 8 (200 rows each at 30, 10, 21 and 33 degC: `--temp-c` 27, 7, 18, 30 plus the warm-up),
# fits `poe-gp` with and without `--effects auto` on day 0, then on each later day registers the
# base on its first 30 rows (`calib register`, as a user would after setting the tracker up
# again) and evaluates on the other 170. Prints one line per method: the later days' mean
# position error, mm. METHODS and DAYS override the defaults below.
set -e
CALIB=$(realpath "$1"); ROBOT=$(realpath "$2"); EFFECTS=$(realpath "$3"); SEED=$4; OUT=$5
METHODS=${METHODS:-"poe-gp:none poe-gp:auto"}
DAYS=${DAYS:-"1:27 2:7 3:18 8:30"}
mkdir -p "$OUT"; cd "$OUT"
sim() { "$CALIB" simulate --robot "$ROBOT" --full-pose --effects "$EFFECTS" --seed "$SEED" "$@" >/dev/null; }
sim --out d0.csv --rows 300
for dt in $DAYS; do
    d=${dt%%:*}; t=${dt##*:}
    sim --out "d$d.csv" --rows 200 --day "$d" --temp-c "$t"
    (head -1 "d$d.csv"; sed -n 2,31p "d$d.csv") > "d$d.reg.csv"
    (head -1 "d$d.csv"; sed -n 32,201p "d$d.csv") > "d$d.test.csv"
done
for me in $METHODS; do
    m=${me%%:*}; e=${me##*:}
    effects=(); [ "$e" = none ] || effects=(--effects "$e")
    "$CALIB" fit --robot "$ROBOT" --data d0.csv --method "$m" "${effects[@]}" --out "$m.$e.ron" --json \
        > "$m.$e.fit.json" 2> "$m.$e.fit.err"
    line="seed $SEED $m $e:"
    for dt in $DAYS; do
        d=${dt%%:*}
        "$CALIB" register --model "$m.$e.ron" --data "d$d.reg.csv" --out "$m.$e.d$d.ron" >/dev/null 2>&1
        v=$("$CALIB" eval --model "$m.$e.d$d.ron" --data "d$d.test.csv" --json 2>/dev/null |
            python3 -c 'import json,sys; print("%.4f" % json.load(sys.stdin)["mean_position_error_mm"])')
        line="$line d$d $v"
    done
    echo "$line"
done
