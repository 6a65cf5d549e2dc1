"""Log folders on disk: round trips, byte stability, located errors, ground-truth stripping."""

import gzip
import json
import time
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.csv as pcsv
import pyarrow.parquet as pq
import pytest

from swarmtopo.arena import default_arena
from swarmtopo.errors import InputError, SwarmtopoError
from swarmtopo._json import jsonable, read_json, write_json
from swarmtopo.io import read_arena, read_log, read_trajectories, read_truth, strip_ground_truth, write_arena, write_log
from swarmtopo.io.logs import GROUND_TRUTH_FILES
from swarmtopo.log import LOG_FORMAT, EncounterLog

FORMATS = ["csv", "parquet"]
AWKWARD_TIMES = [0.1, 1 / 3, 1e-300, 123456789.12345679, 5e-324, 2.0, 2.0 ** 53 - 1, 0.30000000000000004]


def make_log(ids="int", status=True, static=True, meta=None):
    rng = np.random.default_rng(1)
    n_agents = 6
    t = np.array(AWKWARD_TIMES + list(np.round(rng.uniform(0, 50, 30), 3)))
    a = rng.integers(0, n_agents, len(t))
    b = (a + rng.integers(1, n_agents, len(t))) % n_agents
    labels = {"int": np.array([0, 1, 2, 3, 4, 5]), "sparse": np.array([3, 17, 42, 99, 1000, 7]),
              "text": np.array(["007", "a,b", 'say "hi"', "x", "é", "10"], dtype=object),
              "digits": np.array(["1", "2", "3", "4", "5", "6"], dtype=object)}[ids]
    kwargs = {"meta": dict(meta or {"r_d": 30.0, "seed": 5, "units": {"t": "s", "x": "mm"}})}
    if status:
        kwargs["status"] = (np.array([0.0, 0.0, 1.5, 2.0, 1 / 3]), labels[[0, 1, 0, 2, 1]],
                            np.array(["RW", "WF", "S", "S", "RW"], dtype=object))
    if static:
        kwargs["static"] = (labels[[4, 2]], np.array([10.0, 12.25]))
    return EncounterLog.from_records(t, labels[a], labels[b], **kwargs)


def assert_same_log(x: EncounterLog, y: EncounterLog):
    for name in ("t", "a", "b", "agent_ids", "status_t", "status_agent", "status_state", "static_agent",
                 "static_time"):
        u, v = getattr(x, name), getattr(y, name)
        assert u.dtype.kind == v.dtype.kind, name
        assert np.array_equal(u, v), name
    assert [type(v) for v in x.agent_ids] == [type(v) for v in y.agent_ids]


# -- round trips -------------------------------------------------------------------------
@pytest.mark.parametrize("fmt", FORMATS)
@pytest.mark.parametrize("ids", ["int", "sparse", "text", "digits"])
@pytest.mark.parametrize("extras", [(True, True), (False, False), (True, False)])
def test_round_trip(tmp_path, fmt, ids, extras):
    log = make_log(ids, *extras)
    write_log(log, tmp_path, fmt=fmt)
    back = read_log(tmp_path)
    assert_same_log(log, back)
    expected_meta = dict(log.meta)
    if ids == "int":  # IDs 0..n-1 are declared by their count, others one by one
        expected_meta["agent_count"] = 6
    else:
        expected_meta["agent_ids"] = log.agent_ids.tolist()
    assert back.meta == expected_meta
    # a second trip changes nothing
    write_log(back, tmp_path / "again", fmt=fmt)
    assert read_log(tmp_path / "again").meta == back.meta


@pytest.mark.parametrize("fmt", FORMATS)
def test_times_round_trip_bit_exactly(tmp_path, fmt):
    log = make_log()
    write_log(log, tmp_path, fmt=fmt)
    back = read_log(tmp_path)
    assert back.t.view(np.int64).tolist() == log.t.view(np.int64).tolist()
    assert set(AWKWARD_TIMES) <= set(back.t.tolist())


def test_only_events_is_a_valid_log(tmp_path):
    (tmp_path / "events.csv").write_text("t,a,b\n0.5,1,2\n0.25,2,3\n")
    log = read_log(tmp_path)
    assert log.t.tolist() == [0.25, 0.5] and log.agent_ids.tolist() == [1, 2, 3]
    assert len(log.status_t) == 0 and len(log.static_agent) == 0
    assert log.meta == {} and log.n_agents == 3


@pytest.mark.parametrize("fmt", FORMATS)
def test_identical_logs_give_identical_bytes(tmp_path, fmt):
    arena = default_arena()
    for ids in ("int", "text"):
        log = make_log(ids)
        truth = {"xa": np.arange(log.n_events, dtype=float), "ya": np.zeros(log.n_events),
                 "xb": np.ones(log.n_events), "yb": np.full(log.n_events, 1 / 3)}
        first = write_log(log, tmp_path / f"{ids}1", fmt=fmt, truth=truth, arena=arena)
        second = write_log(make_log(ids), tmp_path / f"{ids}2", fmt=fmt, truth=truth, arena=arena)
        assert [p.name for p in first] == [p.name for p in second]
        for p, q in zip(first, second):
            assert p.read_bytes() == q.read_bytes(), p.name


def test_meta_json_layout(tmp_path):
    log = make_log("text")
    write_log(log, tmp_path)
    text = (tmp_path / "meta.json").read_text()
    meta = json.loads(text)
    assert text == json.dumps(meta, sort_keys=True, indent=2) + "\n"
    assert meta["static"] == [{"agent": 'say "hi"', "time": 12.25}, {"agent": "é", "time": 10.0}]
    assert meta["agent_ids"] == log.agent_ids.tolist() and "agent_count" not in meta
    write_log(make_log("int"), tmp_path / "ints")
    meta = read_json(tmp_path / "ints" / "meta.json")
    assert meta["agent_count"] == 6 and "agent_ids" not in meta


