"""What the README shows a newcomer is true: its Python example runs, and mapping the
example events.csv prints the answer the README quotes."""

import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
README = (ROOT / "README.md").read_text(encoding="utf-8")


def blocks(language: str) -> list[str]:
    """The README's fenced blocks of ``language`` ("" for plain ones), in order."""
    found, current, info = [], None, None
    for line in README.splitlines(keepends=True):
        if line.startswith("```"):
            if current is None:
                current, info = [], line[3:].strip()
            else:
                if info == language:
                    found.append("".join(current))
                current = None
        elif current is not None:
            current.append(line)
    return found


def test_the_first_block_is_the_two_commands_ci_runs():
    commands = [line.split("#")[0].strip() for line in blocks("bash")[0].splitlines() if line.strip()]
    assert commands == ['pip install . && swarmtopo demo', 'pip install ".[test]" && python -m pytest']
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    assert "README.md" in ci and "run_fresh demo" in ci and "run_fresh tests" in ci


def test_the_python_example_runs(tmp_path, monkeypatch):
    [example] = blocks("python")
    shutil.copytree(ROOT / "examples" / "encounters", tmp_path / "examples" / "encounters")
    monkeypatch.chdir(tmp_path)
    exec(compile(example, "README.md", "exec"), {"__name__": "readme"})
    assert (tmp_path / "two-holes-map" / "map.json").is_file()
    assert (tmp_path / "two-holes-map" / "report.html").is_file()


def test_mapping_the_example_events_prints_what_the_readme_says(tmp_path):
    quoted = next(block for block in blocks("") if block.startswith("recovered:") and "beta_1 = 2" in block)
    folder = tmp_path / "encounters"
    shutil.copytree(ROOT / "examples" / "encounters", folder)
    assert sorted(p.name for p in folder.iterdir()) == ["events.csv"]  # the one file a log folder needs
    done = subprocess.run([sys.executable, "-m", "swarmtopo", "map", str(folder), "--out", str(tmp_path / "my-map")],
                          capture_output=True, text=True, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines()[0] == quoted.splitlines()[0]
    assert done.stdout.splitlines()[-1] == quoted.splitlines()[-1].replace("my-map", str(tmp_path / "my-map"))
