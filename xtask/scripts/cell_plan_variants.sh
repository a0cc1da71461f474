#!/bin/bash
# `calib plan` settings against random rows, `poe` on N rows of a UR10 series' even rows,
# tested on its odd rows. Usage (from the worktree root, release build):
#   xtask/scripts/cell_plan_variants.sh plan SERIES N 'PLAN_OPTIONS_RON' [label]
#   xtask/scripts/cell_plan_variants.sh random SERIES N SEEDS
#   xtask/scripts/cell_plan_variants.sh model SERIES N ['PLAN_OPTIONS_RON'] [label]
# `model`: `poe` fitted on all the even rows first and the plan made with `--model` (its geometry,
# and its held-out error as the unmodelled error unless the options set it).
C=${CALIB:-target/release/calib}; R=fixtures/robots/ur10.ron; D=${DATA:-/work/data}; T=$(mktemp -d)
ev() { $C eval --model $1 --data $2 --json 2>/dev/null | python3 -c "import json,sys; print('%.4f' % json.load(sys.stdin)['mean_position_error_mm'])"; }
S=$2; N=$3
if [ "$1" = model ]; then
  echo "${4:-()}" > $T/o.ron
  $C fit --robot $R --data $D/ur10_${S}_full_even.csv --method poe --out $T/even.ron >/dev/null 2>&1
  $C plan --robot $R --model $T/even.ron --candidates $D/ur10_${S}_full_even.csv --poses $N --options $T/o.ron --out $T/c.csv >/dev/null
  $C fit --robot $R --data $T/c.csv --method poe --out $T/m.ron >/dev/null 2>&1 && echo "$S N=$N --model ${5:-${4:-()}}: $(ev $T/m.ron $D/ur10_${S}_full_odd.csv)"
elif [ "$1" = plan ]; then
  echo "$4" > $T/o.ron
  $C plan --robot $R --candidates $D/ur10_${S}_full_even.csv --poses $N --full-pose --options $T/o.ron --out $T/c.csv >/dev/null
  $C fit --robot $R --data $T/c.csv --method poe --out $T/m.ron >/dev/null 2>&1 && echo "$S N=$N ${5:-$4}: $(ev $T/m.ron $D/ur10_${S}_full_odd.csv)"
else
  out=""
  for seed in $(seq 1 $4); do
    python3 - $D/ur10_${S}_full_even.csv $N $seed $T/c.csv <<'PY'
import sys, random
lines = open(sys.argv[1]).read().splitlines(); head, rows = lines[0], lines[1:]
random.seed(int(sys.argv[3])); pick = sorted(random.sample(range(len(rows)), int(sys.argv[2])))
open(sys.argv[4], 'w').write('\n'.join([head] + [rows[i] for i in pick]) + '\n')
PY
    $C fit --robot $R --data $T/c.csv --method poe --out $T/m.ron >/dev/null 2>&1 && out="$out $(ev $T/m.ron $D/ur10_${S}_full_odd.csv)"
  done
  echo "$S N=$N random:$out" | python3 -c "import sys,statistics as st; l=sys.stdin.read().split(); v=[float(x) for x in l[3:]]; print(' '.join(l), '| median %.4f' % st.median(v))"
fi
rm -rf $T
