#!/usr/bin/env bash
# scripts/bench-median.sh N COMMAND [ARGS...]
# Runs a benchmark that prints `bench: scene=S what=W ours=X ref=Y ratio=R` lines N times and
# prints one line per (scene, metric): the medians of ours, ref and ratio over the runs and the
# range of the ratio. The machines here drift by 10-20% over minutes, so one run's ratio is
# a sample; the median of several is what docs/benchmarks.md quotes. Raw output: $BENCH_LOG (default
# a temporary file, printed at the end).
#   scripts/bench-median.sh 3 build/release/bench/raycast/bench_raycast
set -euo pipefail
n="${1:?usage: bench-median.sh N COMMAND [ARGS...]}"
shift
[ $# -gt 0 ] || { echo "usage: bench-median.sh N COMMAND [ARGS...]" >&2; exit 2; }
log="${BENCH_LOG:-$(mktemp /tmp/bench-median.XXXXXX)}"
: > "$log"
for ((i = 1; i <= n; ++i)); do
  echo "run $i/$n: $*" >&2
  "$@" 2>&1 | grep '^bench: ' | grep ' ratio=' | sed "s/^/run=$i /" >> "$log"
done
awk '
  function median(arr, cnt,   i, j, t) {   # sorts arr[1..cnt] in place
    for (i = 2; i <= cnt; ++i) { t = arr[i]; for (j = i - 1; j >= 1 && arr[j] > t; --j) arr[j + 1] = arr[j]; arr[j + 1] = t }
    return cnt % 2 ? arr[(cnt + 1) / 2] : (arr[cnt / 2] + arr[cnt / 2 + 1]) / 2
  }
  {
    key = ""; o = r = q = ""
    for (f = 2; f <= NF; ++f) {
      split($f, kv, "=")
      if (kv[1] == "scene" || kv[1] == "what") key = key " " $f
      else if (kv[1] == "ours") o = kv[2]
      else if (kv[1] == "ref") r = kv[2]
      else if (kv[1] == "ratio") q = kv[2]
    }
    if (!(key in cnt)) order[++nk] = key
    c = ++cnt[key]
    O[key, c] = o; R[key, c] = r; Q[key, c] = q
  }
  END {
    for (k = 1; k <= nk; ++k) {
      key = order[k]; c = cnt[key]
      delete a; delete b; delete d
      for (i = 1; i <= c; ++i) { a[i] = O[key, i]; b[i] = R[key, i]; d[i] = Q[key, i] }
      mo = median(a, c); mr = median(b, c); mq = median(d, c)
      printf "bench-median:%s runs=%d ours=%.4g ref=%.4g ratio=%.3f ratio_min=%.3f ratio_max=%.3f\n", key, c, mo, mr, mq, d[1], d[c]
    }
  }' "$log"
echo "raw output: $log" >&2