@pytest.mark.parametrize("ids", ["int", "sparse", "text"])
def test_the_declaration_written_is_the_logs_agents_whatever_meta_says(tmp_path, ids):
    log = make_log(ids)
    # a stale or wrong declaration in log.meta must not reach meta.json
    stale = replace(log, meta={**log.meta, "agent_count": 99, "agent_ids": ["ghost"]})
    write_log(stale, tmp_path)
    meta = read_json(tmp_path / "meta.json")
    if ids == "int":
        assert meta["agent_count"] == 6 and "agent_ids" not in meta
    else:
        assert meta["agent_ids"] == log.agent_ids.tolist() and "agent_count" not in meta
    assert_same_log(log, read_log(tmp_path))


def test_csv_layout_is_plain(tmp_path):
    log = EncounterLog.from_records([0.5, 0.25], [1, 2], [2, 3], status=([0.0], [2], ["WF"]))
    write_log(log, tmp_path)
    assert (tmp_path / "events.csv").read_text() == '"t","a","b"\n0.25,2,3\n0.5,1,2\n'
    assert (tmp_path / "status.csv").read_text() == '"t","agent","state"\n0,2,"WF"\n'


def test_writing_replaces_stale_contract_files_only(tmp_path):
    log = make_log()
    truth = {k: np.zeros(log.n_events) for k in ("xa", "ya", "xb", "yb")}
    write_log(log, tmp_path, fmt="parquet", truth=truth, arena=default_arena())
    (tmp_path / "notes.txt").write_text("mine")
    written = write_log(make_log(status=False), tmp_path, fmt="csv")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["events.csv", "meta.json", "notes.txt"]
    assert sorted(p.name for p in written) == ["events.csv", "meta.json"]


def test_unknown_format():
    with pytest.raises(SwarmtopoError, match="unknown log format 'xlsx'"):
        write_log(make_log(), "unused", fmt="xlsx")


# -- ID kinds in CSV ------------------------------------------------------------------------
@pytest.mark.parametrize("rows, expected", [
    ("0,1,2\n1,2,3\n", [1, 2, 3]),
    ("0,007,8\n1,8,9\n", ["007", "8", "9"]),
    ("0,1,x\n1,2,3\n", ["1", "2", "3", "x"]),
    ("0,1, 2\n1, 2 ,3\n", [1, 2, 3]),
    ("0,-1,99999999999999999999\n", ["-1", "99999999999999999999"]),
    # an integer with a zero fraction (a float column written out) is that integer, exactly
    ("0,12.0,3\n1,12,4\n", [3, 4, 12]),
    ("0,9007199254740993.000,-2.0\n", [-2, 9007199254740993]),  # 2^53 + 1: no float rounding
    ("0,1,2.5\n", ["1", "2.5"]),
    ("0,017.0,17\n", ["017.0", "17"]),  # 017 is text, so is 017.0
    ("0,-0.0,1\n", ["-0.0", "1"]),
])
def test_csv_id_kinds(tmp_path, rows, expected):
    (tmp_path / "events.csv").write_text("t,a,b\n" + rows)
    assert read_log(tmp_path).agent_ids.tolist() == expected


def test_text_ids_in_status_make_every_id_text(tmp_path):
    # "A" met nobody: it must be declared (an undeclared one is refused, see below)
    (tmp_path / "events.csv").write_text("t,a,b\n0,1,2\n")
    (tmp_path / "status.csv").write_text("t,agent,state\n0,A,RW\n0,1,WF\n")
    (tmp_path / "meta.json").write_text('{"agent_ids": [1, 2, "A"]}')
    assert read_log(tmp_path).agent_ids.tolist() == ["1", "2", "A"]


def test_declared_text_ids_keep_digit_strings(tmp_path):
    (tmp_path / "events.csv").write_text("t,a,b\n0,1,2\n")
    (tmp_path / "meta.json").write_text('{"agent_ids": ["1", "2", "3"]}')
    log = read_log(tmp_path)
    assert log.agent_ids.tolist() == ["1", "2", "3"] and log.n_agents == 3


def test_header_with_blanks_and_extra_columns(tmp_path):
    (tmp_path / "events.csv").write_text("\ufeff t , a,b ,note\n1.5, 3 ,4,hello\n")
    log = read_log(tmp_path)
    assert log.t.tolist() == [1.5] and log.agent_ids.tolist() == [3, 4]


def test_parquet_types(tmp_path):
    table = pa.table({"t": pa.array([2, 1], pa.int32()), "a": pa.array([1, 2], pa.uint8()),
                      "b": pa.array(["3", "4"]).dictionary_encode()})
    pq.write_table(table, tmp_path / "events.parquet")
    log = read_log(tmp_path)  # an integer column and a text column: all IDs become text
    assert log.t.tolist() == [1.0, 2.0] and log.agent_ids.tolist() == ["1", "2", "3", "4"]
    pq.write_table(pa.table({"t": [0.0], "a": pa.array(["007"]), "b": pa.array(["8"])}), tmp_path / "events.parquet")
    assert read_log(tmp_path).agent_ids.tolist() == ["007", "8"]


# -- located errors -------------------------------------------------------------------------
def folder(tmp_path, events, status=None, meta=None):
    (tmp_path / "events.csv").write_text(events)
    if status is not None:
        (tmp_path / "status.csv").write_text(status)
    if meta is not None:
        (tmp_path / "meta.json").write_text(meta)
    return tmp_path


def read_error(path) -> InputError:
    with pytest.raises(InputError) as info:
        read_log(path)
    return info.value


