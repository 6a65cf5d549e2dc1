"""Ingest of proximity traces: each format on hand-written files, malformed lines,
--skip-bad, string IDs, SocioPatterns window merging, ONE up/down, and the CLI."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from swarmtopo.errors import InputError
from swarmtopo.ingest import ingest
from swarmtopo.io import read_log, write_log

SCRIPT = "<script>alert(1)</script>"


def write(tmp_path, name, text, mode="w"):
    path = tmp_path / name
    if mode == "w":
        path.write_text(text)
    else:
        path.write_bytes(text)
    return path


def events(log):
    """The log's events as (t, id, id) tuples with the pair in sorted-ID order."""
    return [(float(t), *sorted((str(x), str(y)))) for t, x, y in zip(log.t, log.ids_of(log.a), log.ids_of(log.b))]


# -- SocioPatterns -------------------------------------------------------------------------
def test_sociopatterns_windows_merge_into_encounters_at_their_first_window_start(tmp_path):
    # pair (1,2): windows ending at 20, 40, 60 are one contact (0, 60] -> encounter at 0;
    # the window ending at 120 follows a gap -> a second encounter at 100.  Pair (3,4)
    # once at 40 -> 20.  The pair is unordered ("2 1" continues "1 2"); blanks and tabs mix.
    path = write(tmp_path, "tij.dat", "20 1 2 A B\n40\t1\t2\tA\tB\n60 2  1 B A\n120 1 2 A B\n\n40 3 4 A C\n")
    log, report = ingest(path, "sociopatterns")
    assert events(log) == [(0.0, "1", "2"), (20.0, "3", "4"), (100.0, "1", "2")]
    assert log.agent_ids.tolist() == [1, 2, 3, 4]  # plain integers become integer IDs
    assert report.counts == {"blank_lines": 1, "windows": 5, "merged_windows": 2}
    assert log.meta["ingest"]["agent_classes"] == {"1": "A", "2": "B", "3": "A", "4": "C"}


def test_sociopatterns_window_length_is_configurable(tmp_path):
    # with w = 30, windows at 30 and 60 touch (merge), 100 is 40 s later (new encounter)
    path = write(tmp_path, "tij.dat", "30 a b\n60 a b\n100 a b\n")
    log, _ = ingest(path, "sociopatterns", window=30)
    assert events(log) == [(0.0, "a", "b"), (70.0, "a", "b")]


@pytest.mark.parametrize("line, column, value, reason", [
    ("4x 1 2 A B", "t", "4x", "time is not a number"),
    ("nan 1 2 A B", "t", "nan", "time is not a number"),
    ("10 1 2 A B", "t", "10", "time is less than the window"),
    ("60 2 2 B B", "j", "2", "an agent cannot encounter itself"),
    ("80 1", "fields", "2", "expected 3 or 5 fields"),
    ("80 1 2 A", "fields", "4", "expected 3 or 5 fields"),
])
def test_sociopatterns_malformed_line_names_file_line_field_and_value(tmp_path, line, column, value, reason):
    path = write(tmp_path, "tij.dat", f"20 1 2 A B\n40 1 2 A B\n{line}\n60 1 2 A B\n")
    with pytest.raises(InputError) as caught:
        ingest(path, "sociopatterns")
    exc = caught.value
    assert (exc.row, exc.column, str(exc.value)) == (3, column, value)
    assert reason in str(exc) and "tij.dat" in str(exc) and "row 3" in str(exc)


def test_first_malformed_line_is_reported_whichever_check_finds_it(tmp_path):
    # line 2 has a bad ID pair, line 3 a bad time: the error is at line 2
    path = write(tmp_path, "tij.dat", "20 1 2\n40 5 5\n4x 1 2\n")
    with pytest.raises(InputError) as caught:
        ingest(path, "sociopatterns")
    assert caught.value.row == 2


def test_skip_bad_skips_and_counts_every_malformed_line(tmp_path):
    path = write(tmp_path, "tij.dat", "20 1 2 A B\n4x 1 2 A B\n40 1 2 A B\n60 2 2 B B\n80 1\n"
                                      "10 1 3 A B\n".encode() + b"100 \xff 2 A B\n" + b"120 1 2 A B\n", "wb")
    log, report = ingest(path, "sociopatterns", skip_bad=True)
    assert events(log) == [(0.0, "1", "2"), (100.0, "1", "2")]
    assert report.skipped == 5 and report.lines == 8
    assert [e.split(", ")[1] for e in report.examples] == ["row 2", "row 4", "row 5", "row 6", "row 7"]
    assert log.meta["ingest"]["skipped_lines"] == 5


