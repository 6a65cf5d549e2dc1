"""Output folders are replaced whole or not at all (swarmtopo.io.output), and Ctrl-C in a
command is one line saying what was and was not written."""

import os
import sys
from pathlib import Path

import pytest

from swarmtopo.errors import InputError, SwarmtopoError
from swarmtopo.io import output
from swarmtopo.io.output import Interrupted, staged_folder

MAP = ("map.json", "report.html", "diagram.png", "cloud.png")


def snapshot(folder: Path) -> dict[str, bytes]:
    """Every file under ``folder`` (hidden ones too) -> its bytes."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def hidden(folder: Path) -> list[str]:
    """Staging or aside folders left beside or in ``folder``."""
    return [p.name for p in (*folder.parent.iterdir(), *(folder.iterdir() if folder.is_dir() else ()))
            if ".partial-" in p.name or p.name.startswith(".swarmtopo-")]


def previous_map(folder: Path) -> dict[str, bytes]:
    folder.mkdir(parents=True)
    for name in ("map.json", "report.html", "diagram.png", "cloud.png"):
        (folder / name).write_text(f"old {name}")
    (folder / "notes.txt").write_text("mine")
    return snapshot(folder)


def test_a_new_folder_appears_only_complete(tmp_path):
    final = tmp_path / "a" / "b" / "map"
    with staged_folder(final, MAP, what="map", overwrite=False) as stage:
        (stage.path / "map.json").write_text("new")
        # staged in the nearest existing folder; the parents appear with the result
        assert stage.path.parent == tmp_path and list(tmp_path.iterdir()) == [stage.path]
    assert snapshot(final) == {"map.json": b"new"} and hidden(final) == []
    assert list(tmp_path.iterdir()) == [tmp_path / "a"]
    assert output.COMMITTED[-1] == final and stage.final_path(stage.path / "map.json") == final / "map.json"


@pytest.mark.parametrize("exists", [False, True])
def test_a_writer_failing_midway_leaves_the_previous_folder_untouched(tmp_path, exists):
    final = tmp_path / "runs" / "map"
    before = previous_map(final) if exists else None
    with pytest.raises(RuntimeError, match="disk on fire"):
        with staged_folder(final, MAP, what="map", overwrite=True) as stage:
            (stage.path / "map.json").write_text("new")
            (stage.path / "report.html").write_text("new, half")
            raise RuntimeError("disk on fire")
    if exists:
        assert snapshot(final) == before and hidden(final) == []
    else:  # nothing left: not the folder, not the parents made for it
        assert not (tmp_path / "runs").exists() and list(tmp_path.iterdir()) == []


def test_replacing_keeps_files_the_command_did_not_write(tmp_path):
    final = tmp_path / "map"
    previous_map(final)
    with staged_folder(final, MAP, what="map", overwrite=True) as stage:
        for name in ("map.json", "report.html", "diagram.png"):  # no cloud.png this time
            (stage.path / name).write_text(f"new {name}")
    assert snapshot(final) == {"diagram.png": b"new diagram.png", "map.json": b"new map.json",
                               "notes.txt": b"mine", "report.html": b"new report.html"}
    assert stage.removed == [final / "cloud.png"] and hidden(final) == []


def test_a_subfolder_is_merged_when_owned_by_name(tmp_path):
    """The demo's D/log: its log files replaced, the user's files and a map of it kept."""
    final = tmp_path / "demo"
    (final / "log" / "map").mkdir(parents=True)
    (final / "log" / "events.parquet").write_text("old events")
    (final / "log" / "meta.json").write_text("old meta")
    (final / "log" / "map" / "map.json").write_text("map of the old log")
    (final / "log" / "notes.txt").write_text("mine")
    (final / "map.json").write_text("old map")
    owned = {"log": ["events.parquet", "meta.json"], **dict.fromkeys(MAP)}
    with staged_folder(final, owned, what="demo", overwrite=True) as stage:
        (stage.path / "log").mkdir()
        (stage.path / "log" / "events.csv").write_text("new events")
        (stage.path / "log" / "meta.json").write_text("new meta")
        (stage.path / "map.json").write_text("new map")
    assert snapshot(final) == {"log/events.csv": b"new events", "log/meta.json": b"new meta",
                               "log/map/map.json": b"map of the old log", "log/notes.txt": b"mine",
                               "map.json": b"new map"}
    assert stage.removed == [final / "log" / "events.parquet"]


def test_an_error_names_the_final_file_not_the_staged_one(tmp_path):
    final = tmp_path / "map"
    with pytest.raises(InputError) as info:
        with staged_folder(final, MAP, what="map", overwrite=True) as stage:
            raise InputError("cannot write file (disk full)", file=str(stage.path / "map.json"))
    assert str(info.value) == f"{final / 'map.json'}: cannot write file (disk full)"
    assert info.value.file == str(final / "map.json")


def test_a_failed_switch_is_undone(tmp_path, monkeypatch):
    final = tmp_path / "map"
    before = previous_map(final)
    real, calls = os.rename, []

    def failing(source, destination):
        calls.append(source)
        if len(calls) == 6:  # the four old files moved aside, one new file in: the next fails
            raise OSError(28, "No space left on device")
        real(source, destination)

    monkeypatch.setattr(output.os, "rename", failing)
    with pytest.raises(SwarmtopoError, match=rf"^{final}: cannot move the new map into place \(No space left"):
        with staged_folder(final, MAP, what="map", overwrite=True) as stage:
            for name in MAP:
                (stage.path / name).write_text("new")
    assert len(calls) == 6 + 5 and snapshot(final) == before and hidden(final) == []  # five renames undone


def test_an_existing_result_needs_overwrite(tmp_path):
    final = tmp_path / "map"
    before = previous_map(final)
    with pytest.raises(SwarmtopoError) as info:
        with staged_folder(final, MAP, what="map", overwrite=False):
            pytest.fail("the block must not run")
    assert str(info.value) == (f"{final}: already holds a map (cloud.png, diagram.png, map.json, report.html); "
                               "pass --overwrite to replace it, or choose another --out")
    assert snapshot(final) == before and hidden(final) == []
    (tmp_path / "file").write_text("x")
    with pytest.raises(SwarmtopoError, match="file: is a file; give a folder for the map"):
        with staged_folder(tmp_path / "file", MAP, what="map", overwrite=True):
            pass


def test_a_symlinked_folder_is_written_where_it_points(tmp_path):
    real = tmp_path / "real"
    previous_map(real)
    link = tmp_path / "link"
    link.symlink_to(real, target_is_directory=True)
    with staged_folder(link, MAP, what="map", overwrite=True) as stage:
        (stage.path / "map.json").write_text("new")
    assert link.is_symlink() and (real / "map.json").read_text() == "new" and (real / "notes.txt").exists()
    assert not (real / "report.html").exists() and hidden(real) == []


@pytest.mark.parametrize("exists", [False, True])
def test_ctrl_c_says_what_the_folder_still_holds(tmp_path, exists):
    final = tmp_path / "map"
    before = previous_map(final) if exists else None
    with pytest.raises(Interrupted) as info:
        with staged_folder(final, MAP, what="map", overwrite=True, note="the store keeps the rest") as stage:
            (stage.path / "map.json").write_text("new")
            raise KeyboardInterrupt
    held = f"nothing written; {final} still holds the previous map" if exists else "no map written"
    assert info.value.message == f"interrupted: {held}; the store keeps the rest"
    assert (snapshot(final) == before) if exists else not final.exists()
    assert hidden(final) == []


# -- through the command line's entry point ------------------------------------------------
def run_main(monkeypatch, capsys, *args) -> tuple[int, str, str]:
    """``swarmtopo ARGS`` in this process: (exit code, stdout, stderr)."""
    from swarmtopo.cli import main

    monkeypatch.setattr(sys, "argv", ["swarmtopo", *map(str, args)])
    with pytest.raises(SystemExit) as info:
        main()
    captured = capsys.readouterr()
    return info.value.code, captured.out, captured.err


def tiny_log(folder: Path) -> dict[str, bytes]:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "events.csv").write_text("t,a,b\n" + "".join(f"{i},{i % 5},{(i + 1) % 5}\n" for i in range(40)))
    return snapshot(folder)


@pytest.mark.parametrize("exists", [False, True])
def test_ctrl_c_in_map_is_one_line_and_exit_130(tmp_path, monkeypatch, capsys, exists):
    import swarmtopo.pipeline

    log = tmp_path / "log"
    tiny_log(log)
    before = previous_map(log / "map") if exists else None

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(swarmtopo.pipeline, "map_encounters", interrupted)
    code, out, err = run_main(monkeypatch, capsys, "map", log, *(["--overwrite"] if exists else []))
    held = f"nothing written; {log / 'map'} still holds the previous map" if exists else "no map written"
    assert (code, out, err) == (130, "", f"interrupted: {held}\n")
    assert (snapshot(log / "map") == before) if exists else not (log / "map").exists()
    assert hidden(log / "map") == []


def test_ctrl_c_in_a_command_that_writes_nothing(monkeypatch, capsys):
    import swarmtopo.experiments.plan

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(swarmtopo.experiments.plan, "load_plan", interrupted)
    assert run_main(monkeypatch, capsys, "plan", "--area", 250000, "--agents", 200, "--duration", 30) == \
        (130, "", "interrupted: nothing written\n")


def test_a_log_writer_failing_midway_keeps_the_previous_log(tmp_path, monkeypatch, capsys):
    import swarmtopo.io.logs

    folder = tmp_path / "deployment"
    tiny_log(folder)
    (folder / "notes.txt").write_text("mine")
    before = snapshot(folder)
    real = swarmtopo.io.logs.write_log

    def failing(log, directory, **options):
        real(log, directory, **options)
        raise OSError(28, "No space left on device", str(Path(directory) / "events.csv"))

    monkeypatch.setattr(swarmtopo.io.logs, "write_log", failing)
    code, out, err = run_main(monkeypatch, capsys, "simulate", "--agents", 10, "--duration", 1, "--out", folder,
                              "--overwrite")
    assert (code, out, err) == (1, "", f"error: {folder / 'events.csv'}: No space left on device\n")  # not the staged
    assert snapshot(folder) == before and hidden(folder) == []


def test_an_entry_the_command_did_not_write_is_never_replaced(tmp_path):
    """A user's folder where the command writes a file, or a file where it keeps a
    folder: refused, naming it, and nothing moves."""
    (tmp_path / "events.csv").mkdir()
    (tmp_path / "events.csv" / "inner.txt").write_text("mine")
    with pytest.raises(SwarmtopoError, match=r"events.csv: a folder swarmtopo did not write"):
        with staged_folder(tmp_path, [], what="log", overwrite=True) as stage:
            (stage.path / "events.csv").write_text("t,a,b\n")
    assert (tmp_path / "events.csv" / "inner.txt").read_text() == "mine"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["events.csv"]  # no staging folder left
    (tmp_path / "log").write_text("precious")
    with pytest.raises(SwarmtopoError, match=r"log: is a file where the demo keeps a folder"):
        with staged_folder(tmp_path, {"log": ["events.csv"]}, what="demo", overwrite=True):
            pass
    assert (tmp_path / "log").read_text() == "precious"


def test_map_of_a_file_says_it_is_not_a_log_folder(tmp_path, cli):
    (tmp_path / "events.csv").write_text("t,a,b\n0,1,2\n")
    proc = cli("map", tmp_path / "events.csv")
    assert proc.returncode == 1 and proc.stderr.count("\n") == 1, proc.stderr
    assert "is a file, not a log folder" in proc.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["events.csv"]


def test_a_real_sigint_during_a_re_map_keeps_the_previous_map(tmp_path, one_hole_log):
    """Ctrl-C as a terminal sends it, to a real process: one line, exit 130, the previous
    map byte for byte, no staging folder left (whenever during the run it arrives)."""
    import shutil
    import signal
    import subprocess
    import time

    log = tmp_path / "log"
    shutil.copytree(one_hole_log.folder, log)
    out = log / "map"
    previous = previous_map(out)
    for delay in (1.0, 2.0):  # during start-up and reading, and during the map (about 2.5 s on 2 cores)
        proc = subprocess.Popen([sys.executable, "-m", "swarmtopo", "map", str(log), "--overwrite"],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        time.sleep(delay)
        proc.send_signal(signal.SIGINT)
        stdout, stderr = proc.communicate(timeout=120)
        if proc.returncode == 0:  # the map finished first: nothing to interrupt on this machine
            continue
        assert proc.returncode == 130, stderr
        assert len(stderr.strip().splitlines()) == 1 and stderr.startswith("interrupted: nothing written"), stderr
        assert snapshot(out) == previous and hidden(out) == []
