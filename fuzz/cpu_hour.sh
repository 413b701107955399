#!/usr/bin/env bash
# Fuzzes one target until its process has used BUDGET seconds of CPU time
# (utime + stime, default 3600), not wall time, so that it can run at nice 19
# beside other work. Build first: cargo +nightly fuzz build -O
#   ./cpu_hour.sh TARGET [BUDGET]
set -u
cd "$(dirname "$0")"
t=$1; budget=${2:-3600}
bin=target/x86_64-unknown-linux-gnu/release/$t
mkdir -p corpus/$t artifacts/$t
nice -n 19 "$bin" corpus/$t seeds/$t -max_len=8192 -timeout=60 \
  -malloc_limit_mb=256 -rss_limit_mb=2048 -print_final_stats=1 \
  -artifact_prefix=artifacts/$t/ > "fuzz-$t.log" 2>&1 &
pid=$!
tick=$(getconf CLK_TCK)
while kill -0 $pid 2>/dev/null; do
  read -r -a st < /proc/$pid/stat || break
  cpu=$(( (st[13] + st[14]) / tick ))
  echo "$cpu" > "fuzz-$t.cpu"
  if [ "$cpu" -ge "$budget" ]; then kill -INT $pid; fi
  sleep 5
done
wait $pid; rc=$?
echo "$t: exit $rc after $(cat fuzz-$t.cpu) CPU-s"
grep -E "^stat::(number_of_executed_units|peak_rss_mb)|SUMMARY|panicked|ERROR|deadly" "fuzz-$t.log" | head -8
