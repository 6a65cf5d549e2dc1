"""Ingest of proximity traces: each format on hand-written files, malformed lines,
--skip-bad, string IDs, SocioPatterns window merging, ONE up/down, and the CLI."""

from __future__ import annotations

import gzip
import json
import os

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from swarmtopo.errors import InputError, SwarmtopoError
from swarmtopo.io import read_trace
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
    log, report = read_trace(path, "sociopatterns")
    assert events(log) == [(0.0, "1", "2"), (20.0, "3", "4"), (100.0, "1", "2")]
    assert log.agent_ids.tolist() == [1, 2, 3, 4]  # plain integers become integer IDs
    assert report.counts == {"blank_lines": 1, "windows": 5, "merged_windows": 2}
    assert log.meta["ingest"]["agent_classes"] == {"1": "A", "2": "B", "3": "A", "4": "C"}


def test_sociopatterns_window_length_is_configurable(tmp_path):
    # with w = 30, windows at 30 and 60 touch (merge), 100 is 40 s later (new encounter)
    path = write(tmp_path, "tij.dat", "30 a b\n60 a b\n100 a b\n")
    log, _ = read_trace(path, "sociopatterns", window=30)
    assert events(log) == [(0.0, "a", "b"), (70.0, "a", "b")]


@pytest.mark.parametrize("line, column, value, reason", [
    ("4x 1 2 A B", "t", "4x", "time is not a number"),
    ("nan 1 2 A B", "t", "nan", "time is not a number"),
    ("10 1 2 A B", "t", "10", "time is less than the window"),
    ("60 2 2 B B", "j", "2", "an agent cannot encounter itself"),
    ("80 1", None, "80 1", "expected 3 or 5 fields"),
    ("80  1 2\tA", None, "80 1 2 A", "expected 3 or 5 fields"),
])
def test_sociopatterns_malformed_line_names_file_line_field_and_value(tmp_path, line, column, value, reason):
    path = write(tmp_path, "tij.dat", f"20 1 2 A B\n40 1 2 A B\n{line}\n60 1 2 A B\n")
    with pytest.raises(InputError) as caught:
        read_trace(path, "sociopatterns")
    exc = caught.value
    assert (exc.row, exc.column, str(exc.value)) == (3, column, value)
    assert reason in str(exc) and "tij.dat" in str(exc) and "row 3" in str(exc)


def test_first_malformed_line_is_reported_whichever_check_finds_it(tmp_path):
    # line 2 has a bad ID pair, line 3 a bad time: the error is at line 2
    path = write(tmp_path, "tij.dat", "20 1 2\n40 5 5\n4x 1 2\n")
    with pytest.raises(InputError) as caught:
        read_trace(path, "sociopatterns")
    assert caught.value.row == 2


def test_skip_bad_skips_and_counts_every_malformed_line(tmp_path):
    path = write(tmp_path, "tij.dat", "20 1 2 A B\n4x 1 2 A B\n40 1 2 A B\n60 2 2 B B\n80 1\n"
                                      "10 1 3 A B\n".encode() + b"100 \xff 2 A B\n" + b"120 1 2 A B\n", "wb")
    log, report = read_trace(path, "sociopatterns", skip_bad=True)
    assert events(log) == [(0.0, "1", "2"), (100.0, "1", "2")]
    assert report.skipped == 5 and report.lines == 8
    assert [e.split(", ")[1].split(":")[0] for e in report.examples] == ["row 2", "row 4", "row 5", "row 6", "row 7"]
    assert log.meta["ingest"]["skipped_lines"] == 5


def test_sociopatterns_agent_with_two_classes_is_refused(tmp_path):
    path = write(tmp_path, "tij.dat", "20 1 2 A B\n40 1 3 C B\n")
    with pytest.raises(InputError, match="already has class 'A'") as caught:
        read_trace(path, "sociopatterns")
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
    log, report = read_trace(write(tmp_path, "one.txt", text), "one")
    assert events(log) == [(0.0, "1", "2"), (8.0, "1", "2"), (10.0, "2", "3")]
    assert report.counts == {"blank_lines": 0, "other_events": 1, "repeated_up": 1, "reopened_at_once": 0,
                             "unmatched_down": 1, "open_at_end": 1}


