"""EncounterLog.from_records: canonical form, validation with located errors, fast paths."""

import numpy as np
import pyarrow as pa
import pytest

from swarmtopo.errors import InputError
from swarmtopo.log import RW, S, WF, EncounterLog, parse_states, state_labels


def literal_canonical(t, a, b, declared=None):
    """Slow reference: IDs sorted, codes = rank, events (t, min, max) sorted."""
    ids = sorted(set(declared) if declared is not None else set(a) | set(b))
    code = {v: i for i, v in enumerate(ids)}
    rows = sorted((float(ti), min(code[x], code[y]), max(code[x], code[y])) for ti, x, y in zip(t, a, b))
    return ids, rows


def random_records(seed, n=300, n_agents=12, text=False):
    rng = np.random.default_rng(seed)
    t = rng.integers(0, 40, n) / 4.0  # coarse times: many ties, so the (a, b) order matters
    a = rng.integers(0, n_agents, n)
    b = (a + rng.integers(1, n_agents, n)) % n_agents
    keep = np.unique(np.column_stack([t, np.minimum(a, b), np.maximum(a, b)]), axis=0, return_index=True)[1]
    t, a, b = t[np.sort(keep)], a[np.sort(keep)], b[np.sort(keep)]
    if text:
        names = np.array([f"{'bot' if i % 2 else 'r'}{i:02d}" for i in range(n_agents)], dtype=object)
        a, b = names[a], names[b]
    return t, a, b


@pytest.mark.parametrize("text", [False, True])
def test_canonical_form_matches_the_literal_definition(text):
    for seed in range(10):
        t, a, b = random_records(seed, text=text)
        log = EncounterLog.from_records(t, a, b)
        ids, rows = literal_canonical(t, a, b)
        assert log.agent_ids.tolist() == ids
        assert list(zip(log.t.tolist(), log.a.tolist(), log.b.tolist())) == rows
        assert log.t.dtype == np.float64 and log.a.dtype == np.int64 and log.b.dtype == np.int64
        assert np.all(log.a < log.b)
        # any permutation of the input gives the same log
        p = np.random.default_rng(seed).permutation(len(t))
        again = EncounterLog.from_records(t[p], a[p], b[p])
        assert np.array_equal(again.t, log.t) and np.array_equal(again.a, log.a) and np.array_equal(again.b, log.b)


def test_text_ids_are_python_strings_in_sorted_order():
    log = EncounterLog.from_records([0.0, 1.0], ["b", "007"], ["a", "b"])
    assert log.agent_ids.dtype == object
    assert log.agent_ids.tolist() == ["007", "a", "b"]
    assert all(type(v) is str for v in log.agent_ids)
    assert log.ids_of(log.a).tolist() == ["a", "007"] and log.ids_of(log.b).tolist() == ["b", "b"]


def test_mixed_id_kinds_become_text():
    log = EncounterLog.from_records([0.0, 1.0], [1, 2], [10, "x"])
    assert log.agent_ids.tolist() == ["1", "10", "2", "x"]


def test_integer_valued_float_ids_are_integers():
    log = EncounterLog.from_records([0.0], [3.0], [1.0])
    assert log.agent_ids.dtype == np.int64 and log.agent_ids.tolist() == [1, 3]


def test_pyarrow_columns_give_the_same_log_as_numpy():
    t, a, b = random_records(3, n=500, text=True)
    rng = np.random.default_rng(0)
    st_t = np.sort(rng.uniform(0, 10, 50))
    st_agent = a[:50]
    st_state = state_labels(rng.integers(0, 3, 50))
    ref = EncounterLog.from_records(t, a, b, status=(st_t, st_agent, st_state))
    chunked_b = pa.chunked_array([pa.array(b[:7].tolist()), pa.array(b[7:].tolist())])
    arrow = EncounterLog.from_records(
        t, pa.array(a.tolist()).dictionary_encode(), chunked_b,
        status=(st_t, pa.array(st_agent.tolist()), pa.array(st_state.tolist())))
    for name in ("t", "a", "b", "agent_ids", "status_t", "status_agent", "status_state"):
        assert np.array_equal(getattr(arrow, name), getattr(ref, name)), name
    ints = EncounterLog.from_records(pa.array([0.5, 1.0]), pa.array([1, 2], pa.int32()), pa.array([2, 3], pa.int16()))
    assert ints.agent_ids.tolist() == [1, 2, 3] and ints.agent_ids.dtype == np.int64


