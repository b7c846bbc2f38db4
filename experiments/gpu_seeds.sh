#!/usr/bin/env bash
# The runs behind docs/RESULTS.md: the paper-size data set with the authors' protocol, then the paper and quick
# presets over seeds (and their no-attention baselines) trained in parallel on one GPU machine, each evaluated.
# Usage: DEST=out bash experiments/gpu_seeds.sh      (N, EPOCHS_PAPER, EPOCHS_QUICK, WORKERS, TRAIN_LIMIT override)
set -u
DEST=${DEST:?set DEST to the output folder}
N=${N:-12000}; WORKERS=${WORKERS:-16}; TRAIN_LIMIT=${TRAIN_LIMIT:-420}
EP=${EPOCHS_PAPER:-60}; EQ=${EPOCHS_QUICK:-40}
DATA=$DEST/data/paper_a; RUNS=$DEST/runs
PY=${PY:-python3}; S="$PY -m symlearn.cli.main"
mkdir -p "$RUNS"
t0=$(date +%s); stamp() { echo "[$(( $(date +%s) - t0 )) s] $*"; }

stamp "collect $N samples with $WORKERS workers"
$S collect --out "$DATA" --n "$N" --workers "$WORKERS" --seed 0 --quiet > "$DEST/collect.log" 2>&1 || { stamp "collect failed"; tail -5 "$DEST/collect.log"; exit 1; }
stamp "collected"

train() {  # name, then train flags
  local name=$1; shift
  timeout "$TRAIN_LIMIT" $S train --data "$DATA" --out "$RUNS/$name" --threads 2 --quiet "$@" > "$DEST/train_$name.log" 2>&1
  stamp "train $name rc=$?"
}
for s in 0 1 2; do
  train "paper_s$s" --preset paper --seed $s --epochs "$EP" &
  train "quick_s$s" --preset quick --seed $s --epochs "$EQ" &
done
train paper_noattn --preset paper --seed 0 --epochs "$EP" --no-attention &
train quick_noattn --preset quick --seed 0 --epochs "$EQ" --no-attention &
wait

for r in paper_s0 paper_s1 paper_s2 quick_s0 quick_s1 quick_s2; do
  base=${r%_s*}_noattn
  ( $S evaluate --run "$RUNS/$r" --data "$DATA" --baseline-run "$RUNS/$base" > "$DEST/eval_$r.log" 2>&1
    stamp "evaluate $r rc=$?"
    $S table1 --run "$RUNS/$r" > "$DEST/table1_$r.log" 2>&1; stamp "table1 $r rc=$?"
    OMP_NUM_THREADS=2 $S symbols --run "$RUNS/$r" --data "$DATA" > "$DEST/symbols_$r.log" 2>&1; stamp "symbols $r rc=$?"
    preset=${r%_s*}
    OMP_NUM_THREADS=2 $S train-transition --run "$RUNS/$r" --data "$DATA" --preset "$preset" --quiet > "$DEST/transition_$r.log" 2>&1
    stamp "train-transition $r rc=$?" ) &
done
for r in paper_noattn quick_noattn; do
  ( $S evaluate --run "$RUNS/$r" --data "$DATA" > "$DEST/eval_$r.log" 2>&1; stamp "evaluate $r rc=$?"
    $S table1 --run "$RUNS/$r" > "$DEST/table1_$r.log" 2>&1; stamp "table1 $r rc=$?" ) &
done
wait
stamp "done"