@pytest.mark.parametrize("events, row, column, value, reason", [
    ("t,a,b\n0,1,2\nabc,2,3\n", 2, "t", "abc", "time is not a number"),
    ("t,a,b\n0,1,2\n1,2,3\n2,3,4\n0x5,1,3\n", 4, "t", "0x5", "time is not a number"),
    ("t,a,b\n0,1,2\nNaN,2,3\n", 2, "t", "NaN", "finite"),
    ("t,a,b\n0,1,2\n1,2,3\n-2,3,4\n", 3, "t", "-2", "negative"),
    ("t,a,b\n0,1,2\n1e16,2,3\n", 2, "t", "1e16", "2^53"),
    ("t,a,b\n0,1,2\n,2,3\n", 2, "t", "", "time is missing"),
    ("t,a,b\n0,1,2\n1,2,2.0\n", 2, "b", "2.0", "itself"),
    ("t,a,b\n0,x,y\n1,,y\n", 2, "a", "", "agent ID is missing"),
    ("t,a,b\n0,x,y\n1,y,x\n0,y,x\n", 3, None, None, "duplicate event: same time and pair as row 1"),
    # blank lines are rows, numbered as ingest numbers them; values are quoted as written
    ("t,a,b\n0,1,2\n\n\n\n1,2,3\n-1,3,2\n", 6, "t", "-1", "negative"),
    ("t,a,b\n\n0,1,2\n\nabc,2,3\n", 4, "t", "abc", "time is not a number"),
    ("t,a,b\n\n0,x,y\n\n1,y,x\n0,y,x\n", 5, None, None, "duplicate event: same time and pair as row 2"),
])
def test_bad_events_are_located(tmp_path, events, row, column, value, reason):
    err = read_error(folder(tmp_path, events))
    assert err.file == str(tmp_path / "events.csv")
    assert err.row == row
    assert reason in str(err)
    if column is not None:
        assert err.column == column
    if value is not None:
        assert err.value == value


def test_missing_column_names_the_columns_found(tmp_path):
    err = read_error(folder(tmp_path, "time,a,b\n0,1,2\n"))
    assert err.file == str(tmp_path / "events.csv") and err.column == "t"
    assert "missing column 't'; found columns: 'time', 'a', 'b'" in str(err)
    (tmp_path / "status.csv").write_text("t,agent\n0,1\n")
    (tmp_path / "events.csv").write_text("t,a,b\n0,1,2\n")
    err = read_error(tmp_path)
    assert err.file == str(tmp_path / "status.csv") and err.column == "state"


def test_unknown_state_and_undeclared_id(tmp_path):
    err = read_error(folder(tmp_path, "t,a,b\n0,1,2\n", status="t,agent,state\n0,1,RW\n1,2,walk\n"))
    assert (err.file, err.row, err.column, err.value) == (str(tmp_path / "status.csv"), 2, "state", "walk")
    second = tmp_path / "second"
    second.mkdir()
    err = read_error(folder(second, "t,a,b\n0,0,1\n1,1,5\n", meta='{"agent_count": 3}'))
    assert (err.file, err.row, err.column, err.value) == (str(second / "events.csv"), 2, "b", "5")


def test_an_agent_that_met_nobody_is_fine(tmp_path):
    log = read_log(folder(tmp_path, "t,a,b\n0,0,1\n", status="t,agent,state\n0,2,S\n",
                          meta='{"agent_count": 4}'))
    assert log.n_agents == 4 and log.stop_intervals()[0].tolist() == [2]


def test_unsorted_input_is_sorted(tmp_path):
    log = read_log(folder(tmp_path, "t,a,b\n3,1,0\n1,2,1\n1,0,2\n"))
    assert log.t.tolist() == [1.0, 1.0, 3.0]
    assert log.a.tolist() == [0, 1, 0] and log.b.tolist() == [2, 2, 1]


def test_ragged_csv_row(tmp_path):
    err = read_error(folder(tmp_path, "t,a,b\n0,1,2\n\n1,2\n"))
    assert err.file == str(tmp_path / "events.csv")
    assert (err.row, err.value, err.reason) == (2, "1,2", "cannot parse CSV (expected 3 columns, found 2)")


@pytest.mark.parametrize("data, fragment", [
    ("t,a,b\n0,1,2\n".encode("utf-16"), "byte-order mark of UTF-16"),
    (b"\xff\xfet,a,b\n0,1,2\n", "byte-order mark of UTF-16"),
    ("t,a,b\n0,1,2\n".encode("utf-32"), "byte-order mark of UTF-32"),
    (b"t,a,b,not\xe9\n0,1,2,x\n", "line 1: byte 0xe9 at column 10 is not UTF-8 text (save the file as UTF-8)"),
])
def test_a_file_that_is_not_utf8_is_named(tmp_path, data, fragment):
    (tmp_path / "events.csv").write_bytes(data)
    err = read_error(tmp_path)
    assert err.file == str(tmp_path / "events.csv")
    assert "not UTF-8 text" in str(err) and fragment in str(err)


def test_a_value_that_is_not_utf8_is_located(tmp_path):
    # latin-1 "é" in an ID: row 3 of events; in status, a bad byte in a state label
    (tmp_path / "events.csv").write_bytes(b"t,a,b\n0,1,2\n1,2,3\n2,Jos\xe9,3\n")
    err = read_error(tmp_path)
    assert (err.file, err.row, err.column, err.value) == (str(tmp_path / "events.csv"), 3, "a", "Jos\ufffd")
    assert err.reason == "byte 0xe9 at character 4 of the value is not UTF-8 text (save the file as UTF-8)"
    assert "\\x" not in str(err)  # no Python escape sequence
    (tmp_path / "events.csv").write_text("t,a,b\n0,1,2\n")
    (tmp_path / "status.csv").write_bytes(b"t,agent,state\n0,1,RW\n1,1,\xa7\n")
    err = read_error(tmp_path)
    assert (err.file, err.row, err.column) == (str(tmp_path / "status.csv"), 2, "state")
    # a bad byte in a column read_log ignores is no error
    (tmp_path / "status.csv").unlink()
    (tmp_path / "events.csv").write_bytes(b"t,a,b,note\n0,1,2,caf\xe9\n")
    assert read_log(tmp_path).n_events == 1