# -- declared agents ----------------------------------------------------------------------
def test_declared_agents_include_those_that_met_nobody():
    log = EncounterLog.from_records([0.0, 1.0], [0, 1], [1, 2], meta={"agent_count": 5})
    assert log.n_agents == 5 and log.agent_ids.tolist() == [0, 1, 2, 3, 4]
    log = EncounterLog.from_records([0.0], ["x"], ["y"], meta={"agent_ids": ["z", "y", "x"]})
    assert log.agent_ids.tolist() == ["x", "y", "z"]
    assert log.meta["agent_ids"] == ["z", "y", "x"]


def test_meta_is_kept_as_given_and_a_log_rebuilds_from_it():
    log = EncounterLog.from_records([0.0], [4], [9])
    assert log.meta == {} and log.n_agents == 2
    # rebuilding from the log's own IDs and meta gives the same log (IDs are not 0..n-1)
    again = EncounterLog.from_records(log.t, log.ids_of(log.a), log.ids_of(log.b), meta=log.meta)
    assert again.agent_ids.tolist() == [4, 9] and again.a.tolist() == [0] and again.b.tolist() == [1]
    declared = EncounterLog.from_records([0.0], [0], [1], meta={"agent_count": 3, "r_d": 30.0})
    assert declared.meta == {"agent_count": 3, "r_d": 30.0} and declared.n_agents == 3


# -- located errors ---------------------------------------------------------------------------
def error_of(*args, **kwargs) -> InputError:
    with pytest.raises(InputError) as info:
        EncounterLog.from_records(*args, source={"events": "ev.csv", "status": "st.csv"}, **kwargs)
    return info.value


@pytest.mark.parametrize("t, row, value, reason", [
    ([0.0, np.nan, 1.0], 2, np.nan, "finite"),
    ([0.0, 1.0, np.inf], 3, np.inf, "finite"),
    ([0.0, -0.5, 1.0], 2, -0.5, "negative"),
    (np.array([0.0, "abc", 1.0], dtype=object), 2, "abc", "not a number"),
    (np.array([0.0, 1.0, None], dtype=object), 3, None, "missing"),
    (np.array(["0.5", "1e3", "x1"]), 3, "x1", "not a number"),
])
def test_bad_times(t, row, value, reason):
    err = error_of(t, [0, 1, 2], [1, 2, 3])
    assert (err.file, err.row, err.column) == ("ev.csv", row, "t")
    assert reason in err.reason
    if isinstance(value, float) and np.isnan(value):
        assert np.isnan(err.value)
    else:
        assert err.value == value


def test_self_encounter():
    err = error_of([0.0, 1.0], [0, 4], [1, 4])
    assert (err.file, err.row, err.column, err.value) == ("ev.csv", 2, "b", 4)
    assert "itself" in err.reason
    assert str(err).startswith("ev.csv, row 2, column 'b', value '4': ")


@pytest.mark.parametrize("a, row, value", [
    (np.array(["x", "", "y"], dtype=object), 2, ""),
    (np.array(["x", "y", "  "], dtype=object), 3, "  "),
    (np.array(["x", None, "y"], dtype=object), 2, None),
    (np.array(["x", "y", np.nan], dtype=object), 3, None),
    (pa.array(["x", None, "y"]), 2, None),
])
def test_missing_ids(a, row, value):
    err = error_of([0.0, 1.0, 2.0], a, ["q", "r", "s"])
    assert (err.file, err.row, err.column) == ("ev.csv", row, "a")
    assert "missing" in err.reason
    if value is not None:
        assert err.value == value


def test_non_integer_float_id():
    err = error_of([0.0, 1.0], [1.0, 2.5], [3, 4])
    assert (err.row, err.column, err.value) == (2, "a", 2.5)