def test_one_bad_state_is_malformed(tmp_path):
    path = write(tmp_path, "one.txt", "0 CONN a b up\n3 CONN a b sideways\n")
    with pytest.raises(InputError, match="up or down") as caught:
        read_trace(path, "one")
    assert (caught.value.row, caught.value.column, caught.value.value) == (2, "up|down", "sideways")
    log, report = read_trace(path, "one", skip_bad=True)
    assert events(log) == [(0.0, "a", "b")] and report.skipped == 1


# -- CSV / Parquet -------------------------------------------------------------------------
def test_csv_string_ids_survive_verbatim_and_columns_are_configurable(tmp_path):
    path = write(tmp_path, "trace.csv", f"time,p,q,extra\n1.5,x,y,0\n2,{SCRIPT},007,0\n3,x,007,0\n")
    log, _ = read_trace(path, "csv", time_column="time", a_column="p", b_column="q")
    assert SCRIPT in log.agent_ids.tolist() and "007" in log.agent_ids.tolist()
    assert events(log) == [(1.5, "x", "y"), (2.0, "007", SCRIPT), (3.0, "007", "x")]
    out = tmp_path / "log"
    write_log(log, out)
    assert SCRIPT in read_log(out).agent_ids.tolist()


def test_csv_malformed_rows_error_and_skip(tmp_path):
    path = write(tmp_path, "trace.csv", "t,a,b\n1,x,y\n2,x\n3,,y\nzz,x,y\n5,x,x\n-1,x,y\n6,u,v\n")
    with pytest.raises(InputError) as caught:
        read_trace(path, "csv")
    assert caught.value.row == 2 and "expected 3 fields, found 2" in str(caught.value)
    log, report = read_trace(path, "csv", skip_bad=True)
    assert events(log) == [(1.0, "x", "y"), (6.0, "u", "v")]
    assert report.skipped == 5
    assert [(e.split(", ")[1]) for e in report.examples] == ["row 2", "row 3", "row 4", "row 5", "row 6"]
    assert "value 'zz': time is not a number" in report.examples[2]


def test_csv_missing_column_is_named(tmp_path):
    path = write(tmp_path, "trace.csv", "time,a,b\n1,x,y\n")
    with pytest.raises(InputError, match="missing column 't'; found columns: 'time', 'a', 'b'"):
        read_trace(path, "csv")


def test_csv_duplicate_event_error_names_the_file_row(tmp_path):
    # row numbers of the log's own checks are mapped back to file rows past skipped ones
    path = write(tmp_path, "trace.csv", "t,a,b\nbad,x,y\n1,x,y\n1,y,x\n")
    with pytest.raises(InputError, match="duplicate event") as caught:
        read_trace(path, "csv", skip_bad=True)
    assert caught.value.row == 3


def test_parquet_with_numeric_and_text_columns(tmp_path):
    path = tmp_path / "trace.parquet"
    pq.write_table(pa.table({"t": [1.0, 2.0, float("nan")], "a": ["s1", SCRIPT, "s3"], "b": ["s2", "s1", "s1"]}), path)
    with pytest.raises(InputError, match="finite") as caught:
        read_trace(path, "parquet")
    assert caught.value.row == 3
    log, report = read_trace(path, "parquet", skip_bad=True)
    assert events(log) == [(1.0, "s1", "s2"), (2.0, SCRIPT, "s1")] and report.skipped == 1


def test_streaming_blocks_give_the_same_log_as_one_block(tmp_path, monkeypatch):
    # many tiny blocks: lines cut at block edges, line numbers carried across blocks
    rng = np.random.default_rng(3)
    lines = [f"{20 * k} {i} {j} X X" for k, (i, j) in enumerate(rng.integers(0, 9, (400, 2)), 1) if i != j]
    path = write(tmp_path, "tij.dat", "\n".join(lines[:150] + ["oops"] + lines[150:]) + "\n")
    whole, whole_report = read_trace(path, "sociopatterns", skip_bad=True)
    monkeypatch.setattr("swarmtopo.io.traces._BLOCK", 97)
    small, small_report = read_trace(path, "sociopatterns", skip_bad=True)
    assert events(whole) == events(small) and whole_report == small_report
    assert small_report.examples[0].split(", ")[1] == "row 151"