def test_conflicting_or_repeated_status_rows_are_located(tmp_path):
    events = "t,a,b\n0,1,2\n"
    err = read_error(folder(tmp_path, events, status="t,agent,state\n0,1,RW\n2,1,S\n0,2,RW\n2,1,WF\n"))
    assert (err.file, err.row, err.column, err.value) == (str(tmp_path / "status.csv"), 4, "state", "WF")
    assert "conflicting status rows: row 2 says agent 1 is S at t=2.0, row 4 says WF" in str(err)
    err = read_error(folder(tmp_path, events, status="t,agent,state\n0,1,RW\n0.5,2,S\n0.50,2,s\n"))
    assert (err.file, err.row) == (str(tmp_path / "status.csv"), 3)
    assert "duplicate status row: row 3 repeats row 2 (t=0.5, agent 2, S)" in str(err)


def test_empty_and_missing_files(tmp_path):
    err = read_error(folder(tmp_path, ""))
    assert "cannot parse CSV" in str(err) and err.file == str(tmp_path / "events.csv")
    (tmp_path / "events.csv").unlink()
    assert "no events.csv or events.parquet" in str(read_error(tmp_path))
    assert "log folder not found" in str(read_error(tmp_path / "nope"))


def test_both_formats_present(tmp_path):
    write_log(make_log(), tmp_path, fmt="csv")
    pq.write_table(pa.table({"t": [0.0], "a": [0], "b": [1]}), tmp_path / "events.parquet")
    assert "both events.csv and events.parquet exist" in str(read_error(tmp_path))


def test_parquet_errors_are_located(tmp_path):
    pq.write_table(pa.table({"t": pa.array([0.0, None, 2.0]), "a": [0, 1, 2], "b": [1, 2, 3]}),
                   tmp_path / "events.parquet")
    err = read_error(tmp_path)
    assert (err.file, err.row, err.column) == (str(tmp_path / "events.parquet"), 2, "t")
    pq.write_table(pa.table({"t": ["0", "1", "2", "soon"], "a": [0, 1, 2, 3], "b": [1, 2, 3, 4]}),
                   tmp_path / "events.parquet")
    err = read_error(tmp_path)
    assert (err.row, err.column, err.value) == (4, "t", "soon")
    pq.write_table(pa.table({"t": [0.0, 1.0], "a": pa.array(["x", None]), "b": ["y", "z"]}),
                   tmp_path / "events.parquet")
    err = read_error(tmp_path)
    assert (err.row, err.column) == (2, "a") and "missing" in str(err)
    (tmp_path / "events.parquet").write_bytes(b"not parquet")
    assert "cannot read Parquet file" in str(read_error(tmp_path))


@pytest.mark.parametrize("meta, fragment", [
    ('{"agent_count": 3,\n  "seed": 1,,}', "invalid JSON: Expecting property name enclosed in double quotes "
                                           "(line 2, column 13)"),
    ("[1, 2]", "meta.json must hold a JSON object"),
    ('{"static": {"agent": 1}}', "key 'static' must be a list"),
    ('{"static": [{"agent": 1, "time": 2}, {"agent": 2}]}', "key 'static': entry 2 must be an object"),
    ('{"agent_count": -1}', "key 'agent_count' must be a non-negative integer"),
    ('{"agent_count": 2.5}', "key 'agent_count' must be a non-negative integer"),
    ('{"agent_ids": [1, null]}', "key 'agent_ids': entry 2"),
    ('{"agent_ids": [1, 2], "agent_count": 3}', "key 'agent_count' is 3 but 'agent_ids' lists 2 agents"),
])
def test_bad_meta_names_the_file_and_key(tmp_path, meta, fragment):
    err = read_error(folder(tmp_path, "t,a,b\n0,1,2\n", meta=meta))
    assert err.file == str(tmp_path / "meta.json")
    assert fragment in str(err)


def test_the_log_format_is_checked_when_declared(tmp_path):
    folder(tmp_path, "t,a,b\n0,1,2\n", meta=json.dumps({"format": LOG_FORMAT, "version": "9.9"}))
    assert read_log(tmp_path).meta == {"format": "swarmtopo-log/1", "version": "9.9"}
    (tmp_path / "meta.json").write_text('{"format": "swarmtopo-log/2"}')
    err = read_error(tmp_path)
    assert err.file == str(tmp_path / "meta.json") and err.value == "swarmtopo-log/2"
    assert "key 'format' is not 'swarmtopo-log/1'" in str(err)


def test_bad_static_entry_is_located(tmp_path):
    err = read_error(folder(tmp_path, "t,a,b\n0,1,2\n",
                            meta='{"static": [{"agent": 1, "time": 2}, {"agent": 2, "time": -1}]}'))
    assert err.file == f"{tmp_path / 'meta.json'} static"
    assert (err.row, err.column, err.value) == (2, "time", -1)


# -- ground truth ---------------------------------------------------------------------------------
def truth_and_trajectories(log):
    rng = np.random.default_rng(2)
    n = log.n_events
    truth = {"t": log.t, "a": log.a, "b": log.b, "xa": rng.uniform(0, 500, n), "ya": rng.uniform(0, 500, n),
             "xb": rng.uniform(0, 500, n), "yb": rng.uniform(0, 500, n), "region": rng.integers(0, 2, n)}
    ids = log.agent_ids
    trajectories = {"t": np.repeat([0.0, 0.1], len(ids)), "agent": np.tile(ids, 2),
                    "x": rng.uniform(0, 500, 2 * len(ids)), "y": rng.uniform(0, 500, 2 * len(ids)),
                    "state": rng.integers(0, 3, 2 * len(ids)).astype(np.int8)}
    return truth, trajectories


@pytest.mark.parametrize("fmt", FORMATS)
@pytest.mark.parametrize("ids", ["int", "text"])
def test_truth_and_trajectories_round_trip(tmp_path, fmt, ids):
    log = make_log(ids)
    truth, traj = truth_and_trajectories(log)
    write_log(log, tmp_path, fmt=fmt, truth=truth, trajectories=traj, arena=default_arena())
    back = read_truth(tmp_path)
    assert list(back) == ["t", "a", "b", "xa", "ya", "xb", "yb", "region"]
    assert np.array_equal(back["t"], log.t)
    assert back["a"].tolist() == log.ids_of(log.a).tolist() and back["b"].tolist() == log.ids_of(log.b).tolist()
    for key in ("xa", "ya", "xb", "yb", "region"):
        assert np.array_equal(back[key], truth[key]), key
    tr = read_trajectories(tmp_path)
    assert tr["agent"].tolist() == traj["agent"].tolist()
    assert tr["state"].dtype == np.int8 and np.array_equal(tr["state"], traj["state"])
    for key in ("t", "x", "y"):
        assert np.array_equal(tr[key], traj[key]), key
    assert read_arena(tmp_path / "arena.geojson") == default_arena()


