"""The sweep store at scale: row size, write and read rates, and a 10^5-job sweep end to end.

1. Realistic rows: ``--realistic`` jobs of 200 agents x 120 s (random arenas, 1-3 square
   holes; the default map) swept on the local cluster with every window's diagram kept.
   Bytes per row of its ``diagrams``: as JSON text (``Diagram.to_json`` of every region
   and window: the baseline) and as the compressed BLOB of each ``[sweep] diagrams``
   level.  Then bytes per row on disk for each level: ``--copies``
   copies of each row (distinct keys, every value scaled by 1 + 1e-9 i so that no two
   copies share one) written to a fresh store ``SMALL_BATCH`` rows per transaction (a
   sweep of slow jobs writes a few rows a second; each write rewrites the table's last
   row group, which leaves freed blocks in the file), file size / rows, extrapolated to
   100,000 rows.
2. Writing: the level-"map" copies of part 1 written one
   transaction per row on a held connection with the diagrams as JSON text (the
   baseline) and in batches of ``FLUSH_ROWS`` with the BLOB
   (``ResultStore.write``): rows per second and the ratio.
3. Reading: level-"windows" stores of ``--stream-rows`` rows and twice as many (part 1's
   rows again under new keys) streamed back with ``iter_jobs`` (every column, every
   diagram decoded): rows per second and the peak memory above the start, which must
   not grow with the store.
4. ``--jobs N`` (default 100,000; 0 skips it), in a fresh process: a sweep of N cheap
   jobs (1 agent for 1 s: a real simulate-and-map job that stops at "too little data")
   on the local cluster (``--workers``, default 2): wall time, jobs per minute, the peak
   resident memory of the process (the client, with the local cluster's scheduler in
   it), and the store's size.

    python benchmarks/bench_store.py [--realistic 24] [--copies 40] [--jobs 100000] [--workers 2]
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _measure import machine, revision, run_measured
from swarmtopo.experiments.grid import KEEP_LEVELS, expand_grid
from swarmtopo.experiments.store import JOB_COLUMNS, ResultStore, decode_regions, encode_regions, iter_jobs
from swarmtopo.experiments.sweep import FLUSH_ROWS, run_sweep
from swarmtopo.topology.persistence import Diagram

SCALE = 100_000
SMALL_BATCH = 10


def realistic_jobs(n: int):
    grid = {"sweep": {"name": "realistic", "replicates": n, "salt": "bench-store"},
            "arena": {"holes": [1, 2, 3]}, "swarm": {"agents": 200, "duration": 120.0}}
    return expand_grid(grid).jobs[:n]


def kept(regions, keep: str):
    """The regions with only the diagrams ``keep`` keeps."""
    return [{**{k: v for k, v in r.items() if k not in ("diagram", "windows")},
             "windows": [{k: v for k, v in w.items() if k != "diagram" or keep == "windows"} for w in r["windows"]],
             **({"diagram": r["diagram"]} if keep != "none" else {})} for r in regions]


def json_text(regions) -> str:
    """The regions as JSON text, each Diagram as to_json (the baseline format)."""
    return json.dumps(regions, sort_keys=True, allow_nan=False,
                      default=lambda x: x.to_json() if isinstance(x, Diagram) else x)


def copies(rows, regions, n: int, keep: str):
    """n copies of each row with distinct keys, diagrams kept at ``keep``, every bar and
    H1 length scaled by 1 + 1e-9 i: no two copies share a value, so the store cannot
    fold them together (DuckDB's dictionary compression would, and real rows differ)."""
    out = []
    for row, region in zip(rows, regions):
        for i in range(n):
            factor = 1.0 + 1e-9 * i
            blob = encode_regions(_scaled(kept(region, keep), factor))
            out.append({**row, "key": f"{row['key']}-{i}", "diagrams": blob, "diagrams_kept": keep,
                        "lengths_h1": [x * factor for x in row["lengths_h1"]]})
    return out


def _scaled(item, factor: float):
    if isinstance(item, Diagram):
        return Diagram(tuple(p * factor for p in item.pairs), item.backend)
    if isinstance(item, dict):
        return {k: _scaled(v, factor) for k, v in item.items()}
    if isinstance(item, list):
        return [_scaled(v, factor) for v in item]
    return item


def row_count(path: Path) -> int:
    import duckdb

    with duckdb.connect(str(path), read_only=True) as db:
        return db.execute("SELECT count(*) FROM jobs").fetchone()[0]


def per_row_baseline(rows, path: Path) -> float:
    """Seconds to write rows one transaction each on a held connection, diagrams as JSON text."""
    import duckdb

    names = [name for name, _ in JOB_COLUMNS]
    columns = ", ".join(f'"{n}" {"JSON" if n == "diagrams" else sql}' for n, sql in JOB_COLUMNS)
    with duckdb.connect(str(path)) as db:
        db.execute(f"CREATE TABLE jobs ({columns})")
        insert = f"INSERT INTO jobs VALUES ({', '.join('?' * len(names))})"
        start = time.perf_counter()
        for row in rows:
            values = dict(row, diagrams=json_text(decode_regions(row["diagrams"])))
            db.execute(insert, [json.dumps(values[n], sort_keys=True) if n in ("config", "versions") else values[n]
                                for n in names])
        return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--realistic", type=int, default=24, help="realistic jobs run (default 24)")
    parser.add_argument("--copies", type=int, default=40, help="copies of each row written in parts 1 and 2 (default 40)")
    parser.add_argument("--stream-rows", type=int, default=4096, help="rows of the first store streamed in part 3")
    parser.add_argument("--jobs", type=int, default=SCALE, help="cheap jobs of the end-to-end sweep (0: skip)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--sweep-only", action="store_true", help=argparse.SUPPRESS)  # part 4 in a fresh process
    args = parser.parse_args()
    if args.sweep_only:
        print(f"# bench_store --sweep-only  {revision()}  {machine()}", flush=True)
        cheap_sweep(args.jobs, args.workers)
        return
    print(f"# bench_store  {revision()}  {machine()}\n")

    with tempfile.TemporaryDirectory() as tmp:
        source = Path(tmp) / "realistic.duckdb"
        start = time.perf_counter()
        summary = run_sweep(realistic_jobs(args.realistic), source, workers=args.workers, keep="windows")
        assert summary.run == args.realistic and not summary.failed
        rows = list(iter_jobs(source))
        print(f"1. {len(rows)} realistic rows (200 agents x 120 s, 1-3 holes, every window's diagram kept), "
              f"mapped in {time.perf_counter() - start:.0f} s on {args.workers} workers")
        regions = [row["diagrams"] for row in rows]
        sizes = {"JSON text (every window)": [len(json_text(r).encode()) for r in regions]}
        for keep in KEEP_LEVELS:
            sizes[f"BLOB, diagrams = {keep!r}"] = [len(encode_regions(kept(r, keep))) for r in regions]
        for name, values in sizes.items():
            print(f"   diagrams column, {name:<30} {statistics.median(values) / 1e3:9.1f} KB per row (median)")

        print(f"\n   on disk ({args.copies} copies of each row, their values scaled apart, written {SMALL_BATCH} "
              "at a time as a sweep of slow jobs writes them; file size / rows):")
        for keep in KEEP_LEVELS:
            path = Path(tmp) / f"{keep}.duckdb"
            store = ResultStore(path)
            level = copies(rows, regions, args.copies, keep)
            for i in range(0, len(level), SMALL_BATCH):
                assert store.write(level[i:i + SMALL_BATCH])
            per_row = path.stat().st_size / len(level)
            print(f"   diagrams = {keep!r:<10} {per_row / 1e3:8.1f} KB per row -> "
                  f"{per_row * SCALE / 1e9:6.2f} GB for {SCALE:,} rows")

        batch = copies(rows, regions, args.copies, "map")
        baseline = per_row_baseline(batch, Path(tmp) / "baseline.duckdb")
        store = ResultStore(Path(tmp) / "batched.duckdb")
        start = time.perf_counter()
        for i in range(0, len(batch), FLUSH_ROWS):
            assert store.write(batch[i:i + FLUSH_ROWS])
        batched = time.perf_counter() - start
        print(f"\n2. writing {len(batch)} rows (diagrams = 'map'): one transaction per row, JSON "
              f"{len(batch) / baseline:7.0f} rows/s; batches of {FLUSH_ROWS}, BLOB {len(batch) / batched:7.0f} rows/s "
              f"({baseline / batched:.1f}x)")

        # stores of 1x and 2x --stream-rows rows of level "windows" (part 1's rows again
        # under new keys: DuckDB stores a repeated value once, reading expands each row)
        blobs = [encode_regions(region) for region in regions]
        peaks = []
        for n in (args.stream_rows, 2 * args.stream_rows):
            path = Path(tmp) / f"stream-{n}.duckdb"
            store = ResultStore(path)
            level = [{**row, "key": f"{row['key']}-{i}", "diagrams": blob}
                     for i in range(-(-n // len(rows))) for row, blob in zip(rows, blobs)]
            for i in range(0, len(level), FLUSH_ROWS):
                assert store.write(level[i:i + FLUSH_ROWS])

            def stream():
                return sum(p.nbytes for row in iter_jobs(path) for region in row["diagrams"]
                           for w in region["windows"] for p in w["diagram"].pairs), row_count(path)
            (decoded, count), seconds, peak, _ = run_measured(stream)
            peaks.append(peak)
            print(f"{'3.' if len(peaks) == 1 else '  '} streaming {count} rows (every column, every window's "
                  f"diagram decoded: {decoded / 1e9:.1f} GB): {count / seconds:.0f} rows/s, "
                  f"peak {peak / 1e6:.0f} MB above the start")
        print(f"   twice the rows, {peaks[1] / peaks[0]:.2f}x the peak")

    if args.jobs:  # a fresh process, so that its peak memory is the sweep's alone
        subprocess.run([sys.executable, __file__, "--sweep-only", "--jobs", str(args.jobs),
                        "--workers", str(args.workers)], check=True)


def cheap_sweep(n: int, workers: int) -> None:
    grid = {"sweep": {"name": "cheap", "replicates": n, "salt": "bench-store"},
            "swarm": {"agents": 1, "duration": 1.0}}
    cheap = expand_grid(grid).jobs
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "cheap.duckdb"
        summary, wall, _, _ = run_measured(lambda: run_sweep(cheap, path, workers=workers))
        assert summary.run == n
        peak = _peak_rss_mb()
        size = path.stat().st_size
        alone = statistics.median(r["t_total"] for r in iter_jobs(path, columns=("key", "t_total")))
    print(f"\n4. {n:,} cheap jobs on {workers} local workers: {wall / 60:.1f} min, {60 * n / wall:,.0f} jobs/min; "
          f"client peak RSS {peak:.0f} MB (the whole process: the client and the local cluster's scheduler); "
          f"store {size / 1e6:.1f} MB ({size / n:.0f} B per row); one job alone {alone * 1e3:.1f} ms (median)")


def _peak_rss_mb() -> float:
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1e3
    return float("nan")

if __name__ == "__main__":
    main()