# -- CLI -----------------------------------------------------------------------------------
from conftest import run_cli  # noqa: E402  (the CLI in-process)


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
    assert bad.returncode == 1 and "row 799" in bad.stderr and "'broken line'" in bad.stderr
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
    monkeypatch.setattr("swarmtopo.io.traces._BLOCK", 100)
    log, report = read_trace(path, "csv", skip_bad=True)
    assert report.skipped == 2 and log.n_events == 297 and report.lines == 299
    assert [e.split(", ")[1] for e in report.examples] == ["row 50", "row 200"]


def test_earliest_malformed_line_wins_over_a_later_non_utf8_line(tmp_path):
    path = write(tmp_path, "tij.dat", b"20 1 2\n40 1\n60 \xff 2\n", "wb")
    with pytest.raises(InputError, match="expected 3 or 5 fields") as caught:
        read_trace(path, "sociopatterns")
    assert caught.value.row == 2
    path = write(tmp_path, "tij2.dat", b"20 1 2\n40 \xff 2\n60 1\n", "wb")
    with pytest.raises(InputError, match="not UTF-8") as caught:
        read_trace(path, "sociopatterns")
    assert caught.value.row == 2


def test_trace_without_encounters_is_refused(tmp_path):
    path = write(tmp_path, "tij.dat", "\n4x 1 2\n")
    expected = r"no encounters in the trace \(2 lines read, 1 skipped as malformed, 1 blank\)"
    with pytest.raises(InputError, match=expected):
        read_trace(path, "sociopatterns", skip_bad=True)


def test_cli_ingest_help_shows_an_example():
    result = run_cli("ingest", "--help")
    assert result.returncode == 0 and "Example: swarmtopo ingest" in result.stdout


# -- traces as they come from the field ------------------------------------------------------
def test_ingest_refuses_to_overwrite_its_own_trace_and_says_what_it_removes(tmp_path):
    folder = tmp_path / "run"
    folder.mkdir()
    trace = folder / "events.parquet"
    pq.write_table(pa.table({"t": [1.0, 2.0], "a": [1, 2], "b": [2, 3]}), trace)
    for overwrite in ([], ["--overwrite"]):  # never the trace, and not first a hint to --overwrite
        refused = run_cli("ingest", trace, "--format", "parquet", "--out", folder, *overwrite)
        assert refused.returncode == 1 and "write the log to another folder" in refused.stderr
        assert "Traceback" not in refused.stderr and trace.is_file() and not (folder / "events.csv").exists()
    other = tmp_path / "log"
    assert run_cli("ingest", trace, "--format", "parquet", "--out", other, "--log-format", "parquet").returncode == 0
    kept = run_cli("ingest", trace, "--format", "parquet", "--out", other)  # a log is there: not without --overwrite
    assert kept.returncode == 1 and "already holds a log (events.parquet, meta.json); pass --overwrite" in kept.stderr
    again = run_cli("ingest", trace, "--format", "parquet", "--out", other, "--overwrite")  # CSV: the Parquet goes
    assert again.returncode == 0 and f"removed the outdated {other / 'events.parquet'}" in again.stdout
    assert sorted(p.name for p in other.iterdir()) == ["events.csv", "meta.json"]


@pytest.mark.parametrize("column, seconds", [
    (pa.array([10_000, 20_000], pa.duration("ms")), [10.0, 20.0]),
    (pa.array([1_400_000_000_000_000_000, 1_400_000_020_500_000_000], pa.timestamp("ns", tz="UTC")),
     [1_400_000_000.0, 1_400_000_020.5]),
    (pa.array([16_000, 16_001], pa.date32()), [16_000 * 86400.0, 16_001 * 86400.0]),
    (pa.array([1_500, 61_000], pa.time32("ms")), [1.5, 61.0]),
    (pa.array([1_500_000, 61_000_000], pa.time64("us")), [1.5, 61.0]),
])
def test_parquet_date_and_time_columns_become_seconds(tmp_path, column, seconds):
    path = tmp_path / "trace.parquet"
    pq.write_table(pa.table({"t": column, "a": [1, 2], "b": [2, 3]}), path)
    log, _ = read_trace(path, "parquet")
    assert log.t.tolist() == seconds and str(column.type) in log.meta["ingest"]["time_type"]


