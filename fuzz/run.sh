#!/usr/bin/env bash
# Runs one fuzz target for 10 million executions (or SECONDS seconds, whichever is first).
#   fuzz/run.sh TARGET [SECONDS] [extra libFuzzer flags...]
# Builds with debug assertions (-a: overflow checks as in debug builds) and without a
# sanitizer (-s none: Sylva forbids unsafe code). New corpus inputs go to
# fuzz/corpus/TARGET (not kept in git); fuzz/seeds/TARGET is read only. Crashes land in
# fuzz/artifacts/TARGET/.
set -euo pipefail
cd "$(dirname "$0")/.."
target=$1; secs=${2:-14400}; shift $(( $# < 2 ? $# : 2 ))
case $target in
  genome|garden) dict=json.dict ;;
  config|experiment) dict=toml.dict ;;
  sexpr) dict=sexpr.dict ;;
  lsystem_rules) dict=lsystem.dict ;;
  packed) dict=packed.dict ;;
  checkpoint) dict=checkpoint.dict ;;
  glb) dict=glb.dict; set -- -max_len=16384 "$@" ;;
  *) dict= ;;
esac
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-/tmp/fuzz-target}
mkdir -p "fuzz/corpus/$target" "fuzz/artifacts/$target"
exec cargo +nightly fuzz run -s none -a --target-dir "$CARGO_TARGET_DIR" "$target" \
  "fuzz/corpus/$target" "fuzz/seeds/$target" -- \
  -runs=10000000 -max_total_time="$secs" -rss_limit_mb=2048 -timeout=10 \
  -print_final_stats=1 ${dict:+-dict=fuzz/dicts/$dict} "$@"
