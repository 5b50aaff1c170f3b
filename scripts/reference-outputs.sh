#!/usr/bin/env bash
# The reference runs' outputs as checksums, one line a file: the simulated default, the warp
# renderer fed by kalman-cv, and a run with the simulated board, each filmed and then analysed.
# A change that should not change behaviour leaves this listing the same, byte for byte:
#
#   scripts/reference-outputs.sh OUT > before.txt   # on the commit before the change
#   scripts/reference-outputs.sh OUT > after.txt    # on the change
#   diff before.txt after.txt
#
# The analysis's JSON is compared without the seconds each stage took (the machine's, not the
# rig's). Needs `rig` on the PATH (the project's .venv activated).
set -euo pipefail
if [[ $# -ne 1 ]]; then
    echo "usage: $0 OUT_DIR (made afresh; the runs' files are left there)" >&2
    exit 2
fi
rm -rf "$1"
mkdir -p "$1"
# The runs are named relative to OUT, so paths the outputs hold read the same wherever OUT is.
cd "$1"
declare -A runs=(
    [default]=""
    [warp-kalman-cv]="--renderer warp --predictor kalman-cv"
    [board]="--board"
)
for name in default warp-kalman-cv board; do
    # shellcheck disable=SC2086  # the options are words
    rig simulate --out "$name" --duration 4 ${runs[$name]} > /dev/null
    board=()
    [[ -d "$name/board" ]] && board=(--board "$name/board")
    rig analyse "$name/video.avi" "${board[@]}" --json > "$name.analysis.json" || [[ $? -eq 3 ]]
    python3 - "$name.analysis.json" > "$name.analysis.stable.json" <<'EOF'
import json, sys
def stable(value):
    if isinstance(value, dict):
        return {k: stable(v) for k, v in value.items() if not k.endswith("seconds")}
    if isinstance(value, list):
        return [stable(v) for v in value]
    return value
print(json.dumps(stable(json.load(open(sys.argv[1]))), indent=1, sort_keys=True))
EOF
    rm "$name.analysis.json"
done
find . -type f | LC_ALL=C sort | xargs sha256sum