def test_times_of_2_to_the_53_seconds_or_more_are_refused_as_another_unit(tmp_path):
    ns = pa.array([1_400_000_000_000_000_000, 1_400_000_020_000_000_000], pa.int64())
    pq.write_table(pa.table({"t": ns, "a": [1, 2], "b": [2, 3]}), tmp_path / "ns.parquet")
    with pytest.raises(InputError, match="2\\^53 s or more") as caught:
        read_trace(tmp_path / "ns.parquet", "parquet")
    assert (caught.value.row, caught.value.column) == (1, "t")
    path = write(tmp_path, "ns.csv", "t,a,b\n1,1,2\n1400000000000000001,1,2\n")
    with pytest.raises(InputError, match="2\\^53 s or more") as caught:
        read_trace(path, "csv")
    assert caught.value.row == 2
    folder = tmp_path / "log"  # a log folder written by another tool: map refuses it in one line
    folder.mkdir()
    pq.write_table(pa.table({"t": ns, "a": [1, 2], "b": [2, 3]}), folder / "events.parquet")
    mapped = run_cli("map", folder)
    assert mapped.returncode == 1 and "2^53 s or more" in mapped.stderr and "Traceback" not in mapped.stderr


def test_a_column_named_twice_is_refused_in_csv_and_parquet(tmp_path):
    path = write(tmp_path, "trace.csv", "t,a,b,a\n1,x,y,z\n")
    with pytest.raises(InputError, match="column 'a': column appears twice"):
        read_trace(path, "csv")
    table = pa.table([pa.array([1.0]), pa.array([1]), pa.array([2]), pa.array([7])], names=["t", "a", "b", "a"])
    pq.write_table(table, tmp_path / "trace.parquet")
    with pytest.raises(InputError, match="column 'a': column appears twice"):
        read_trace(tmp_path / "trace.parquet", "parquet")


def test_parquet_nulls_and_nan_ids_are_missing_values_and_text_is_kept_exactly(tmp_path):
    path = tmp_path / "trace.parquet"
    pq.write_table(pa.table({"t": [1.0, None, 3.0], "a": [1, None, 3], "b": [2, None, 1]}), path)
    with pytest.raises(InputError, match="time is missing") as caught:  # not a blank line
        read_trace(path, "parquet")
    assert caught.value.row == 2
    pq.write_table(pa.table({"t": [1.0, 2.0], "a": [1.0, float("nan")], "b": [2.0, 3.0]}), path)
    with pytest.raises(InputError, match="agent ID is missing") as caught:
        read_trace(path, "parquet")
    assert (caught.value.row, caught.value.column) == (2, "a")
    pq.write_table(pa.table({" t": [1.0, 2.0], "a ": [" 1", "1 "], "b": ["2", "2"]}), path)
    log, _ = read_trace(path, "parquet")  # names found as in CSV headers; values not trimmed: two agents
    assert events(log) == [(1.0, " 1", "2"), (2.0, "1 ", "2")]


def test_parquet_float_ids_minus_zero_is_agent_zero_as_map_reads_it(tmp_path):
    path = tmp_path / "trace.parquet"
    half = pa.table({"t": [1.0, 2.0], "a": pa.array([0.0, -0.0], pa.float16()), "b": pa.array([1.0, 2.0], pa.float16())})
    pq.write_table(half, path)
    assert events(read_trace(path, "parquet")[0]) == [(1.0, "0", "1"), (2.0, "0", "2")]  # float16 IDs too
    pq.write_table(pa.table({"t": [1.0, 2.0, 3.0], "a": [0.0, 1.0, -0.0], "b": [1.0, 2.0, 2.0]}), path)
    log, _ = read_trace(path, "parquet")
    assert events(log) == [(1.0, "0", "1"), (2.0, "1", "2"), (3.0, "0", "2")] and log.agent_ids.dtype.kind == "i"
    pq.write_table(pa.table({"t": [1.0, 2.0, 3.0], "a": [0.0, 1.0, -0.0], "b": [1.0, 2.0, 2.0]}),
                   tmp_path / "events.parquet")
    assert read_log(tmp_path).agent_ids.tolist() == [0, 1, 2]


def test_ids_holding_a_nul_and_traces_that_are_not_regular_files_are_refused(tmp_path):
    path = tmp_path / "trace.parquet"
    pq.write_table(pa.table({"t": [1.0, 2.0, 3.0], "a": ["x", "y", "x\x00"], "b": ["y", "z", "z"]}), path)
    with pytest.raises(InputError, match="NUL") as caught:
        read_trace(path, "parquet")
    assert (caught.value.row, caught.value.column, caught.value.value) == (3, "a", "x\x00")
    log, report = read_trace(path, "parquet", skip_bad=True)  # a malformed line like any other
    assert events(log) == [(1.0, "x", "y"), (2.0, "y", "z")] and report.skipped == 1
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)  # as /dev/stdin is when a trace is piped in: never opened, so never blocks
    with pytest.raises(InputError, match="not a regular file.*save it to a file first"):
        read_trace(fifo, "csv")


