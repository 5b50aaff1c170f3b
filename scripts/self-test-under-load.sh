#!/usr/bin/env bash
# The self-test under a CPU hog: RUNS runs of `rig measure --self-test` for each of 10 s and 20 s
# while `stress-ng --cpu 1` loads one core, then the tally: valid and within 2 ms of the log /
# invalid with the stall named / other (degraded, a disagreement, an error), each run on a line.
# Needs `rig` on PATH, xvfb-run and stress-ng (Debian: xvfb, stress-ng).
# Usage: scripts/self-test-under-load.sh [RUNS] [OUT_DIR]   (RUNS per duration, default 10)
set -euo pipefail
runs=${1:-10}
out=${2:-$(mktemp -d -t rig-self-test-load-XXXXXX)}
mkdir -p "$out"
command -v stress-ng > /dev/null || { echo "stress-ng is not installed (Debian: stress-ng)" >&2; exit 2; }
started=$(date +%s)
stress-ng --cpu 1 --quiet &
hog=$!
trap 'kill "$hog"' EXIT
for duration in 10 20; do
  for i in $(seq 1 "$runs"); do
    run="$out/d$duration-$i"
    status=0
    timeout 600 xvfb-run -a rig measure --self-test --json --duration "$duration" --out "$run" >"$run.json" 2>"$run.err" \
      || status=$?
    echo "$duration $i $status" >>"$out/statuses.txt"
  done
done
# The hog's share of a core over the runs: it loaded the machine as said, or the tally means nothing.
hog_cpu_s=$(ps -o cputimes= --ppid "$hog" | awk '{s += $1} END {print s + 0}')
echo "CPU hog: $hog_cpu_s s of CPU in $(($(date +%s) - started)) s"
python - "$out" <<'EOF'
import json, sys
from pathlib import Path

out = Path(sys.argv[1])
tally = {"valid within 2 ms": 0, "invalid, stall named": 0, "other": 0}
for line in (out / "statuses.txt").read_text().splitlines():
    duration, i, status = line.split()
    text = (out / f"d{duration}-{i}.json").read_text().strip()
    if not text:
        kind, what = "other", f"error: {(out / f'd{duration}-{i}.err').read_text().strip().splitlines()[-1:]}"
    else:
        report = json.loads(text)
        verdict, check = report["verdict"], report["run"].get("self_test")
        difference = f"video - log {check['difference_ms']:+.2f} ms" if check else "not analysed"
        if verdict == "valid" and check and check["agree"]:
            kind = "valid within 2 ms"
        elif verdict.startswith("invalid") and "stalled" in verdict and status == "4":
            kind = "invalid, stall named"
        else:
            kind = "other"
        what = f"{verdict} ({difference})"
    tally[kind] += 1
    print(f"{duration} s run {i}: exit {status}: {kind}: {what}")
print("tally: " + ", ".join(f"{count} {kind}" for kind, count in tally.items()))
EOF