def test_sociopatterns_agent_with_two_classes_is_refused(tmp_path):
    path = write(tmp_path, "tij.dat", "20 1 2 A B\n40 1 3 C B\n")
    with pytest.raises(InputError, match="already has class 'A'") as caught:
        ingest(path, "sociopatterns")
    assert (caught.value.row, caught.value.column, caught.value.value) == (2, "Ci", "C")


# -- ONE -----------------------------------------------------------------------------------
def test_one_encounter_at_each_up_that_opens_a_connection(tmp_path):
    text = ("0 CONN 1 2 up\n"      # opens 1-2: encounter at 0
            "5 CONN 2 1 up\n"      # 1-2 already up: same contact (repeated_up)
            "6 CONN 1 2 down\n"    # closes 1-2
            "7 CONN 3 4 down\n"    # nothing open (unmatched_down)
            "8 CONN 1 2 up\n"      # reopens: encounter at 8, never closed (open_at_end)
            "9 C M1 1 2 100\n"     # a message event: counted, ignored
            "10 CONN 2 3 up\n"     # encounter at 10, open at end
            "10 CONN 2 3 down\n")  # same time, later line: closes it
    log, report = ingest(write(tmp_path, "one.txt", text), "one")
    assert events(log) == [(0.0, "1", "2"), (8.0, "1", "2"), (10.0, "2", "3")]
    assert report.counts == {"blank_lines": 0, "other_events": 1, "repeated_up": 1, "unmatched_down": 1,
                             "open_at_end": 1}


def test_one_bad_state_is_malformed(tmp_path):
    path = write(tmp_path, "one.txt", "0 CONN a b up\n3 CONN a b sideways\n")
    with pytest.raises(InputError, match="up or down") as caught:
        ingest(path, "one")
    assert (caught.value.row, caught.value.column, caught.value.value) == (2, "up|down", "sideways")
    log, report = ingest(path, "one", skip_bad=True)
    assert events(log) == [(0.0, "a", "b")] and report.skipped == 1


# -- CSV / Parquet -------------------------------------------------------------------------
def test_csv_string_ids_survive_verbatim_and_columns_are_configurable(tmp_path):
    path = write(tmp_path, "trace.csv", f"time,p,q,extra\n1.5,x,y,0\n2,{SCRIPT},007,0\n3,x,007,0\n")
    log, _ = ingest(path, "csv", time_column="time", a_column="p", b_column="q")
    assert SCRIPT in log.agent_ids.tolist() and "007" in log.agent_ids.tolist()
    assert events(log) == [(1.5, "x", "y"), (2.0, "007", SCRIPT), (3.0, "007", "x")]
    out = tmp_path / "log"
    write_log(log, out)
    assert SCRIPT in read_log(out).agent_ids.tolist()


def test_csv_malformed_rows_error_and_skip(tmp_path):
    path = write(tmp_path, "trace.csv", "t,a,b\n1,x,y\n2,x\n3,,y\nzz,x,y\n5,x,x\n-1,x,y\n6,u,v\n")
    with pytest.raises(InputError) as caught:
        ingest(path, "csv")
    assert caught.value.row == 2 and "expected 3 fields, found 2" in str(caught.value)
    log, report = ingest(path, "csv", skip_bad=True)
    assert events(log) == [(1.0, "x", "y"), (6.0, "u", "v")]
    assert report.skipped == 5
    assert [(e.split(", ")[1]) for e in report.examples] == ["row 2", "row 3", "row 4", "row 5", "row 6"]
    assert "value 'zz': time is not a number" in report.examples[2]


def test_csv_missing_column_is_named(tmp_path):
    path = write(tmp_path, "trace.csv", "time,a,b\n1,x,y\n")
    with pytest.raises(InputError, match="missing column 't'; found columns: 'time', 'a', 'b'"):
        ingest(path, "csv")


def test_csv_duplicate_event_error_names_the_file_row(tmp_path):
    # row numbers of the log's own checks are mapped back to file rows past skipped ones
    path = write(tmp_path, "trace.csv", "t,a,b\nbad,x,y\n1,x,y\n1,y,x\n")
    with pytest.raises(InputError, match="duplicate event") as caught:
        ingest(path, "csv", skip_bad=True)
    assert caught.value.row == 3


def test_parquet_with_numeric_and_text_columns(tmp_path):
    path = tmp_path / "trace.parquet"
    pq.write_table(pa.table({"t": [1.0, 2.0, float("nan")], "a": ["s1", SCRIPT, "s3"], "b": ["s2", "s1", "s1"]}), path)
    with pytest.raises(InputError, match="finite") as caught:
        ingest(path, "parquet")
    assert caught.value.row == 3
    log, report = ingest(path, "parquet", skip_bad=True)
    assert events(log) == [(1.0, "s1", "s2"), (2.0, SCRIPT, "s1")] and report.skipped == 1