@pytest.mark.parametrize("ids", [["B7", "B7 ", "B8"], ["B12  ", "B13  ", "B1   "]])
def test_padded_parquet_ids_survive_a_csv_log_folder(tmp_path, ids):
    path = tmp_path / "trace.parquet"
    pq.write_table(pa.table({"t": [0.0, 1.0, 2.0], "a": [ids[0], ids[1], ids[0]], "b": [ids[1], ids[2], ids[2]]}), path)
    log, _ = read_trace(path, "parquet")
    write_log(log, tmp_path / "log", fmt="csv")
    back = read_log(tmp_path / "log")
    assert events(back) == events(log) == [(0.0, *sorted(ids[:2])), (1.0, *sorted(ids[1:])),
                                           (2.0, *sorted((ids[0], ids[2])))]


def test_csv_ids_differing_only_in_blanks_are_refused_not_merged(tmp_path):
    path = write(tmp_path, "trace.csv", "t,a,b\n0,B7,B8\n\n1,B8,B9\n2,B9,B7 \n")
    with pytest.raises(InputError, match="only in the blanks around it") as caught:
        read_trace(path, "csv")
    assert (caught.value.row, caught.value.column, caught.value.value) == (4, "b", "B7 ")
    # blanks round integer IDs, or round every spelling of a text ID alike, are dropped
    log, _ = read_trace(write(tmp_path, "ints.csv", "t, a, b\n0, 5, 6\n1,6,7\n"), "csv")
    assert log.agent_ids.tolist() == [5, 6, 7]
    log, _ = read_trace(write(tmp_path, "text.csv", "t, a, b\n0, p1, p2\n1, p2, p3\n"), "csv")
    assert log.agent_ids.tolist() == ["p1", "p2", "p3"]


def test_duplicate_events_quote_both_file_rows_and_the_exact_time(tmp_path):
    path = write(tmp_path, "trace.csv", "t,a,b\n5,7,8\n\n6,x,x\n1400028780,1,2\n1400028780,2,1\n")
    with pytest.raises(InputError) as caught:
        read_trace(path, "csv", skip_bad=True)
    assert caught.value.row == 5 and "as row 4 (a pair is unordered: a -> b and b -> a at one time" in str(caught.value)
    assert caught.value.value == "1400028780, 1, 2"


def test_one_flapping_connection_at_one_time_is_one_encounter_and_a_bad_kind_is_malformed(tmp_path):
    path = write(tmp_path, "one.txt", "0 CONN 1 2 up\n9.5 CONN 1 2 down\n9.5 CONN 1 2 up\n9.5 CONN 1 2 down\n"
                                      "9.5 CONN 1 2 up\n")
    log, report = read_trace(path, "one")
    assert events(log) == [(0.0, "1", "2"), (9.5, "1", "2")] and report.counts["reopened_at_once"] == 1
    path = write(tmp_path, "typo.txt", "0 CONN 1 2 up\n3 CON 1 2 down\n4 M1 3 4 x\n")
    with pytest.raises(InputError, match="event kind must be CONN") as caught:
        read_trace(path, "one")
    assert (caught.value.row, caught.value.value) == (2, "CON")


@pytest.mark.parametrize("raw", [
    b"\xef\xbb\xbf20 1 2\n40 2 3\n",  # UTF-8 byte order mark
    b"20 1 2\r40 2 3\r",  # CR-only line ends
    b"20 1 2\r\n40 2 3",  # CRLF, no final line end
])
def test_sociopatterns_text_as_editors_save_it(tmp_path, raw):
    log, report = read_trace(write(tmp_path, "tij.dat", raw, "wb"), "sociopatterns")
    assert events(log) == [(0.0, "1", "2"), (20.0, "2", "3")] and report.lines == 2


def test_gzipped_text_traces_are_read_whatever_their_name(tmp_path):
    path = tmp_path / "tij.dat"
    path.write_bytes(gzip.compress(b"20 1 2\n40 2 3\n"))
    log, _ = read_trace(path, "sociopatterns")
    assert events(log) == [(0.0, "1", "2"), (20.0, "2", "3")]