def test_truth_ids_are_checked_as_the_logs_are(tmp_path):
    write_log(make_log(), tmp_path)
    columns = {"t": [0.0, 1.0], "xa": [0.0] * 2, "ya": [0.0] * 2, "xb": [0.0] * 2, "yb": [0.0] * 2}
    for a, reason in (([1.0, 3.5], "must be an integer"), ([1.0, 1e20], "int64 range")):
        pq.write_table(pa.table({**columns, "a": a, "b": [2.0, 4.0]}), tmp_path / "truth.parquet")
        err = read_error_of(read_truth, tmp_path)
        assert (err.file, err.row, err.column, err.value) == (str(tmp_path / "truth.parquet"), 2, "a", a[1])
        assert reason in str(err)
    pq.write_table(pa.table({**columns, "a": [1.0, -0.0], "b": [2.0, 4.0]}), tmp_path / "truth.parquet")
    assert read_truth(tmp_path)["a"].tolist() == [1, 0]
    pq.write_table(pa.table({**columns, "a": ["x1", "x2"], "b": ["x3", "x4\x00"]}), tmp_path / "truth.parquet")
    err = read_error_of(read_truth, tmp_path)  # a text ID holding a NUL, as in the log
    assert (err.row, err.column, err.value) == (2, "b", "x4\x00") and "NUL" in str(err)


def read_error_of(read, path) -> InputError:
    with pytest.raises(InputError) as info:
        read(path)
    return info.value


def test_absent_ground_truth_reads_as_none(tmp_path):
    write_log(make_log(), tmp_path)
    assert read_truth(tmp_path) is None and read_trajectories(tmp_path) is None


def test_misaligned_truth_is_refused(tmp_path):
    log = make_log()
    truth, _ = truth_and_trajectories(log)
    with pytest.raises(ValueError, match="truth\\['a'\\] is not aligned"):
        write_log(log, tmp_path, truth={**truth, "a": truth["b"]})
    with pytest.raises(ValueError, match="rows"):
        write_log(log, tmp_path, truth={**truth, "xa": truth["xa"][:-1]})
    with pytest.raises(ValueError, match="lacks column"):
        write_log(log, tmp_path, truth={"xa": truth["xa"]})


def test_strip_ground_truth(tmp_path):
    log = make_log("text", meta={"r_d": 30.0, "simulation": {"arena": "default", "holes": 1}})
    truth, traj = truth_and_trajectories(log)
    src, dst = tmp_path / "full", tmp_path / "stripped"
    write_log(log, src, truth=truth, trajectories=traj, arena=default_arena())
    assert {"arena.geojson", "truth.csv", "trajectories.csv"} <= {p.name for p in src.iterdir()}
    strip_ground_truth(src, dst)
    assert sorted(p.name for p in dst.iterdir()) == ["events.csv", "meta.json", "status.csv"]
    assert not set(GROUND_TRUTH_FILES) & {p.name for p in dst.iterdir()}
    for name in ("events.csv", "status.csv"):
        assert (dst / name).read_bytes() == (src / name).read_bytes()
    meta_src, meta_dst = read_json(src / "meta.json"), read_json(dst / "meta.json")
    assert "simulation" in meta_src and "simulation" not in meta_dst
    assert meta_dst == {k: v for k, v in meta_src.items() if k != "simulation"}
    stripped = read_log(dst)
    assert_same_log(log, stripped)
    with pytest.raises(InputError, match="new or empty folder"):
        strip_ground_truth(src, dst)


# -- JSON ----------------------------------------------------------------------------------------
def test_json_helpers(tmp_path):
    path = write_json({"b": np.int64(3), "a": [np.float64(0.5), np.arange(2)], "c": np.bool_(True)},
                      tmp_path / "x.json")
    expected = '{\n  "a": [\n    0.5,\n    [\n      0,\n      1\n    ]\n  ],\n  "b": 3,\n  "c": true\n}\n'
    assert path.read_text() == expected
    assert read_json(path) == {"a": [0.5, [0, 1]], "b": 3, "c": True}
    with pytest.raises(InputError, match="cannot write JSON") as info:
        write_json({"duration": float("nan")}, tmp_path / "nan.json")
    assert info.value.file == str(tmp_path / "nan.json") and not (tmp_path / "nan.json").exists()
    with pytest.raises(InputError, match="file not found"):
        read_json(tmp_path / "missing.json")
    (tmp_path / "bin.json").write_bytes(b'{"a": "\xff"}')
    with pytest.raises(InputError, match="not UTF-8"):
        read_json(tmp_path / "bin.json")


def test_jsonable():
    data = {1: (np.int64(3), np.float32(0.5), np.bool_(False)), "inf": [np.inf, -np.inf, np.nan, 2.5],
            "array": np.array([[1.0, np.inf], [np.nan, -0.0]]), "path": Path("a") / "b", "none": None}
    out = jsonable(data)
    assert out == {"1": [3, 0.5, False], "inf": ["inf", "-inf", None, 2.5],
                   "array": [[1.0, "inf"], [None, -0.0]], "path": str(Path("a") / "b"), "none": None}
    assert [type(v) for v in out["1"]] == [int, float, bool]
    assert json.loads(json.dumps(out, allow_nan=False)) == out  # plain, strict JSON
    with pytest.raises(TypeError, match="set"):
        jsonable({"x": {1, 2}})


