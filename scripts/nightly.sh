#!/usr/bin/env bash
# Nightly regression sweep: run a sweep, compare it with the committed baseline, write the
# report. Exit code: whirlmap compare's (0 the same, 1 changed beyond the thresholds, 2 error).
#
#   scripts/nightly.sh [OUT]
#
# OUT defaults to results/nightly-runs/<UTC date>. Environment:
#   WHIRLMAP          the binary (default: target/release/whirlmap, built if missing)
#   NIGHTLY_SPEC      the sweep (default: sweeps/nightly.json)
#   NIGHTLY_BASELINE  the baseline results (default: results/nightly-baseline)
#   COMPARE_ARGS      extra options for whirlmap compare (e.g. "--force-rel 0.02")
# The report is OUT/compare.md with the class map OUT/compare-classes.png. On a cluster, run
# the sweep with scripts/slurm/submit.sh instead and compare its merged folder the same way.
set -uo pipefail
cd "$(dirname "$0")/.."
whirlmap=${WHIRLMAP:-target/release/whirlmap}
if [ ! -x "$whirlmap" ]; then
    cargo build --release --quiet || exit 2
fi
spec=${NIGHTLY_SPEC:-sweeps/nightly.json}
baseline=${NIGHTLY_BASELINE:-results/nightly-baseline}
out=${1:-results/nightly-runs/$(date -u +%Y-%m-%d)}

# --overwrite: a second run into the same OUT (the same day) replaces the first; its files
# are kept in OUT/previous-run/ until the new run's first records are written.
"$whirlmap" sweep "$spec" --out "$out" --overwrite --no-progress
rc=$?
# 1: some points failed; they are recorded and the comparison reports them.
if [ $rc -ne 0 ] && [ $rc -ne 1 ]; then
    echo "nightly: the sweep failed (exit $rc)" >&2
    exit 2
fi
# shellcheck disable=SC2086
"$whirlmap" compare "$baseline" "$out" --out "$out/compare.md" ${COMPARE_ARGS:-}
rc=$?
case $rc in
0) echo "nightly: the same as $baseline" ;;
1) echo "nightly: CHANGED since $baseline: see $out/compare.md" ;;
*) echo "nightly: compare failed (exit $rc)" >&2 ;;
esac
exit $rc
