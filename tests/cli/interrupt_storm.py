"""Interrupt each long command many times at random moments and count what went wrong (a script,
run by hand: `.venv/bin/python tests/cli/interrupt_storm.py --tries 20`).

Each try starts the command as a user does, waits a random time within the command's usual run,
sends SIGINT (every fourth try SIGTERM), and records the exit status, the seconds it took to stop,
and what of its outputs could not be read back (the checks of test_interrupts.py). Prints one line
per command: tries, stopped (130/143), finished before the signal (0), segmentation faults or other
signal deaths, hangs, tracebacks, unreadable outputs, and the slowest stop.
"""

from __future__ import annotations

import argparse
import json
import math
import random
import signal
import subprocess
import sys
import tempfile
import time
from contextlib import contextmanager, nullcontext
from collections import Counter
from pathlib import Path
from typing import Iterator

sys.path.insert(0, str(Path(__file__).parent))
from test_interrupts import EXIT_FOR, RIG, STOP_LIMIT_S, Run, after, unreadable  # noqa: E402


def _film(folder: Path) -> Path:
    subprocess.run([str(RIG), "simulate", "--out", str(folder / "film"), "--duration", "8", "--camera-fps", "120"],
                   check=True, capture_output=True)  # fmt: skip
    return folder / "film" / "video.avi"


def _trace(folder: Path) -> Path:
    path = folder / "head.csv"
    rows = []
    for i in range(12000):
        t = i / 100
        angle = 0.4 * math.sin(2 * math.pi * 0.7 * t)
        rows.append(f"{t!r},{0.1 * math.sin(t)},0,0,{math.cos(angle / 2)!r},0,{math.sin(angle / 2)!r},0\n")
    path.write_text("t,px,py,pz,qw,qx,qy,qz\n" + "".join(rows))
    return path


@contextmanager
def _emulated_tracker(link: Path) -> Iterator[Path]:
    """A serial tracker streaming on a pseudo-terminal at `link` (one per try: the emulator ends
    when its reader goes)."""
    emulator = subprocess.Popen([str(RIG), "emulate-tracker", "serial", "--pty", str(link), "--rate", "500"],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)  # fmt: skip
    try:
        while not link.exists():
            time.sleep(0.05)
        yield link
    finally:
        emulator.send_signal(signal.SIGINT)
        emulator.wait(timeout=STOP_LIMIT_S)


def _commands(folder: Path) -> dict[str, tuple[float, object]]:
    """Name: (the longest wait before the signal, argv for an output folder)."""
    video, trace = _film(folder), _trace(folder)
    spec = folder / "sweep.toml"
    spec.write_text('[base]\nduration_s = 3\n[grid]\n"camera.fps" = [120, 180, 240]\n')
    return {
        "simulate": (8.0, lambda out: ["simulate", "--out", str(out), "--duration", "10"]),
        "demo": (12.0, lambda out: ["demo", "--out", str(out), "--duration", "6"]),
        "analyse": (5.0, lambda out: ["analyse", str(video), "--method", "all", "--csv", str(out / "tracks.csv")]),
        "tune": (8.0, lambda out: ["tune", "kalman-cv", "--trace", str(trace), "--horizon-ms", "30", "--max-iterations",
                                   "400", "--out", str(out / "params.json")]),  # fmt: skip
        "bench": (6.0, lambda out: ["bench", "predictors", "--duration", "10", "--json", str(out / "bench.json")]),
        "sweep": (10.0, lambda out: ["sweep", str(spec), "--out", str(out)]),
        "record-tracker": (3.0, lambda out: ["record-tracker", "--tracker", f"serial:{out}.tty", "--out", str(out)]),
        "record": (4.0, lambda out: ["record", "--camera", f"camera:{video}", "--duration", "30", "--out", str(out)]),
    }


def _storm(name: str, longest_s: float, argv, tries: int, folder: Path, rng: random.Random) -> dict[str, object]:
    counts: Counter[str] = Counter()
    slowest = 0.0
    for i in range(tries):
        out = folder / f"{name}{i:02d}"
        sig = signal.SIGTERM if i % 4 == 3 else signal.SIGINT
        with _emulated_tracker(Path(f"{out}.tty")) if name == "record-tracker" else nullcontext():
            run = Run(argv(out), out)
            finished_first = not run.wait_for(after(rng.uniform(0.0, longest_s)))
            try:
                code, took = run.stop(sig)
            except AssertionError:
                counts["hangs"] += 1
                print(f"{name} try {i}: hung after {sig.name}; its stderr ends:\n{run.stderr[-3000:]}", file=sys.stderr)
                continue
        counts["finished first"] += finished_first
        slowest = max(slowest, took)
        if code == EXIT_FOR[sig]:
            counts["stopped"] += 1
        elif code < 0:
            counts[f"killed by {signal.Signals(-code).name}"] += 1
        elif code != 0 or not finished_first:
            counts[f"exit {code}" + ("" if finished_first else " after the signal")] += 1
        if "Traceback" in run.stderr or "Fatal Python error" in run.stderr:
            counts["tracebacks"] += 1
        if code != (0 if finished_first else EXIT_FOR[sig]) or "Traceback" in run.stderr or "Fatal Python error" in run.stderr:
            print(f"{name} try {i}: exit {code} after {sig.name}; its stderr ends:\n{run.stderr[-3000:]}", file=sys.stderr)
        problems = unreadable(out)
        if problems:
            counts["unreadable outputs"] += 1
            print(f"{name} try {i}: {problems}", file=sys.stderr)
    return {"command": name, "tries": tries, **counts, "slowest stop s": round(slowest, 2)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--tries", type=int, default=20)
    parser.add_argument("--only", action="append", help="only this command; repeat for several")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    rng = random.Random(args.seed)
    with tempfile.TemporaryDirectory(prefix="rig-interrupt-storm-") as scratch:
        folder = Path(scratch)
        for name, (longest_s, argv) in _commands(folder).items():
            if args.only and name not in args.only:
                continue
            print(json.dumps(_storm(name, longest_s, argv, args.tries, folder, rng)), flush=True)
    print(f"(a hang: still running {STOP_LIMIT_S:g} s after the signal)")


if __name__ == "__main__":
    main()