def test_text_ids_holding_a_nul_are_refused_not_merged():
    # numpy strings drop trailing NULs: 'a7\x00' would be agent 'a7'
    for ids in (np.array(["a7", "a8", "a7\x00"], dtype=object), pa.array(["a7", "a8", "a7\x00"])):
        err = error_of([0.0, 1.0, 2.0], ids, ["b1", "b2", "b3"])
        assert (err.file, err.row, err.column, err.value) == ("ev.csv", 3, "a", "a7\x00")
        assert "NUL" in err.reason
    err = error_of([0.0], ["a"], pa.array(["b\x00c"]))  # inside an ID too
    assert (err.row, err.column) == (1, "b")
    err = error_of([0.0, 1.0, 2.0], ["a", "b", "a\x00"], ["b", "c", "c"])  # a Python list, not numpy strings first
    assert (err.row, err.column, err.value) == (3, "a", "a\x00")
    err = error_of([0.0], np.array(["a\x00b"]), ["c"])  # numpy strings keep a NUL inside an ID
    assert (err.row, err.column) == (1, "a")


def test_float_ids_beyond_int64_are_refused_not_wrapped():
    # 1e20 and 2e20 would both cast to -2^63: one agent
    for ids in (np.array([1.0, 1e20]), pa.array([1.0, 1e20])):
        err = error_of([0.0, 1.0], ids, np.array([2.0, 2e20]))
        assert (err.row, err.column, err.value) == (2, "a", 1e20) and "int64 range" in err.reason
    log = EncounterLog.from_records([0.0], np.array([-(2.0 ** 63)]), np.array([2.0 ** 62]))
    assert log.agent_ids.tolist() == [-(2 ** 63), 2 ** 62]


def test_status_errors_name_the_source_rows():
    err = error_of([0.0], [1], [2], status=([0.0, 0.0], [1, 1], ["RW", "S"]), status_rows=[3, 7])
    assert err.row == 7 and "row 3 says agent 1 is RW" in err.reason and "row 7 says S" in err.reason
    err = error_of([0.0], [1], [2], status=([0.0, -1.0], [1, 1], ["RW", "S"]), status_rows=[3, 7])
    assert (err.row, err.column) == (7, "t")


def test_undeclared_ids():
    err = error_of([0.0, 1.0, 2.0], [0, 1, 2], [1, 7, 1], meta={"agent_count": 3})
    assert (err.file, err.row, err.column, err.value) == ("ev.csv", 2, "b", 7)
    assert "declares" in err.reason
    err = error_of([0.0], ["x"], ["y"], meta={"agent_ids": ["x", "z"]})
    assert (err.row, err.column, err.value) == (1, "b", "y")
    err = error_of([0.0], [0], [1], status=([0.0], [9], ["RW"]), meta={"agent_count": 2})
    assert (err.file, err.row, err.column, err.value) == ("st.csv", 1, "agent", 9)


@pytest.mark.parametrize("t, a, b, row, first", [
    ([0.0, 1.0, 0.0], [0, 1, 0], [1, 2, 1], 3, 1),   # (t, a, b) twice
    ([0.0, 1.0, 1.0], [0, 1, 2], [1, 2, 1], 3, 2),   # (t, a, b) then (t, b, a)
    ([5.0, 1.0, 5.0, 2.0], ["x", "y", "z", "z"], ["z", "x", "x", "x"], 3, 1),
])
def test_duplicate_events(t, a, b, row, first):
    err = error_of(t, a, b)
    assert (err.file, err.row) == ("ev.csv", row)
    assert f"duplicate event: same time and pair as row {first}" in err.reason


def test_states_are_parsed_leniently_and_unknown_states_located():
    log = EncounterLog.from_records([0.0], [0], [1], status=([0.0, 1.0, 2.0], [0, 0, 1], [" rw", "Wf", "S "]))
    assert log.status_state.tolist() == [RW, WF, S]
    err = error_of([0.0], [0], [1], status=([0.0, 1.0], [0, 1], ["RW", "run"]))
    assert (err.file, err.row, err.column, err.value) == ("st.csv", 2, "state", "run")
    err = error_of([0.0], [0], [1], status=([0.0, 1.0], [0, 1], pa.array(["RW", None])))
    assert (err.row, err.column) == (2, "state")