def test_file_system_refusals_name_the_path(tmp_path):
    log = make_log()
    taken = tmp_path / "taken"
    taken.write_text("a file, not a folder")
    with pytest.raises(InputError) as info:
        write_log(log, taken)
    assert info.value.file == str(taken) and "cannot create the output folder (a file of that name exists)" \
        in str(info.value)
    with pytest.raises(InputError) as info:
        write_log(log, taken / "below")
    assert info.value.file == str(taken / "below") and "cannot create the output folder" in str(info.value)
    (tmp_path / "log" / "meta.json").mkdir(parents=True)  # a folder where a file goes
    with pytest.raises(InputError) as info:
        write_log(log, tmp_path / "log")
    assert info.value.file == str(tmp_path / "log" / "meta.json") and "cannot write file" in str(info.value)
    with pytest.raises(InputError) as info:
        write_json({"a": 1}, taken / "x.json")
    assert info.value.file == str(taken / "x.json") and "cannot write file" in str(info.value)
    with pytest.raises(InputError) as info:
        write_arena(default_arena(), tmp_path / "log" / "meta.json")
    assert info.value.file == str(tmp_path / "log" / "meta.json")
    with pytest.raises(InputError, match="cannot read file"):
        read_json(tmp_path / "log" / "meta.json")
    assert not list(tmp_path.rglob(".*.tmp"))  # no temporary file is left behind


# -- size ------------------------------------------------------------------------------------------
def big_events(path, n, text):
    rng = np.random.default_rng(0)
    n_agents = 400
    t = np.sort(rng.uniform(0, 600, n))
    a = rng.integers(0, n_agents, n)
    b = (a + rng.integers(1, n_agents, n)) % n_agents
    names = [f"rob{i:03d}" for i in range(n_agents)]
    cols = (pa.DictionaryArray.from_arrays(a, names), pa.DictionaryArray.from_arrays(b, names)) if text else (a, b)
    table = pa.table({"t": t, "a": cols[0], "b": cols[1]})
    if path.suffix == ".csv":
        pcsv.write_csv(table, path)
    else:
        pq.write_table(table, path)
    return t, np.minimum(a, b), np.maximum(a, b)


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_large_log_reads_correctly(tmp_path, suffix):
    t, lo, hi = big_events(tmp_path / f"events{suffix}", 10**5, text=True)
    log = read_log(tmp_path)
    assert np.array_equal(log.t, t) and np.array_equal(log.a, lo) and np.array_equal(log.b, hi)
    assert log.agent_ids[:2].tolist() == ["rob000", "rob001"]


@pytest.mark.slow
@pytest.mark.parametrize("text", [False, True])
def test_a_million_csv_rows_read_fast(tmp_path, text):
    t, lo, hi = big_events(tmp_path / "events.csv", 10**6, text=text)
    start = time.perf_counter()
    log = read_log(tmp_path)
    elapsed = time.perf_counter() - start
    assert log.n_events == 10**6 and np.array_equal(log.a, lo) and np.array_equal(log.b, hi)
    assert elapsed < 20.0  # about 1 s on an idle core; generous for a loaded 2-core machine


@pytest.mark.parametrize("key, value, message", [
    ("r_d", -1, "key 'r_d' must be a positive number"),
    ("v_c", 0, "key 'v_c' must be a positive number"),
    ("v_p", "fast", "key 'v_p' must be a positive number"),
    ("dt", True, "key 'dt' must be a positive number"),
    ("duration", -2.0, "key 'duration' must be a non-negative number"),
    ("duration", 1.5, "key 'duration' is 1.5 s but the log runs to t = 3 s"),
])
def test_meta_numbers_that_cannot_be_are_refused(tmp_path, key, value, message):
    log = EncounterLog.from_records([0.0, 1.0, 3.0], [1, 2, 1], [2, 3, 3], meta={"r_d": 30.0, "v_c": 15.0})
    write_log(log, tmp_path)
    meta = json.loads((tmp_path / "meta.json").read_text())
    meta[key] = value
    (tmp_path / "meta.json").write_text(json.dumps(meta))
    with pytest.raises(InputError, match=message) as caught:
        read_log(tmp_path)
    assert caught.value.file == str(tmp_path / "meta.json")
    meta[key] = 3.0  # a valid value of each key reads
    (tmp_path / "meta.json").write_text(json.dumps(meta))
    assert read_log(tmp_path).meta[key] == 3.0


def test_log_files_that_are_folders_and_odd_meta_keys_are_refused(tmp_path):
    log = EncounterLog.from_records([0.0, 1.0, 3.0], [1, 2, 1], [2, 3, 3])
    write_log(log, tmp_path / "log")
    with pytest.raises(InputError, match="is a file, not a log folder"):
        read_log(tmp_path / "log" / "events.csv")
    (tmp_path / "log" / "status.csv").mkdir()
    with pytest.raises(InputError, match="is a folder, not a file") as caught:
        read_log(tmp_path / "log")
    assert caught.value.file == str(tmp_path / "log" / "status.csv")
    (tmp_path / "log" / "status.csv").rmdir()
    meta_path = tmp_path / "log" / "meta.json"
    for meta, message, value in [({"units": {"time": "ms"}}, "key 'units.time' must be \"s\"", "ms"),
                                 ({"agent_ids": [1, 2, 3, 2]}, "lists an agent twice", 2),
                                 ({"format": None}, "key 'format' is not", "null"),
                                 ({"units": "ms"}, "key 'units' must be an object", "ms")]:
        meta_path.write_text(json.dumps(meta))
        with pytest.raises(InputError, match=message) as caught:
            read_log(tmp_path / "log")
        assert caught.value.value == value


# -- input the review found mishandled ------------------------------------------------------
def test_ids_written_with_a_zero_fraction_are_the_same_agents_in_every_file(tmp_path):
    # a float column written out ("12.0") and an integer one ("12") name the same agents
    log = read_log(folder(tmp_path, "t,a,b\n0,12.0,3.0\n1,3.0,4.0\n", status="t,agent,state\n0,12,WF\n"))
    assert log.agent_ids.tolist() == [3, 4, 12] and log.n_agents == 3
    assert log.ids_of(log.status_agent).tolist() == [12]


