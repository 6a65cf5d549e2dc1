"""Fingerprints of maps through the command line, to show a refactor changed no answer.

    python lab/map_fingerprints.py OUT.json [--logs DIR]

Simulates a fixed set of logs (random arenas with 0-3 holes, two rooms, a contact trace
read as encounters only), maps each with the default pipeline and with ``--paper``, and
writes a SHA-256 per map.json with the fields that vary run to run (timings, software
versions) removed.  Run it before and after a change and compare the two files: equal
hashes mean byte-identical maps.  Only the CLI is used, so it works across layouts.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import shutil
import subprocess
import sys
from pathlib import Path

CASES = [  # (name, simulate options)
    ("holes0", ["--holes", "0", "--agents", "200", "--duration", "30", "--seed", "11"]),
    ("holes1", ["--holes", "1", "--agents", "300", "--duration", "30", "--seed", "12"]),
    ("holes2", ["--holes", "2", "--agents", "200", "--duration", "45", "--seed", "13"]),
    ("holes3", ["--holes", "3", "--agents", "400", "--duration", "40", "--seed", "14"]),
    ("static", ["--holes", "1", "--agents", "250", "--duration", "30", "--seed", "15",
                "--static-fraction", "0.2"]),
]
MAPS = [("default", []), ("paper", ["--paper"])]


def run(*args: str) -> None:
    done = subprocess.run([sys.executable, "-m", "swarmtopo", *args], capture_output=True, text=True)
    if done.returncode:
        raise SystemExit(f"swarmtopo {' '.join(args)} failed: {done.stderr.strip()}")


def fingerprint(map_json: Path) -> str:
    doc = json.loads(map_json.read_text())
    doc.pop("timings", None)
    doc.pop("software", None)
    return hashlib.sha256(json.dumps(doc, sort_keys=True).encode()).hexdigest()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--logs", type=Path, default=Path("fingerprint-logs"))
    args = parser.parse_args()
    prints: dict[str, str] = {}
    for name, options in CASES:
        log = args.logs / name
        if log.exists():
            shutil.rmtree(log)
        run("simulate", *options, "--out", str(log), "--quiet")
        prints[f"{name}/log"] = hashlib.sha256((log / "events.csv").read_bytes()
                                               + (log / "status.csv").read_bytes()).hexdigest()
        trace = args.logs / f"{name}-trace"  # the same encounters, no status: read as a contact trace
        if trace.exists():
            shutil.rmtree(trace)
        trace.mkdir(parents=True)
        shutil.copy(log / "events.csv", trace / "events.csv")
        for label, flags in MAPS + [("trace", [])]:
            source = trace if label == "trace" else log
            out = args.logs / f"{name}-{label}-map"
            if out.exists():
                shutil.rmtree(out)
            run("map", str(source), "--out", str(out), "--quiet", *flags)
            prints[f"{name}/{label}"] = fingerprint(out / "map.json")
            print(name, label, prints[f"{name}/{label}"][:12], flush=True)
    args.out.write_text(json.dumps(prints, indent=1, sort_keys=True) + "\n")


if __name__ == "__main__":
    main()
