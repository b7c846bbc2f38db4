#!/usr/bin/env bash
# The lever runs behind docs/RESULTS.md ("Levers"): on the paper-size set (data/paper_a), the paper and quick
# presets trained with up-weighted riders and the code-stability loss, over seeds, beside no-attention baselines
# trained with the same rider weight, single-lever quick runs that say which lever moved what, and a quick run on
# a 1-5-object set (data/k15) next to the 1-3-object model measured zero-shot on that set.
# Every run is then evaluated (effects, riders, symbol stability), put through Table I, m(z) and its symbols.
# Each phase has a time limit, so a lent GPU's 10-minute call returns whatever finished.
# SET=followup runs the second call's set instead (see its branch below).
# Usage: DEST=out bash bench/gpu_levers.sh   (DATA, DATA15, EPOCHS_PAPER, EPOCHS_QUICK, RIDER, STAB, DYN,
#   TRANSITION_EPOCHS_PAPER,
#   TRAIN_LIMIT, POST_LIMIT and TRAIN_EXTRA override; TRAIN_EXTRA is added to every train command)
set -u
DEST=${DEST:?set DEST to the output folder}
DATA=${DATA:-data/paper_a}; DATA15=${DATA15:-data/k15}
EP=${EPOCHS_PAPER:-40}; EQ=${EPOCHS_QUICK:-40}; RIDER=${RIDER:-10}; STAB=${STAB:-0.1}; DYN=${DYN:-0.5}
TRAIN_LIMIT=${TRAIN_LIMIT:-280}; POST_LIMIT=${POST_LIMIT:-120}; TRAIN_EXTRA=${TRAIN_EXTRA:-}
TEP=${TRANSITION_EPOCHS_PAPER:-100}  # m(z) epochs for the paper preset (its default 200 may not fit a lent call)
PY=${PY:-python3}; S="$PY -m symlearn.cli.main"
RUNS=$DEST/runs; LOGS=$DEST/logs
mkdir -p "$RUNS" "$LOGS"
t0=$(date +%s); stamp() { echo "[$(( $(date +%s) - t0 )) s] $*" | tee -a "$DEST/progress.txt"; }

train() {  # name, data, then train flags
  local name=$1 data=$2; shift 2
  timeout "$TRAIN_LIMIT" $S train --data "$data" --out "$RUNS/$name" --threads 1 --quiet $TRAIN_EXTRA "$@" \
    > "$LOGS/train_$name.log" 2>&1
  stamp "train $name rc=$?"
}
LEVERS="--rider-weight $RIDER --stability-weight $STAB"
if [ "${SET:-main}" = main ]; then
  for s in 0 1 2; do
    train "paper_s$s" "$DATA" --preset paper --seed $s --epochs "$EP" $LEVERS &
    train "quick_s$s" "$DATA" --preset quick --seed $s --epochs "$EQ" $LEVERS &
  done
  train paper_noattn "$DATA" --preset paper --seed 0 --epochs "$EP" --no-attention --rider-weight "$RIDER" &
  train quick_noattn "$DATA" --preset quick --seed 0 --epochs "$EQ" --no-attention --rider-weight "$RIDER" &
  train quick_s0_rider "$DATA" --preset quick --seed 0 --epochs "$EQ" --rider-weight "$RIDER" &
  train quick_s0_stab "$DATA" --preset quick --seed 0 --epochs "$EQ" --stability-weight "$STAB" &
  train quick_s0_dyn "$DATA" --preset quick --seed 0 --epochs "$EQ" $LEVERS --dynamics-weight "$DYN" &
  [ -d "$DATA15" ] && train k15_s0 "$DATA15" --preset quick --seed 0 --epochs "$EQ" $LEVERS &
else  # SET=followup: the stability lever alone on the paper preset; the 1-5-object quick run over more seeds
  train paper_stab_s0 "$DATA" --preset paper --seed 0 --epochs "$EP" --stability-weight "$STAB" &
  for s in 0 1 2; do train "k15_s$s" "$DATA15" --preset quick --seed $s --epochs "$EQ" $LEVERS & done
