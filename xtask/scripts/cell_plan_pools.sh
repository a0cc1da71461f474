#!/bin/bash
# `calib plan`: planned against random poses over many candidate pools, not one design. Usage (from the
# worktree root, release build): [OPTS='PLAN_OPTIONS_RON'] xtask/scripts/cell_plan_pools.sh SERIES N POOLS
# Pool p is a random half of the series' even rows (Python random.seed(1000 + p)). From each pool: N rows
# planned with the nominal geometry (`--full-pose`), N planned with `--model` (`poe` fitted on all the
# even rows), and 5 random draws of N (random.seed(1..5)); `poe` fitted on each, mean position error
# on the series' odd rows printed. One line per pool.
C=${CALIB:-target/release/calib}; R=fixtures/robots/ur10.ron; D=${DATA:-/work/data}; S=$1; N=$2; T=$(mktemp -d)
ev() { $C eval --model $1 --data $D/ur10_${S}_full_odd.csv --json 2>/dev/null | python3 -c "import json,sys; print('%.4f' % json.load(sys.stdin)['mean_position_error_mm'])"; }
$C fit --robot $R --data $D/ur10_${S}_full_even.csv --method poe --out $T/even.ron >/dev/null 2>&1
echo "${OPTS:-()}" > $T/o.ron
for p in $(seq 1 $3); do
  python3 - $D/ur10_${S}_full_even.csv $p $T/pool.csv <<'PY'
import sys, random
lines = open(sys.argv[1]).read().splitlines(); head, rows = lines[0], lines[1:]
random.seed(1000+int(sys.argv[2])); pick = sorted(random.sample(range(len(rows)), len(rows)//2))
open(sys.argv[3], 'w').write('\n'.join([head] + [rows[i] for i in pick]) + '\n')
PY
  $C plan --robot $R --candidates $T/pool.csv --poses $N --full-pose --options $T/o.ron --out $T/c.csv >/dev/null 2>&1
  $C fit --robot $R --data $T/c.csv --method poe --out $T/m.ron >/dev/null 2>&1; nom=$(ev $T/m.ron)
  $C plan --robot $R --model $T/even.ron --candidates $T/pool.csv --poses $N --options $T/o.ron --out $T/c.csv >/dev/null 2>&1
  $C fit --robot $R --data $T/c.csv --method poe --out $T/m.ron >/dev/null 2>&1; mod=$(ev $T/m.ron)
  rnd=""
  for s in 1 2 3 4 5; do
    python3 - $T/pool.csv $N $s $T/c.csv <<'PY'
import sys, random
lines = open(sys.argv[1]).read().splitlines(); head, rows = lines[0], lines[1:]
random.seed(int(sys.argv[3])); pick = sorted(random.sample(range(len(rows)), int(sys.argv[2])))
open(sys.argv[4], 'w').write('\n'.join([head] + [rows[i] for i in pick]) + '\n')
PY
    $C fit --robot $R --data $T/c.csv --method poe --out $T/m.ron >/dev/null 2>&1; rnd="$rnd $(ev $T/m.ron)"
  done
  echo "$S N=$N pool=$p nominal=$nom model=$mod random:$rnd"
done
rm -rf $T
