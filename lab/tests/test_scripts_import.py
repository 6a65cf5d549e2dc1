"""Every research script and benchmark imports (the package moved under them once), and
calls ``map_encounters`` only with its real keywords."""

import ast
import importlib.util
import inspect
import sys
from pathlib import Path

import pytest

from swarmtopo.pipeline import map_encounters

ROOT = Path(__file__).resolve().parent.parent.parent
SCRIPTS = sorted([*(ROOT / "lab").glob("*.py"), *(ROOT / "benchmarks").glob("*.py")])
KEYWORDS = set(inspect.signature(map_encounters).parameters)


@pytest.mark.parametrize("path", SCRIPTS, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_a_script_imports_and_maps_with_real_keywords(path, monkeypatch):
    monkeypatch.syspath_prepend(str(path.parent))  # siblings import each other
    spec = importlib.util.spec_from_file_location(f"_script_{path.stem}", path)
    module = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, spec.name, module)
    spec.loader.exec_module(module)  # every script guards its main() with __name__
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Call) and getattr(node.func, "id", getattr(node.func, "attr", None)) == "map_encounters":
            unknown = {k.arg for k in node.keywords if k.arg} - KEYWORDS
            assert not unknown, f"{path.name}:{node.lineno} calls map_encounters with {sorted(unknown)}"