def test_crlf_split_across_blocks_is_one_line_end(tmp_path, monkeypatch):
    raw = b"".join(f"{20 * k} {k % 7} {7 + k % 5}\r\n".encode() for k in range(1, 200))
    path = write(tmp_path, "tij.dat", raw, "wb")
    whole, whole_report = read_trace(path, "sociopatterns")
    for block in (5, 9, 10, 11):  # cuts before, at and after the \r\n of 8-11 byte lines
        monkeypatch.setattr("swarmtopo.io.traces._BLOCK", block)
        small, small_report = read_trace(path, "sociopatterns")
        assert events(small) == events(whole) and small_report == whole_report
    assert whole_report.lines == 199 and whole_report.counts["blank_lines"] == 0


@pytest.mark.parametrize("fmt, name, raw", [
    ("one", "t.gz", gzip.compress(b"1 CONN 1 2 up\n", mtime=0)[:20]),  # truncated
    ("sociopatterns", "g.dat", b"\x1f\x8b\x08\x00\x00\x00\x00\x00" + bytes(range(7, 107))),  # corrupt
    ("csv", "t.csv.gz", gzip.compress(b"t,a,b\n1,1,2\n2,2,3\n", mtime=0)[:25]),
])
def test_a_broken_gzip_trace_is_one_line_naming_the_file(tmp_path, fmt, name, raw):
    path = write(tmp_path, name, raw, "wb")
    with pytest.raises(InputError) as caught:
        read_trace(path, fmt)
    assert caught.value.file == str(path) and ("gzip" in str(caught.value) or "compressed" in str(caught.value))


def test_not_utf8_mask_agrees_with_decoding_each_value():
    from swarmtopo.io.tables import not_utf8
    values = [b"ok", b"Cr\xe8che", None, "é".encode(), b"\xff", b""] * 50
    expected = [v is not None and not _decodes_literally(v) for v in values]
    assert not_utf8(pa.array(values, pa.binary())).tolist() == expected


def _decodes_literally(value: bytes) -> bool:
    try:
        value.decode("utf-8")
    except UnicodeDecodeError:
        return False
    return True


def test_minus_zero_is_not_the_integer_zero_and_a_folder_is_not_a_trace(tmp_path):
    log, _ = read_trace(write(tmp_path, "trace.csv", "t,a,b\n1,0,1\n2,-0,1\n"), "csv")
    assert sorted(map(str, log.agent_ids)) == ["-0", "0", "1"]
    with pytest.raises(InputError, match="is a folder, not a file"):
        read_trace(tmp_path, "csv")


# -- input the review found mishandled ------------------------------------------------------
def test_csv_ids_written_with_a_zero_fraction_are_integers(tmp_path):
    log, _ = read_trace(write(tmp_path, "trace.csv", "t,a,b\n1,12.0,3\n2,12,3.00\n3,9007199254740993.0,3\n"), "csv")
    assert log.agent_ids.tolist() == [3, 12, 9007199254740993]  # exact beyond 2^53
    log, _ = read_trace(write(tmp_path, "text.csv", "t,a,b\n1,12.0,3\n2,12.5,3\n"), "csv")
    assert log.agent_ids.tolist() == ["12.0", "12.5", "3"]


@pytest.mark.parametrize("text, lines, blank", [
    ("1 C M1 1 2\n", 1, 0),  # a message, no connection
    ("", 0, 0),
    ("\n  \n", 2, 2),
    ("1 CONN 1 2 down\n2 CONN 1 2 down\n", 2, 0),
])
def test_a_one_trace_without_an_up_has_no_encounters(tmp_path, text, lines, blank):
    with pytest.raises(InputError) as caught:
        read_trace(write(tmp_path, "one.txt", text), "one")
    expected = f"no encounters in the trace ({lines} lines read, 0 skipped as malformed, {blank} blank)"
    assert caught.value.reason == expected


