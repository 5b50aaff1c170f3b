"""`rig bench trackers` (its command line declared in `rig.bench.trackers_settings`): what it measures.

Each case starts `rig emulate-tracker` in a process of its own (a pseudo-terminal, a TCP socket or
an LSL outlet, with the emulator's log of every record's fate) and records it in this process with
`rig.service.tracker_recording.record_tracker`, as `rig record-tracker` does, until the emulator has
ended (it has sent everything, or lost its reader) and what was in flight has arrived. Then:

* sent, recorded: records the emulator wrote (intact or damaged) and rows in tracker.csv;
* missing: intact records sent that are not in tracker.csv; fabricated: rows that match no intact
  record sent (a damaged record let through); in_order: the rows' device times only increase;
* corrupt: what the source counted as damaged, beside damaged_sent, what the emulator damaged;
* us_per_sample: this process's CPU time over the run (the reader, liblsl's threads, the
  recording loop decoding and writing both files), per recorded sample; reading_us_per_sample:
  what it takes to have the sample for a predictor (the reader's CPU, and the consumer's
  decoding, checking and clock mapping), without the files; reader_us_per_sample: the reader's
  alone: its compiled thread (`rig.devices.trackers._readers`: waiting, reading, stamping,
  queueing) and the stream's Python thread that supervises it and reconnects, which every case
  here has (a pty, a TCP socket and an LSL inlet on the monotonic clock);
* latency_ms_median, latency_ms_p95: from the emulator's write of a record to its arrival, when
  the reader has queued it and a predictor's `poll()` gets it, both on the monotonic clock.

Rows are keyed by the device's time (to the microsecond), which every emulated record carries. A
case that cannot run (its emulator does not start, or does not end once its recording has) is a
row with `failed` and the reason, and the cases after it still run.

The machine's share of the CPU figures is measured beside them, before each case (`wake_floor`,
2 s): the CPU a bare Python thread spends per record reading the serial emulator's pty at the
same rate (select, read, nothing else). The kernel's part of it (the wake-up, the poll and the
read) is paid by any reader woken once per record, the compiled one too, which saves only the
interpreter's part; on a shared virtual machine it varies from run to run.
"""

from __future__ import annotations

import argparse
import csv
import os
import resource
import select
import subprocess
import sys
import time
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterator

import numpy as np

from rig.bench.contract import Bench, Context, Log, new_figure
from rig.clock import MonotonicClock
from rig.devices.trackers.decoders import BinaryDecoder
from rig.devices.trackers.profile import load_profile
from rig.devices.trackers.stream import TrackerRecord
from rig.errors import RigError
from rig.service.tracker_recording import record_tracker

TARGET_US_PER_SAMPLE = 50.0
TARGET_LATENCY_MEDIAN_MS = 1.0
TARGET_LATENCY_P95_MS = 2.0
# Recording goes on this long after the emulator has ended, for the reader to take what is in flight.
SETTLE_S = 2.0
# An emulator waits this long for its reader, and is given this long beyond its own duration to end
# once its recording has: it ends as soon as its reader hangs up, or once it has sent everything.
START_TIMEOUT_S = 30.0
WAKE_FLOOR_S = 2.0


@dataclass(frozen=True)
class Case:
    source: str
    transport: str
    profile: str
    faults: str


def cases(fault_at_s: float) -> list[Case]:
    """The bench's cases: serial over a pty (binary and CSV lines), over TCP, and LSL; clean, and the
    binary pty and LSL with faults (a disconnect of 0.5 s at `fault_at_s`, 1 % of bytes corrupted)."""
    disconnect = f"disconnect={fault_at_s:g}:0.5"
    return [
        Case("serial", "pty", "binary-pose", "none"),
        Case("serial", "pty", "csv", "none"),
        Case("serial", "tcp", "binary-pose", "none"),
        Case("lsl", "lsl", "", "none"),
        Case("serial", "pty", "binary-pose", f"corrupt=0.01,{disconnect}"),
        Case("lsl", "lsl", "", disconnect),
    ]