def test_a_status_file_none_of_whose_agents_met_anyone_is_refused(tmp_path):
    # "a1" in events, "A1" in status: without a declared agent set, nothing ties them together
    err = read_error(folder(tmp_path, "t,a,b\n0,a1,a2\n1,a2,a3\n", status="t,agent,state\n0,A1,WF\n0,A2,RW\n"))
    assert (err.file, err.column, err.value) == (str(tmp_path / "status.csv"), "agent", "A1")
    assert "agent never appears in events.csv (none of this file's agents does" in err.reason
    # a declared agent set that holds them all makes them agents that met nobody
    (tmp_path / "status.csv").write_text("t,agent,state\n0,A1,WF\n")
    (tmp_path / "meta.json").write_text('{"agent_ids": ["a1", "a2", "a3", "A1"]}')
    assert read_log(tmp_path).n_agents == 4


@pytest.mark.parametrize("data, fragment", [
    (gzip.compress(b"t,a,b\n0,1,2\n"), "gzip-compressed: gunzip it first"),
    (b"PAR1\x15\x04\x15\x00\x00t,a,b\n", "binary data, not text: line 1 holds a NUL byte"),
    (b"t,a,b\n0,1,2\n1,2\x00,3\n", "binary data, not text: line 3 holds a NUL byte"),
], ids=["gzip", "parquet", "nul"])
def test_a_binary_or_compressed_events_csv_is_one_line(tmp_path, data, fragment):
    (tmp_path / "events.csv").write_bytes(data)
    err = read_error(tmp_path)
    assert err.file == str(tmp_path / "events.csv") and err.reason.startswith(fragment)


def test_a_ragged_row_that_is_not_utf8_is_named_without_a_traceback(tmp_path, monkeypatch):
    # pyarrow fails to decode such a row for its invalid-row handler (printed as an
    # "Exception ignored" traceback); the byte is named instead
    unraisable = []
    monkeypatch.setattr("sys.unraisablehook", unraisable.append)
    (tmp_path / "events.csv").write_bytes(b"t,a,b\n0,1,2\n1,Jos\xe9\n")
    err = read_error(tmp_path)
    assert err.reason == "line 3: byte 0xe9 at column 6 is not UTF-8 text (save the file as UTF-8)"
    assert unraisable == []


def test_a_ragged_row_is_quoted_as_a_value(tmp_path):
    err = read_error(folder(tmp_path, "t,a,b\n0,1,2\n1,2,3,\x1b[31mred\n"))
    assert (err.row, err.value) == (2, "1,2,3,\x1b[31mred") and "'1,2,3,\\x1b[31mred'" in str(err)


def test_repeated_names_among_ignored_columns_are_fine(tmp_path):
    # Excel's trailing empty columns: header "t,a,b,,", rows ending ",,"
    log = read_log(folder(tmp_path, "t,a,b,,\n0,1,2,,\n1,2,3,,\n", status="t,agent,state,x,x\n0,1,RW,,\n"))
    assert log.n_events == 2 and log.agent_ids.tolist() == [1, 2, 3]
    for events in ("t,a,b, a\n0,1,2,3\n", "t,a,b,t\n0,1,2,3\n"):
        err = read_error(folder(tmp_path, events, status="t,agent,state\n0,1,RW\n"))
        assert err.reason == "column appears twice" and err.column in ("a", "t")


def test_narrow_float_times_are_refused_when_they_were_rounded(tmp_path):
    times = np.array([1.4e9, 1.4e9 + 30.0, 1.4e9 + 60.0])
    pq.write_table(pa.table({"t": pa.array(times.astype(np.float32)), "a": [1, 2, 3], "b": [2, 3, 4]}),
                   tmp_path / "events.parquet")
    err = read_error(tmp_path)
    assert (err.file, err.column) == (str(tmp_path / "events.parquet"), "t")
    assert err.reason.startswith("a float time column tells times apart only to 128 s at its largest value")
    # small float32 / float16 times are exact in float64: read as they are
    for kind, values in ((np.float32, [0.5, 1.25, 1000.125]), (np.float16, [0.5, 1.25, 1.5])):
        pq.write_table(pa.table({"t": pa.array(np.array(values, kind)), "a": [1, 2, 3], "b": [2, 3, 4]}),
                       tmp_path / "events.parquet")
        assert read_log(tmp_path).t.tolist() == values
    pq.write_table(pa.table({"t": pa.array(np.array([0.5, 2048.0], np.float16)), "a": [1, 2], "b": [2, 3]}),
                   tmp_path / "events.parquet")
    assert read_error(tmp_path).reason.startswith("a halffloat time column tells times apart only to 2 s")


def test_an_id_column_of_lists_is_refused_naming_its_type(tmp_path):
    pq.write_table(pa.table({"t": [0.0, 1.0], "a": pa.array([[1], [2]]), "b": [2, 3]}), tmp_path / "events.parquet")
    err = read_error(tmp_path)
    assert (err.file, err.column) == (str(tmp_path / "events.parquet"), "a")
    assert err.reason.startswith("agent IDs must be integers or text, not list<")


# -- padded text IDs, float IDs beyond int64, blank lines ------------------------------------
@pytest.mark.parametrize("ids", [["B7", "B7 ", "B8"], ["B12  ", " B13", "B1   "]])
def test_padded_text_ids_read_back_exactly_from_a_csv_log(tmp_path, ids):
    # write_log declares text IDs in meta.json; the CSV reader keeps a declared ID as written
    log = EncounterLog.from_records([0.0, 1.0, 2.0], [ids[0], ids[1], ids[0]], [ids[1], ids[2], ids[2]],
                                    status=([0.0], [ids[1]], ["S"]))
    write_log(log, tmp_path, fmt="csv")
    back = read_log(tmp_path)
    assert back.agent_ids.tolist() == sorted(ids)
    assert back.ids_of(back.a).tolist() == log.ids_of(log.a).tolist()
    assert back.ids_of(back.b).tolist() == log.ids_of(log.b).tolist()
    assert back.ids_of(back.status_agent).tolist() == [ids[1]]