fi
wait
stamp "training done"

analyse() {  # run name, data, baseline run name ('' for none), transition preset ('' for none)
  local r=$1 data=$2 base=$3 tp=$4
  local bflag=(); [ -n "$base" ] && [ -f "$RUNS/$base/best.pt" ] && bflag=(--baseline-run "$RUNS/$base")
  [ -f "$RUNS/$r/best.pt" ] || { stamp "skip $r: no best.pt"; return; }
  OMP_NUM_THREADS=1 timeout "$POST_LIMIT" $S evaluate --run "$RUNS/$r" --data "$data" "${bflag[@]}" > "$LOGS/eval_$r.log" 2>&1
  stamp "evaluate $r rc=$?"
  OMP_NUM_THREADS=1 timeout 60 $S table1 --run "$RUNS/$r" > "$LOGS/table1_$r.log" 2>&1; stamp "table1 $r rc=$?"
  [ -n "$tp" ] || return
  local tflag=(); [ "$tp" = paper ] && tflag=(--epochs "$TEP")
  OMP_NUM_THREADS=1 timeout "$POST_LIMIT" $S train-transition --run "$RUNS/$r" --data "$data" --preset "$tp" "${tflag[@]}" --quiet \
    > "$LOGS/transition_$r.log" 2>&1; stamp "train-transition $r rc=$?"
  OMP_NUM_THREADS=1 timeout 60 $S symbols --run "$RUNS/$r" --data "$data" > "$LOGS/symbols_$r.log" 2>&1
  stamp "symbols $r rc=$?"
}
if [ "${SET:-main}" = main ]; then
  for s in 0 1 2; do
    analyse "paper_s$s" "$DATA" paper_noattn paper &
    analyse "quick_s$s" "$DATA" quick_noattn quick &
  done
  for r in quick_s0_rider quick_s0_stab quick_s0_dyn; do analyse $r "$DATA" quick_noattn quick & done
  analyse paper_noattn "$DATA" "" "" &
  analyse quick_noattn "$DATA" "" "" &
  if [ -d "$DATA15" ]; then
    analyse k15_s0 "$DATA15" "" quick &
    if [ -f "$RUNS/quick_s0/best.pt" ]; then  # the 1-3-object model on the 1-5-object set: zero-shot
      mkdir -p "$RUNS/quick_s0_on_k15" && cp "$RUNS/quick_s0/best.pt" "$RUNS/quick_s0/config.json" "$RUNS/quick_s0_on_k15/"
      ( OMP_NUM_THREADS=1 timeout "$POST_LIMIT" $S evaluate --run "$RUNS/quick_s0_on_k15" --data "$DATA15" \
          > "$LOGS/eval_quick_s0_on_k15.log" 2>&1; stamp "evaluate quick_s0_on_k15 rc=$?" ) &
    fi
  fi
else
  analyse paper_stab_s0 "$DATA" "" paper &
  for s in 0 1 2; do
    analyse "k15_s$s" "$DATA15" "" "" &
    if [ -f "$RUNS/k15_s$s/best.pt" ]; then  # the 1-5-object model on the 1-3-object test split
      mkdir -p "$RUNS/k15_s${s}_on_paper_a" && cp "$RUNS/k15_s$s/best.pt" "$RUNS/k15_s$s/config.json" "$RUNS/k15_s${s}_on_paper_a/"
      ( OMP_NUM_THREADS=1 timeout "$POST_LIMIT" $S evaluate --run "$RUNS/k15_s${s}_on_paper_a" --data "$DATA" \
          > "$LOGS/eval_k15_s${s}_on_paper_a.log" 2>&1; stamp "evaluate k15_s${s}_on_paper_a rc=$?" ) &
    fi
  done
fi
wait
stamp "done"
