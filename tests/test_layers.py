"""Layers that point one way: the import-linter contracts of pyproject.toml hold, and no two modules of
gearbody import each other in a cycle (imports under TYPE_CHECKING are annotations and do not count)."""

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_import_contracts_hold():
    # the lint-imports of the environment running the tests (another one on PATH, say the system's,
    # cannot import this checkout's packages: the outcome would depend on how pytest was started)
    exe = Path(sys.executable).with_name("lint-imports")
    exe = str(exe) if exe.exists() else (shutil.which("lint-imports") or str(exe))
    if not Path(exe).exists():
        pytest.skip("import-linter is not installed (pip install '.[test]')")
    run = subprocess.run([exe, "--config", str(ROOT / "pyproject.toml")], capture_output=True, text=True)
    assert run.returncode == 0, run.stdout[-4000:] + run.stderr[-2000:]
    assert "BROKEN" not in run.stdout and "KEPT" in run.stdout


def _cycles(graph, modules: set[str]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan), among ``modules``."""
    index, low, stack, on, out = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph.find_modules_directly_imported_by(v) & modules:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    sys.setrecursionlimit(max(sys.getrecursionlimit(), 10_000))
    for v in sorted(modules):
        if v not in index:
            visit(v)
    return out


def test_no_import_cycles_between_modules():
    grimp = pytest.importorskip("grimp")
    graph = grimp.build_graph("gearbody", exclude_type_checking_imports=True)
    # a package's __init__ re-exporting its own modules is not a cycle between concerns
    modules = {m for m in graph.modules}
    for package in [m for m in modules if graph.find_children(m)]:
        for child in graph.find_descendants(package):
            if graph.direct_import_exists(importer=package, imported=child):
                graph.remove_import(importer=package, imported=child)
    assert _cycles(graph, modules) == []


def _package(module: str) -> str:
    """The top-level package (or module) of gearbody a module belongs to: gearbody.reports.mesh.figure ->
    gearbody.reports; the root package stays itself."""
    return ".".join(module.split(".")[:2])


def test_no_import_cycles_between_packages():
    """No two of gearbody's packages (analysis, plotting, reports, ..., and the top-level modules result,
    errors, ...) import each other, directly or around a longer loop: each layer can be understood, and
    replaced, from the ones below it (issue 27: plotting and reports imported each other)."""
    grimp = pytest.importorskip("grimp")
    graph = grimp.build_graph("gearbody", exclude_type_checking_imports=True)
    packages = {_package(m) for m in graph.modules}
    assert {"gearbody", "gearbody.plotting", "gearbody.reports", "gearbody.result"} <= packages
    edges: dict[str, set[str]] = {p: set() for p in packages}
    for module in graph.modules:
        for imported in graph.find_modules_directly_imported_by(module):
            a, b = _package(module), _package(imported)
            if a != b:
                edges[a].add(b)

    class Collapsed:  # the package graph, as _cycles reads a grimp graph
        @staticmethod
        def find_modules_directly_imported_by(package):
            return edges[package]

    assert _cycles(Collapsed, packages) == []