@pytest.mark.parametrize("rows, row, message", [
    # same agent, same time, two states: the log would depend on the row order
    (([0.0, 1.0, 1.0], ["a", "b", "b"], ["RW", "S", "WF"]), 3,
     "conflicting status rows: row 2 says agent 'b' is S at t=1.0, row 3 says WF"),
    (([2.5, 0.0, 2.5], [7, 7, 7], ["WF", "RW", "s"]), 3,
     "conflicting status rows: row 1 says agent 7 is WF at t=2.5, row 3 says S"),
    # an exact repeat, found after sorting (rows 1 and 4), states compared after parsing
    (([3.0, 0.0, 1.0, 3.0], [1, 0, 1, 1], ["S", "RW", "RW", " S"]), 4,
     "duplicate status row: row 4 repeats row 1 (t=3.0, agent 1, S)"),
])
def test_two_status_rows_for_one_agent_at_one_time(rows, row, message):
    ids = rows[1]
    err = error_of([0.0], [ids[0]], ["zz" if isinstance(ids[0], str) else 99], status=rows)
    assert (err.file, err.row) == ("st.csv", row)
    assert message in str(err)


def test_same_time_different_agents_or_same_agent_different_times_are_fine():
    log = EncounterLog.from_records([0.0], [0], [1], status=([1.0, 1.0, 2.0], [0, 1, 0], ["S", "S", "S"]))
    assert log.status_state.tolist() == [S, S, S]


def test_state_labels_and_parse_states_are_inverse():
    codes = np.array([RW, WF, S, S, RW], np.int8)
    labels = state_labels(codes)
    assert labels.dtype == object and labels.tolist() == ["RW", "WF", "S", "S", "RW"]
    assert parse_states(labels, "x").tolist() == codes.tolist()
    assert parse_states(pa.array(labels.tolist()).dictionary_encode(), "x").tolist() == codes.tolist()
    for bad in ([0, 3], [-1], np.array([0.0, 1.0])):  # -1 must not wrap around to "S"
        with pytest.raises(InputError, match="state code must be an integer 0 .. 2"):
            state_labels(np.asarray(bad))


def test_static_listed_twice():
    with pytest.raises(InputError) as info:
        EncounterLog.from_records([0.0], [0], [1], static=([1, 0, 1], [1.0, 2.0, 3.0]),
                                  source={"static": "meta.json static"})
    assert (info.value.file, info.value.row, info.value.value) == ("meta.json static", 3, 1)


def test_columns_of_different_lengths():
    with pytest.raises(InputError, match="different lengths"):
        EncounterLog.from_records([0.0, 1.0], [0], [1])


def test_status_sorted_by_agent_then_time_and_stop_intervals():
    log = EncounterLog.from_records(
        [0.0], ["a"], ["b"],
        status=([5.0, 0.0, 2.0, 1.0, 3.0], ["b", "b", "a", "a", "a"], ["RW", "S", "S", "RW", "S"]))
    assert log.status_agent.tolist() == [0, 0, 0, 1, 1]
    assert log.status_t.tolist() == [1.0, 2.0, 3.0, 0.0, 5.0]
    agent, start, end = log.stop_intervals()
    # agent a stops at 2 and stays stopped (S again at 3): one open stop; b stops 0..5
    assert agent.tolist() == [0, 1] and start.tolist() == [2.0, 0.0] and end.tolist() == [np.inf, 5.0]


def test_empty_log():
    log = EncounterLog.from_records([], [], [])
    assert log.n_events == 0 and log.n_agents == 0 and log.duration == 0.0


def test_a_million_text_ids_from_pyarrow_take_no_per_row_python():
    """10^6 events with text IDs: one dictionary encoding, integer work only."""
    import time

    rng = np.random.default_rng(0)
    n, n_agents = 10**6, 300
    t = np.sort(rng.uniform(0, 300, n))
    a = rng.integers(0, n_agents, n)
    b = (a + rng.integers(1, n_agents, n)) % n_agents
    names = np.array([f"agent-{i:04d}" for i in range(n_agents)])
    col_a, col_b = pa.DictionaryArray.from_arrays(a, names), pa.DictionaryArray.from_arrays(b, names)
    start = time.perf_counter()
    log = EncounterLog.from_records(t, col_a, col_b)
    elapsed = time.perf_counter() - start
    assert log.n_events == n and log.n_agents == n_agents
    assert np.array_equal(log.a, np.minimum(a, b)) and np.array_equal(log.b, np.maximum(a, b))
    assert elapsed < 10.0  # about 0.3 s on one idle core; generous for a loaded 2-core machine