def test_a_gzipped_csv_is_read_by_content_and_binary_csv_is_refused(tmp_path, monkeypatch):
    path = write(tmp_path, "trace.csv", gzip.compress(b"t,a,b\n1,1,2\n2,2,3\n"), "wb")
    log, _ = read_trace(path, "csv")
    assert events(log) == [(1.0, "1", "2"), (2.0, "2", "3")]
    path = write(tmp_path, "sheet.csv", b"PK\x03\x04\x14\x00\x06\x00\x08\x00\x00\x00!\x00", "wb")
    with pytest.raises(InputError) as caught:
        read_trace(path, "csv", skip_bad=True)
    assert caught.value.reason.startswith("binary data, not text: line 1 holds a NUL byte")
    # a line that is not UTF-8 (here also ragged: pyarrow fails to hand it to Python) refuses the file
    unraisable = []
    monkeypatch.setattr("sys.unraisablehook", unraisable.append)
    path = write(tmp_path, "latin1.csv", b"t,a,b\n1,1,2\n2,Jos\xe9\n3,2,3\n", "wb")
    with pytest.raises(InputError) as caught:
        read_trace(path, "csv", skip_bad=True)
    assert caught.value.reason == "line 3: byte 0xe9 at column 6 is not UTF-8 text (save the file as UTF-8)"
    assert unraisable == []


def test_narrow_float_parquet_times_are_refused_when_they_were_rounded(tmp_path):
    path = tmp_path / "trace.parquet"
    times = np.array([1.4e9, 1.4e9 + 20.0, 1.4e9 + 40.0], np.float32)
    pq.write_table(pa.table({"t": times, "a": ["1", "2", "3"], "b": ["2", "3", "4"]}), path)
    with pytest.raises(InputError) as caught:
        read_trace(path, "parquet", skip_bad=True)
    assert (caught.value.row, caught.value.column) == (1, "t")
    assert caught.value.reason.startswith("a float time column tells times apart only to 128 s")
    pq.write_table(pa.table({"t": np.array([0.5, 1000.125], np.float32), "a": ["1", "2"], "b": ["2", "3"]}), path)
    log, _ = read_trace(path, "parquet")
    assert log.t.tolist() == [0.5, 1000.125]


def test_one_column_cannot_be_both_time_and_id(tmp_path):
    path = write(tmp_path, "trace.csv", "id1,id2\n1,2\n")
    with pytest.raises(SwarmtopoError, match="three different columns"):
        read_trace(path, "csv", time_column="id1", a_column="id1", b_column="id2")


# -- input the issue-39 review found mishandled ------------------------------------------------
def test_a_sociopatterns_class_conflict_names_its_first_line_and_both_classes(tmp_path):
    # agent 2 is B on line 1 and E on line 3; agent 1 is A on line 1 and D on line 2: line 2 is first
    path = write(tmp_path, "tij.dat", "20 1 2 A B\n40 3 1 C D\n60 2 3 E C\n")
    with pytest.raises(InputError) as caught:
        read_trace(path, "sociopatterns")
    exc = caught.value
    assert (exc.row, exc.column, exc.value) == (2, "Cj", "D")
    assert exc.reason == "agent '1' already has class 'A' (row 1); an agent has one class"


@pytest.mark.parametrize("raw, fmt, message", [
    (b"t,a,b\n1,x,y\n2,agent-Jos\xe9,z\n", "csv",
     "trace.csv: line 3: byte 0xe9 at column 12 is not UTF-8 text (save the file as UTF-8)"),
    # columns count characters, not bytes: "2,\xc3\xa9" is 3 characters
    (b"t,a,b\n1,\xc3\xa9t\xc3\xa9,y\n2,\xc3\xa9\xe9,z\n", "csv",
     "trace.csv: line 3: byte 0xe9 at column 4 is not UTF-8 text (save the file as UTF-8)"),
    (b"20 1 2\n40 Jos\xe9 2\n", "sociopatterns",
     "trace.csv, row 2: byte 0xe9 at column 7 is not UTF-8 text (save the file as UTF-8)"),
    (b"0 CONN 1 2 up\n1 CONN 2 \xff up\n", "one",
     "trace.csv, row 2: byte 0xff at column 10 is not UTF-8 text (save the file as UTF-8)"),
])
def test_a_trace_that_is_not_utf8_names_the_byte_without_escape_sequences(tmp_path, monkeypatch, raw, fmt, message):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "trace.csv").write_bytes(raw)
    with pytest.raises(InputError) as caught:
        read_trace("trace.csv", fmt)
    assert str(caught.value) == message
    if fmt != "csv":  # skipped with --skip-bad, the report says the same
        _, report = read_trace("trace.csv", fmt, skip_bad=True)
        assert report.examples == (message,)