def _emulator_command(case: Case, address: str, rate_hz: float, duration_s: float, log: Path) -> list[str]:
    command = [sys.executable, "-m", "rig.cli", "emulate-tracker", "lsl" if case.transport == "lsl" else "serial"]
    if case.transport == "lsl":
        command += ["--name", address]
    else:
        command += [f"--{case.transport}", address, "--profile", case.profile]
    return command + ["--rate", f"{rate_hz:g}", "--duration", f"{duration_s:g}", "--faults", case.faults, "--log", str(log),
                      "--idle-timeout", f"{START_TIMEOUT_S:g}"]  # fmt: skip


@contextmanager
def _emulator(command: list[str], folder: Path, duration_s: float) -> Iterator[tuple[subprocess.Popen, str]]:
    """The emulator sending for `duration_s`, started, and the tracker spec it printed once ready; on
    the way out it is waited for (killed if the block failed, RigError if it does not end) and its
    pipe closed."""
    with open(folder / "emulator.err", "w") as errors:
        process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=errors, text=True)
    try:
        line = process.stdout.readline()
        if "--tracker " not in line:
            raise RigError(f"the tracker emulator did not start: {(folder / 'emulator.err').read_text()[-500:]}")
        yield process, line.rsplit("--tracker ", 1)[1].strip()
        try:
            process.wait(timeout=duration_s + START_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            raise RigError(f"the tracker emulator had not ended {duration_s + START_TIMEOUT_S:g} s after its recording") from None
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
        process.stdout.close()


def _ended(process: subprocess.Popen, clock: MonotonicClock) -> Callable[[], bool]:
    """Whether the emulator `process` ended SETTLE_S ago or more: it has sent all it was asked to (a
    recording that stopped at a fixed time would cut short an emulator that a loaded machine started
    late, and count what it sent after as missing)."""
    ended_at: list[float] = []

    def ended() -> bool:
        if not ended_at and process.poll() is not None:
            ended_at.append(clock.now())
        return bool(ended_at) and clock.now() >= ended_at[0] + SETTLE_S

    return ended


def _sent(log: Path) -> tuple[dict[int, float], int, int]:
    """The intact records' write times by device time (us), and counts of damaged and lost ones."""
    intact: dict[int, float] = {}
    damaged = lost = 0
    with log.open() as stream:
        for row in csv.DictReader(stream):
            if row["fate"] == "intact":
                intact[round(float(row["device_time"]) * 1e6)] = float(row["t_write"])
            elif row["fate"] == "damaged":
                damaged += 1
            else:
                lost += 1
    return intact, damaged, lost


def run_case(case: Case, rate_hz: float, duration_s: float, folder: Path, log: Log) -> dict[str, Any]:
    folder.mkdir(parents=True, exist_ok=True)
    sent_log = folder / "sent.csv"
    address = str(folder / "tracker") if case.transport == "pty" else "0" if case.transport == "tcp" else f"rig-bench-{os.getpid()}-{folder.name}"
    clock = MonotonicClock()
    arrivals: list[tuple[float, float]] = []

    def on_batch(records: list[TrackerRecord]) -> None:
        origin = clock.origin_ns / 1e9
        arrivals.extend((record.device_time, origin + record.t_arrival) for record in records)

    with _emulator(_emulator_command(case, address, rate_hz, duration_s, sent_log), folder, duration_s) as (process, spec):
        cpu = resource.getrusage(resource.RUSAGE_SELF)
        recording = record_tracker(spec, duration_s + START_TIMEOUT_S, folder / "recording", overwrite=True,
                                   on_batch=on_batch, clock=clock, until=_ended(process, clock))  # fmt: skip
    used = resource.getrusage(resource.RUSAGE_SELF)
    cpu_s = (used.ru_utime - cpu.ru_utime) + (used.ru_stime - cpu.ru_stime)
    intact, damaged, lost = _sent(sent_log)
    keys = [round(device_time * 1e6) for device_time, _ in arrivals]
    latencies = np.array([available - intact[key] for key, (_, available) in zip(keys, arrivals) if key in intact]) * 1e3
    counters = recording.sidecar["counters"]
    tracker_latency = recording.sidecar.get("latency") or {}
    row = {
        **case_fields(case, rate_hz, duration_s),
        "sent": len(intact) + damaged,
        "damaged_sent": damaged,
        "lost_sent": lost,
        "recorded": recording.samples,
        "missing": len(set(intact) - set(keys)),
        "fabricated": sum(key not in intact for key in keys),
        "in_order": bool(np.all(np.diff(keys) > 0)),
        "corrupt": counters["corrupt"],
        "rejected": counters["rejected"],
        "dropped": counters["dropped"],
        "reconnects": counters["reconnects"],
        "us_per_sample": cpu_s / max(recording.samples, 1) * 1e6,
        "reading_us_per_sample": recording.sidecar["reading_cpu_us_per_sample"],
        "reader_us_per_sample": recording.sidecar["reader_cpu_us_per_sample"],
        "latency_ms_median": float(np.median(latencies)) if latencies.size else None,
        "latency_ms_p95": float(np.percentile(latencies, 95)) if latencies.size else None,
        "tracker_latency_ms_median": tracker_latency.get("median_ms"),
    }
    log(f"{case.source}/{case.transport}/{row['profile']} faults {case.faults}: sent {row['sent']}, recorded {row['recorded']}, "
        f"missing {row['missing']}, fabricated {row['fabricated']}, corrupt {row['corrupt']} (damaged {damaged})")  # fmt: skip
    return row


def wake_floor(rate_hz: float, duration_s: float, folder: Path) -> float:
    """CPU microseconds per record of a bare reader thread (select and read only) on the serial
    emulator's pty at `rate_hz` for `duration_s` (see the module docstring)."""
    folder.mkdir(parents=True, exist_ok=True)
    case = Case("serial", "pty", "binary-pose", "none")
    link = folder / "tracker"
    received = 0
    with _emulator(_emulator_command(case, str(link), rate_hz, duration_s, folder / "sent.csv"), folder, duration_s) as (process, _):
        started = time.thread_time()
        fd = os.open(link, os.O_RDONLY | os.O_NONBLOCK | os.O_NOCTTY)
        try:
            while True:
                if select.select([fd], [], [], 0.5)[0]:
                    try:
                        data = os.read(fd, 65536)
                    except OSError:  # the emulator closed its end
                        break
                    if not data:
                        break
                    received += len(data)
                elif process.poll() is not None:
                    break
        finally:
            os.close(fd)
        cpu_s = time.thread_time() - started
    records = received / BinaryDecoder(load_profile("binary-pose")).record_bytes
    return cpu_s / max(records, 1.0) * 1e6


def case_fields(case: Case, rate_hz: float, duration_s: float, failed: str | None = None) -> dict[str, Any]:
    """A case's row as far as what it is goes, and why it could not run (`failed`; None: it ran)."""
    return {"failed": failed, "source": case.source, "transport": case.transport, "profile": case.profile or "pose (7 channels)",
            "faults": case.faults, "rate_hz": rate_hz, "duration_s": duration_s}  # fmt: skip


def every_case_failed(rows: list[dict[str, Any]]) -> str | None:
    """Where no case recorded a sample: how many, and the first one's reason."""
    if not rows or any(row["failed"] is None and row["recorded"] > 0 for row in rows):
        return None
    first = rows[0]["failed"] or "nothing recorded"
    return f"every one of the {len(rows)} cases failed or recorded nothing (the first: {first})"


def targets(rows: list[dict[str, Any]]) -> dict[str, bool | None]:
    """The bench's targets, met or not, in this run (None for each where no case ran); a run where
    a case failed has not met "every case ran"."""
    every_case_ran = all(r["failed"] is None for r in rows)
    rows = [r for r in rows if r["failed"] is None]
    clean = [r for r in rows if r["faults"] == "none"]
    faulty = [r for r in rows if r["faults"] != "none"]
    met = {
        "clean runs: every sample sent recorded, in order": all(r["recorded"] == r["sent"] and r["missing"] == 0 and r["in_order"] for r in clean),
        "faults: every intact record recovered, nothing fabricated": all(r["missing"] == 0 and r["fabricated"] == 0 for r in faulty),
        "faults: every damaged record counted": all(r["corrupt"] >= r["damaged_sent"] for r in faulty),
        f"reading CPU <= {TARGET_US_PER_SAMPLE:g} us per sample": all(r["reading_us_per_sample"] <= TARGET_US_PER_SAMPLE for r in rows),
        f"whole recording process CPU <= {TARGET_US_PER_SAMPLE:g} us per sample": all(r["us_per_sample"] <= TARGET_US_PER_SAMPLE for r in rows),
        f"added latency median <= {TARGET_LATENCY_MEDIAN_MS:g} ms, p95 <= {TARGET_LATENCY_P95_MS:g} ms": all(
            r["latency_ms_median"] is not None and r["latency_ms_median"] <= TARGET_LATENCY_MEDIAN_MS
            and r["latency_ms_p95"] <= TARGET_LATENCY_P95_MS for r in rows
        ),
    }  # fmt: skip
    return {**(met if rows else dict.fromkeys(met)), **({} if every_case_ran else {"every case ran": False})}


def cpu_ticks() -> tuple[int, int] | None:
    """The machine's CPU time so far, in clock ticks: (stolen by the hypervisor, all), from
    /proc/stat; None where there is none."""
    try:
        with open("/proc/stat") as stat:
            fields = [int(value) for value in stat.readline().split()[1:]]
    except (OSError, ValueError):
        return None
    # user nice system idle iowait irq softirq steal [guest guest_nice, already counted in user, nice]
    return (fields[7], sum(fields[:8])) if len(fields) >= 8 else None


def stolen_pct(before: tuple[int, int] | None, after: tuple[int, int] | None) -> float | None:
    """The share of the machine's CPU time a virtual machine's host took between two `cpu_ticks`."""
    if before is None or after is None or after[1] <= before[1]:
        return None
    return 100.0 * (after[0] - before[0]) / (after[1] - before[1])


def run(args: argparse.Namespace, context: Context) -> list[dict[str, Any]]:
    """Every case in turn, `args.rate` records a second for `args.duration` seconds; each row also holds the noise its figures carry: the machine's 1-minute
    load average when it started, the wake floor measured just before it, and the share of the CPU
    the host of a virtual machine took during it (a stolen stretch delays records by milliseconds,
    which shows in the latency's 95th percentile first)."""
    rows = []
    every = cases(fault_at_s=args.duration / 2.0)
    progress = context.progress("recording the cases")
    for index, case in enumerate(every):
        progress(index, len(every))
        load = os.getloadavg()[0]
        floor = wake_floor(args.rate, WAKE_FLOOR_S, context.folder / f"floor{index}")
        before = cpu_ticks()
        try:
            row = run_case(case, args.rate, args.duration, context.folder / f"case{index}", context.log)
        except RigError as error:
            context.log(f"{case.source}/{case.transport}/{case.profile or 'pose'} faults {case.faults}: FAILED: {error}")
            row = case_fields(case, args.rate, args.duration, str(error))
        rows.append({**row, "load_average_1min": load, "wake_floor_us": floor, "stolen_cpu_pct": stolen_pct(before, cpu_ticks())})
    progress(len(every), len(every))
    return rows


def machine_noise(rows: list[dict[str, Any]]) -> str:
    """The machine's load and the CPU its host took, over the cases."""
    loads = [row["load_average_1min"] for row in rows]
    stolen = [row["stolen_cpu_pct"] for row in rows if row.get("stolen_cpu_pct") is not None]
    return (f"machine noise: {os.cpu_count()} CPUs, 1-minute load average {min(loads):.2f} to {max(loads):.2f} over the cases"
            + (f", CPU stolen by the virtual machine's host {min(stolen):.1f} to {max(stolen):.1f} %" if stolen else ""))  # fmt: skip


def table(rows: list[dict[str, Any]]) -> str:
    head = (
        "| source | transport | profile | faults | sent | recorded | missing | fabricated | corrupt (damaged) "
        "| us/sample: reading (reader thread), process | wake floor us | CPU stolen % | latency ms median, p95 |"
    )
    lines = [head, "|" + " --- |" * (head.count("|") - 1)]
    for r in rows:
        if r["failed"] is not None:
            lines.append(f"| {r['source']} | {r['transport']} | {r['profile']} | {r['faults']} | failed: {r['failed']} |")
            continue
        latency = f"{r['latency_ms_median']:.3f}, {r['latency_ms_p95']:.3f}" if r["latency_ms_median"] is not None else "n/a"
        stolen = f"{r['stolen_cpu_pct']:.1f}" if r.get("stolen_cpu_pct") is not None else "n/a"
        lines.append(
            f"| {r['source']} | {r['transport']} | {r['profile']} | {r['faults']} | {r['sent']} | {r['recorded']} | {r['missing']} | "
            f"{r['fabricated']} | {r['corrupt']} ({r['damaged_sent']}) | {r['reading_us_per_sample']:.1f} ({r['reader_us_per_sample']:.1f}), "
            f"{r['us_per_sample']:.1f} | {r['wake_floor_us']:.1f} | {stolen} | {latency} |"
        )
    return "\n".join(lines)


def plot(rows: list[dict[str, Any]], path: Path) -> None:
    """CPU per sample and added latency (median and 95th percentile) per case that ran."""
    rows = [r for r in rows if r["failed"] is None]
    labels = ["\n".join([f"{r['source']}/{r['transport']}", *r["faults"].split(",")]) for r in rows]
    x = np.arange(len(rows))
    figure, (cost, latency) = new_figure((max(6.0, 1.6 * len(rows)) + 2.5, 7.0), nrows=2, ncols=1, sharex=True)
    cost.bar(x - 0.2, [r["reading_us_per_sample"] for r in rows], width=0.4, color="tab:blue", label="reading")
    cost.bar(x + 0.2, [r["us_per_sample"] for r in rows], width=0.4, color="tab:gray", label="whole recording process")
    cost.plot(x, [r["wake_floor_us"] for r in rows], "o", color="tab:red", label="bare thread woken per record")
    cost.axhline(TARGET_US_PER_SAMPLE, color="k", linestyle="--", label="target")
    cost.set_ylabel("CPU per sample (us)")
    cost.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    latency.bar(x - 0.2, [r["latency_ms_median"] or 0.0 for r in rows], width=0.4, label="median")
    latency.bar(x + 0.2, [r["latency_ms_p95"] or 0.0 for r in rows], width=0.4, label="95th percentile")
    latency.axhline(TARGET_LATENCY_MEDIAN_MS, color="k", linestyle="--", label="target, median")
    latency.axhline(TARGET_LATENCY_P95_MS, color="k", linestyle=":", label="target, 95th percentile")
    latency.set_ylabel("emulator write to queued for a predictor (ms)")
    latency.set_xticks(x, labels, fontsize=8)
    latency.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    figure.tight_layout()
    figure.savefig(path, dpi=100)


BENCH = Bench(run=run, table=table, targets=targets, notes=machine_noise, plot=plot, all_failed=every_case_failed)