def test_csv_ids_that_trimming_would_merge_are_refused(tmp_path):
    err = read_error(folder(tmp_path, "t,a,b\n0,B7,B8\n1,B8,B9\n2,B7 ,B9\n"))
    assert (err.file, err.row, err.column, err.value) == (str(tmp_path / "events.csv"), 3, "a", "B7 ")
    assert "only in the blanks around it" in str(err) and "\n" not in str(err)
    # blanks round undeclared CSV IDs are still dropped when nothing collides
    log = read_log(folder(tmp_path, "t, a, b\n0, B7, B8\n1, B8, B9 \n"))
    assert log.agent_ids.tolist() == ["B7", "B8", "B9"]
    # an undeclared padded spelling of a declared ID beside the declared one is refused too
    err = read_error(folder(tmp_path, "t,a,b\n0,B7,B8\n1,B7 ,B9\n", meta='{"agent_ids": ["B7", "B8", "B9"]}'))
    assert (err.row, err.column, err.value) == (2, "a", "B7 ")


@pytest.mark.parametrize("value", [1e20, -2e19, 2.0 ** 63])
def test_float_ids_beyond_int64_are_refused_without_a_warning(tmp_path, value):
    pq.write_table(pa.table({"t": [0.0, 1.0], "a": [1.0, value], "b": [2.0, 2 * value]}), tmp_path / "events.parquet")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        err = read_error(tmp_path)
    assert (err.file, err.row, err.column, err.value) == (str(tmp_path / "events.parquet"), 2, "a", value)
    assert "int64 range" in str(err)


def test_largest_float_id_within_int64_is_read_exactly(tmp_path):
    big = 2.0 ** 63 - 1024  # the largest float64 below 2^63
    pq.write_table(pa.table({"t": [0.0], "a": [-(2.0 ** 63)], "b": [big]}), tmp_path / "events.parquet")
    assert read_log(tmp_path).agent_ids.tolist() == [-(2 ** 63), int(big)]


def test_status_rows_count_blank_lines(tmp_path):
    err = read_error(folder(tmp_path, "t,a,b\n0,1,2\n", status="t,agent,state\n\n0,1,RW\n\n0,1,S\n"))
    assert (err.file, err.row) == (str(tmp_path / "status.csv"), 4)
    assert "row 2 says agent 1 is RW" in str(err) and "row 4 says S" in str(err)
    err = read_error(folder(tmp_path, "t,a,b\n0,1,2\n", status="t,agent,state\n\n0,1,RW\n\n1,2,walk\n"))
    assert (err.row, err.column, err.value) == (4, "state", "walk")


# -- input the issue-39 review found mishandled ------------------------------------------------
def test_a_status_agent_that_is_in_no_event_is_refused_unless_declared(tmp_path):
    events = "t,a,b\n0,1,2\n1,2,3\n"
    err = read_error(folder(tmp_path, events, status="t,agent,state\n0,1,RW\n\n2,9,S\n"))
    assert (err.file, err.row, err.column, err.value) == (str(tmp_path / "status.csv"), 3, "agent", "9")
    assert err.reason.startswith("agent never appears in events.csv (an agent that met nobody is declared")
    # declared, it is an agent that met nobody: by its ID or by the count of IDs 0 .. n-1
    (tmp_path / "meta.json").write_text('{"agent_ids": [1, 2, 3, 9]}')
    log = read_log(tmp_path)
    assert log.agent_ids.tolist() == [1, 2, 3, 9] and log.ids_of(log.status_agent).tolist() == [1, 9]
    (tmp_path / "meta.json").write_text('{"agent_count": 10}')
    assert read_log(tmp_path).n_agents == 10


@pytest.mark.parametrize("fmt", FORMATS)
def test_gzipped_csv_tables_are_read_and_two_versions_of_a_table_refused(tmp_path, fmt):
    log = make_log("text")
    truth, traj = truth_and_trajectories(log)
    write_log(log, tmp_path / "plain", truth=truth, trajectories=traj)
    gz = tmp_path / "gz"
    gz.mkdir()
    for path in (tmp_path / "plain").iterdir():
        target = gz / (path.name + ".gz" if path.suffix == ".csv" else path.name)
        target.write_bytes(gzip.compress(path.read_bytes()) if path.suffix == ".csv" else path.read_bytes())
    assert sorted(p.name for p in gz.iterdir()) == ["events.csv.gz", "meta.json", "status.csv.gz",
                                                    "trajectories.csv.gz", "truth.csv.gz"]
    assert_same_log(read_log(gz), log)
    assert np.array_equal(read_truth(gz)["xa"], truth["xa"])
    assert read_trajectories(gz)["agent"].tolist() == traj["agent"].tolist()
    strip_ground_truth(gz, tmp_path / "stripped")
    assert sorted(p.name for p in (tmp_path / "stripped").iterdir()) == ["events.csv.gz", "meta.json", "status.csv.gz"]
    (gz / "events.csv").write_bytes((tmp_path / "plain" / "events.csv").read_bytes())
    err = read_error(gz)
    assert (err.file, err.reason) == (str(gz), "both events.csv and events.csv.gz exist; keep one")
    # a log written over the folder replaces every version of its tables
    write_log(log, gz, fmt=fmt)
    assert sorted(p.name for p in gz.iterdir()) == sorted([f"events.{fmt}", "meta.json", f"status.{fmt}"])


@pytest.mark.parametrize("name", ["events.csv", "events.csv.gz", "status.csv", "meta.json"])
def test_a_log_file_that_is_a_folder_is_named_as_one(tmp_path, name):
    (tmp_path / name).mkdir()
    if name.startswith("status") or name == "meta.json":
        (tmp_path / "events.csv").write_text("t,a,b\n0,1,2\n")
    assert str(read_error(tmp_path)) == f"{tmp_path / name}: is a folder, not a file"
