"""The compiled boundary's rules, read from the sources: one Python module imports the
extension, no kernel entry point takes more than six positional arguments (records cross by
name: om_redundant/_core/), and the C folders follow the data path: ik/ includes nothing of
redundancy/ or binding/, redundancy/ nothing of binding/, and only binding/ includes Python.h."""

from __future__ import annotations

import ast
import re
import types
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
MAX_POSITIONAL = 6


def test_only_core_imports_the_extension():
    importers = []
    for path in sorted((ROOT / "om_redundant").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            names = []
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                names = [f"{node.module}.{alias.name}" for alias in node.names] + [str(node.module)]
            if any(name.split(".")[-1] == "ckernels" for name in names):
                importers.append(path.relative_to(ROOT).as_posix())
    assert set(importers) == {"om_redundant/_core/__init__.py"}


def test_the_c_folders_include_along_the_data_path():
    folders = {path.name: {header.name for header in path.glob("*.h")} for path in (ROOT / "csrc").iterdir()}
    assert set(folders) == {"ik", "redundancy", "binding"}
    allowed = {
        "ik": folders["ik"],
        "redundancy": folders["ik"] | folders["redundancy"],
        "binding": folders["ik"] | folders["redundancy"] | folders["binding"],
    }
    for folder, headers in allowed.items():
        for path in sorted((ROOT / "csrc" / folder).glob("*.[ch]")):
            source = path.read_text()
            quoted = set(re.findall(r'#include "([^"]+)"', source))
            assert quoted <= headers, (folder, path.name, quoted - headers)
            python = "#include <Python.h>" in source
            assert python == (folder == "binding" and path.name == "binding.h"), (folder, path.name)


def test_no_entry_point_takes_more_than_six_positional_arguments():
    """Each kernel function and Solver method, called with seven positional arguments, refuses
    them by count, naming at most six."""
    from om_redundant import OMSolver, _core

    kernel = OMSolver("panda").kernel
    entries = {name: getattr(_core, name) for name in dir(_core)}
    entries = {name: f for name, f in entries.items() if isinstance(f, types.BuiltinFunctionType)}
    methods = [
        name for name in dir(_core.Solver) if not name.startswith("_") and callable(getattr(kernel, name))
    ]
    entries.update({f"Solver.{name}": getattr(kernel, name) for name in methods})
    assert len(entries) > 30, sorted(entries)
    taken = {}
    for name, entry in entries.items():
        with pytest.raises(TypeError) as raised:
            entry(*[None] * (MAX_POSITIONAL + 1))
        count = re.search(r"takes (?:at most )?(\d+)|takes \(([^)]*)\)", str(raised.value))
        assert count, f"{name}: {raised.value}"
        taken[name] = int(count[1]) if count[1] else len(count[2].split(","))
    over = {name: n for name, n in taken.items() if n > MAX_POSITIONAL}
    assert not over, over