def test_streaming_blocks_give_the_same_log_as_one_block(tmp_path, monkeypatch):
    # many tiny blocks: lines cut at block edges, line numbers carried across blocks
    rng = np.random.default_rng(3)
    lines = [f"{20 * k} {i} {j} X X" for k, (i, j) in enumerate(rng.integers(0, 9, (400, 2)), 1) if i != j]
    path = write(tmp_path, "tij.dat", "\n".join(lines[:150] + ["oops"] + lines[150:]) + "\n")
    whole, whole_report = ingest(path, "sociopatterns", skip_bad=True)
    monkeypatch.setattr("swarmtopo.ingest._BLOCK", 97)
    small, small_report = ingest(path, "sociopatterns", skip_bad=True)
    assert events(whole) == events(small) and whole_report == small_report
    assert small_report.examples[0].split(", ")[1] == "row 151"


# -- CLI -----------------------------------------------------------------------------------
def run_cli(*args):
    return subprocess.run([sys.executable, "-m", "swarmtopo", *map(str, args)], capture_output=True, text=True)


def test_cli_ingest_then_map(tmp_path):
    # two groups of 6 agents that only meet inside their group, 60 windows each: a log
    # with enough events per group for the map to count two regions (beta_0 = 2)
    rng = np.random.default_rng(0)
    lines = []
    for group in (0, 1):
        members = [f"g{group}-{k}" for k in range(6)]
        for w in range(1, 400):
            i, j = rng.choice(6, 2, replace=False)
            lines.append(f"{20 * w} {members[i]} {members[j]} G{group} G{group}")
    trace = write(tmp_path, "tij.dat", "\n".join(lines) + "\nbroken line\n")
    out = tmp_path / "log"
    bad = run_cli("ingest", trace, "--format", "sociopatterns", "--out", out)
    assert bad.returncode == 1 and "row 799" in bad.stderr and "'fields'" in bad.stderr
    ok = run_cli("ingest", trace, "--format", "sociopatterns", "--out", out, "--skip-bad")
    assert ok.returncode == 0, ok.stderr
    assert "skipped 1 malformed line(s)" in ok.stdout
    meta = json.loads((out / "meta.json").read_text())
    assert meta["ingest"]["skipped_lines"] == 1 and meta["ingest"]["format"] == "sociopatterns"
    mapped = run_cli("map", out, "--quiet")
    assert mapped.returncode == 0, mapped.stderr
    result = json.loads((out / "map" / "map.json").read_text())
    assert result["betti"]["0"] == 2


def test_cli_unknown_format_is_a_usage_error(tmp_path):
    trace = write(tmp_path, "t.csv", "t,a,b\n1,x,y\n")
    result = run_cli("ingest", trace, "--format", "json", "--out", tmp_path / "o")
    assert result.returncode == 2 and "'json' is not one of csv, parquet, sociopatterns, one" in result.stderr


def test_csv_streaming_blocks_keep_row_numbers(tmp_path, monkeypatch):
    # a structurally bad row and a bad time far apart, read in ~100-byte blocks: the
    # data rows named in the messages are those of the file
    rows = [f"{k},a{k % 7},b{k % 5}" for k in range(1, 300)]
    rows[49] = "50,a1"        # data row 50: two fields
    rows[199] = "x200,a1,b1"  # data row 200: bad time
    path = write(tmp_path, "trace.csv", "t,a,b\n" + "\n".join(rows) + "\n")
    monkeypatch.setattr("swarmtopo.ingest._BLOCK", 100)
    log, report = ingest(path, "csv", skip_bad=True)
    assert report.skipped == 2 and log.n_events == 297 and report.lines == 299
    assert [e.split(", ")[1] for e in report.examples] == ["row 50", "row 200"]


def test_earliest_malformed_line_wins_over_a_later_non_utf8_line(tmp_path):
    path = write(tmp_path, "tij.dat", b"20 1 2\n40 1\n60 \xff 2\n", "wb")
    with pytest.raises(InputError, match="expected 3 or 5 fields") as caught:
        ingest(path, "sociopatterns")
    assert caught.value.row == 2
    path = write(tmp_path, "tij2.dat", b"20 1 2\n40 \xff 2\n60 1\n", "wb")
    with pytest.raises(InputError, match="not UTF-8") as caught:
        ingest(path, "sociopatterns")
    assert caught.value.row == 2


def test_trace_without_encounters_is_refused(tmp_path):
    path = write(tmp_path, "tij.dat", "\n4x 1 2\n")
    expected = r"no encounters in the trace \(2 lines read, 1 skipped as malformed, 1 blank\)"
    with pytest.raises(InputError, match=expected):
        ingest(path, "sociopatterns", skip_bad=True)


def test_cli_ingest_help_shows_an_example():
    result = run_cli("ingest", "--help")
    assert result.returncode == 0 and "Example: swarmtopo ingest" in result.stdout
