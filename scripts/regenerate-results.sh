#!/usr/bin/env bash
# Regenerates every committed result under results/ with the current build, each into a fresh
# folder (a result never mixes files of two runs). Run it after any change that moves
# results (a new MODEL_VERSION, a new default), then review `git diff --stat results/`.
#
#   scripts/regenerate-results.sh [PART...]
#
# PART is one of: paper radial reference physics nightly ensemble adaptive accuracy drops
# thermal life (default: all), or accuracy-charts (the accuracy studies' charts drawn again
# from their study.json, no drops run). About 40 minutes on two cores in all; `paper` alone about one.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
W=target/release/whirlmap
parts=("$@")
[ ${#parts[@]} -eq 0 ] && parts=(paper radial reference physics nightly ensemble adaptive accuracy drops thermal life)

# The accuracy studies, as OUTPUT:CASES (results/OUTPUT from sweeps/CASES.json).
studies=(accuracy:accuracy-cases accuracy-radial:accuracy-radial accuracy-implicit:accuracy-implicit
         accuracy-rodas4:accuracy-rodas4 accuracy-rodas5p:accuracy-rodas5p accuracy-draft:accuracy-draft
         accuracy-bdf:accuracy-bdf)

# `compare` exits 1 when the runs differ, which is the point of these comparisons.
compare() { "$W" compare "$@" || [ $? -eq 1 ]; }

for part in "${parts[@]}"; do
  echo "== $part"
  case "$part" in
    paper)
      rm -rf results/paper
      "$W" sweep sweeps/paper.json --no-progress ;;
    radial)
      # The paper's radial-only support damper against the default isotropic one.
      rm -rf results/paper-radial
      "$W" sweep sweeps/paper-radial.json --no-progress
      compare results/paper results/paper-radial --out results/paper-radial/compare-with-paper.md ;;
    reference)
      # The main job at the reference fidelity, and the convergence checks against it.
      rm -rf results/paper-reference results/convergence
      "$W" sweep sweeps/paper-reference.json --no-progress
      cargo run --release --quiet -p whirlmap-sweep --example convergence ;;
    physics)
      rm -rf results/physics
      cargo run --release --quiet --example physics ;;
    nightly)
      rm -rf results/nightly-baseline
      "$W" sweep sweeps/nightly.json --out results/nightly-baseline --no-progress ;;
    ensemble)
      rm -rf results/ensemble-paper
      "$W" ensemble sweeps/ensemble-paper.json --no-progress ;;
    adaptive)
      for s in adaptive-paper adaptive-paper-64 adaptive-paper-64-seed9; do
        rm -rf "results/$s"
        "$W" adaptive "sweeps/$s.json" --compare-full --no-progress
      done ;;
    accuracy)
      for s in "${studies[@]}"; do
        out=${s%%:*}; cases=${s##*:}
        rm -rf "results/$out"
        "$W" accuracy --cases "sweeps/$cases.json" --out "results/$out"
      done ;;
    accuracy-charts)
      for s in "${studies[@]}"; do
        out=${s%%:*}; cases=${s##*:}
        "$W" accuracy --cases "sweeps/$cases.json" --out "results/$out" --charts-only
      done ;;
    drops)
      # Fig. 3(f): mu 0.3 at 8000 r/min as released, and with a 2 um unbalance.
      mkdir -p results/reference
      "$W" drop --speed-rpm 8000 --mu 0.3 --orbit results/reference/drop-8000rpm-mu0.30.png \
        > results/reference/drop-8000rpm-mu0.30.txt
      "$W" drop --speed-rpm 8000 --mu 0.3 --set unbalance_m=2e-6 \
        --orbit results/reference/drop-8000rpm-mu0.30-e2um.png \
        > results/reference/drop-8000rpm-mu0.30-e2um.txt ;;
    thermal)
      "$W" drop --scene scenes/coast-down.json --duration-s 60 \
        --temperatures results/reference/coast-down.png > /dev/null
      "$W" drop --scene scenes/runaway.json --duration-s 60 \
        --temperatures results/reference/runaway-60s.png > /dev/null ;;
    life)
      # Does the touchdown bearing survive? Drops to failure and contact pressure over
      # speed x friction, with the survival report bearing.md.
      rm -rf results/life
      "$W" sweep sweeps/life.json --no-progress ;;
    *)
      echo "unknown part: $part" >&2
      exit 2 ;;
  esac
done
