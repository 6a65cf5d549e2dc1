"""Ingest of large proximity traces: time and peak memory at 10^6 rows.

Two generated traces of ROWS lines (10^6, ``--quick``: 10^5):

* SocioPatterns-like ``t i j Ci Cj``, tab-separated: 300 agents in 10 classes,
  contacts of a geometric number of 20 s windows (mean 3), so merging has work;
* CSV ``t,a,b`` with text IDs (``agent-17``), one encounter per row.

For each: median wall time of 3 ingests (``swarmtopo.io.read_trace``, file to
EncounterLog), the peak RSS above the level before one more ingest (Arrow set to the
system allocator, so freed memory is returned and shows in the next peak), and the same
for the baseline measured in the same run: a plain ``pyarrow.csv.read_csv`` of the
same file into an Arrow table (no validation, no merging).  The script exits 1 if an
ingest's peak RSS exceeds BOUND_BYTES_PER_ROW bytes per input row plus 32 MB.  Measured: about
270 B/row at 10^6 rows (int64/float64 temporaries of the validation, factorization
and sort, 8 B each per row); 400 leaves 1.5x headroom, and holding the rows as Python
objects (a tuple of a float and two str: 64 + 24 + 2 x 59 + 8 B) would add 200+ B/row
on top of the arrays and break it.

    python benchmarks/bench_ingest.py [--quick]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.csv as pcsv

from _measure import machine, revision, run_measured
from swarmtopo.io import read_trace

REPEATS = 3
BOUND_BYTES_PER_ROW = 400
"""Peak RSS bound of an ingest, bytes per input row ..."""
BOUND_FIXED_BYTES = 32_000_000
"""... plus this, for the 4 MiB read blocks and library buffers (10^6 rows: 432 MB)."""


def sociopatterns_trace(path: Path, rows: int, rng) -> None:
    """``t i j Ci Cj`` lines, runs of consecutive 20 s windows per pair, sorted by t."""
    agents, classes = 300, 10
    contacts = rows // 3 + 1
    length = rng.geometric(1 / 3, contacts)
    keep = np.cumsum(length) <= rows
    length = length[keep]
    length[-1] += rows - length.sum()
    i = rng.integers(0, agents, len(length))
    j = (i + rng.integers(1, agents, len(length))) % agents
    start = 20 * rng.integers(1, 10_000, len(length))
    first = np.repeat(np.cumsum(length) - length, length)
    t = np.repeat(start, length) + 20 * (np.arange(length.sum()) - first)
    i, j = np.repeat(i, length), np.repeat(j, length)
    order = np.argsort(t, kind="stable")
    klass = np.asarray([f"{k}A" for k in range(classes)])[np.arange(agents) % classes]
    table = pa.table({"t": t[order], "i": 1000 + i[order], "j": 1000 + j[order],
                      "ci": klass[i[order]], "cj": klass[j[order]]})
    pcsv.write_csv(table, path, pcsv.WriteOptions(include_header=False, delimiter="\t", quoting_style="none"))


def csv_trace(path: Path, rows: int, rng) -> None:
    """``t,a,b`` rows with text IDs, strictly increasing times (no duplicate events)."""
    agents = 2000
    a = rng.integers(0, agents, rows)
    b = (a + rng.integers(1, agents, rows)) % agents
    names = np.asarray([f"agent-{k}" for k in range(agents)])
    table = pa.table({"t": np.round(np.arange(rows) * 0.05, 2), "a": names[a], "b": names[b]})
    pcsv.write_csv(table, path)


def measure(fn):
    """(median seconds of REPEATS runs, peak RSS bytes above baseline of one more run, result)."""
    times = []
    for _ in range(REPEATS):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    result, _, peak, _ = run_measured(fn)
    return statistics.median(times), peak, result


def main() -> None:
    # Arrow's default pool (jemalloc / mimalloc) keeps freed memory, which would hide
    # later runs' allocations from the RSS peak; the system allocator hands it back.
    pa.set_memory_pool(pa.system_memory_pool())
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="10^5 rows instead of 10^6")
    args = parser.parse_args()
    rows = 100_000 if args.quick else 1_000_000
    rng = np.random.default_rng(0)
    print(f"# bench_ingest: {rows:,} rows; {machine()}; revision {revision()}")
    bound = BOUND_BYTES_PER_ROW * rows + BOUND_FIXED_BYTES
    print(f"peak RSS bound: {BOUND_BYTES_PER_ROW} bytes/row + {BOUND_FIXED_BYTES / 1e6:.0f} MB = {bound / 1e6:.0f} MB\n")
    print("| trace | input MB | events | ingest s (median) | pyarrow read_csv s | time ratio "
          "| ingest peak MB | read_csv peak MB | peak ratio | peak bytes/row | within bound |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    failed = False
    with tempfile.TemporaryDirectory() as tmp:
        cases = [("sociopatterns", Path(tmp) / "tij.dat", sociopatterns_trace,
                  pcsv.ParseOptions(delimiter="\t"), pcsv.ReadOptions(autogenerate_column_names=True)),
                 ("csv", Path(tmp) / "events.csv", csv_trace, pcsv.ParseOptions(), pcsv.ReadOptions())]
        for fmt, path, make, parse, read in cases:
            make(path, rows, rng)
            seconds, peak, (log, report) = measure(lambda: read_trace(path, fmt))
            assert report.lines == rows and report.skipped == 0
            base_seconds, base_peak, _ = measure(
                lambda: pcsv.read_csv(path, read_options=read, parse_options=parse))
            per_row = peak / rows
            ok = peak <= bound
            failed |= not ok
            print(f"| {fmt} | {path.stat().st_size / 1e6:.1f} | {log.n_events:,} | {seconds:.2f} | "
                  f"{base_seconds:.2f} | {seconds / base_seconds:.1f} | {peak / 1e6:.0f} | {base_peak / 1e6:.0f} | "
                  f"{peak / max(base_peak, 1):.1f} | "
                  f"{per_row:.0f} | {'yes' if ok else 'NO'} |")
    if failed:
        print(f"\nFAILED: an ingest's peak RSS exceeded the bound of {bound / 1e6:.0f} MB")
        sys.exit(1)


if __name__ == "__main__":
    main()
