#!/usr/bin/env bash
# Runs every fuzz target for SECONDS (default 150) each, one after another.
# Needs cargo-fuzz and a nightly toolchain (cargo +nightly fuzz ...).
set -u
cd "$(dirname "$0")"
secs=${1:-150}
for t in pcd ply las xyz; do
  mkdir -p corpus/$t
  cargo +nightly fuzz run -O $t corpus/$t seeds/$t -- \
    -max_total_time=$secs -max_len=8192 -timeout=10 \
    -malloc_limit_mb=256 -rss_limit_mb=2048 -print_final_stats=1 \
    > "fuzz-$t.log" 2>&1
  echo "$t: exit $?"; grep -E "^stat::(number_of_executed_units|peak_rss_mb)|Done|SUMMARY|panicked|ERROR" "fuzz-$t.log" | head -8
done
