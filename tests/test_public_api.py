"""The flat public API (issue 27): ``gearbody``'s own names (``simulate``, ``modes``, ``load_scenario``, ...)
and three namespaces, ``gearbody.analysis``, ``gearbody.studies`` and ``gearbody.render``, each with an
``__all__``; every public name has a docstring; there is one ``simulate`` (and one ``modes``); the README
and docs/*.md examples import public names only; ``import gearbody`` stays light.

Public means: a name of ``gearbody.__all__``, or of the ``__all__`` of one of :data:`NAMESPACES`.
``gearbody.plotting``, ``gearbody.reports`` and the layers below (model, assembly, engine, physics) are
internal: an example needing one of their names is a name missing from the public API."""

from __future__ import annotations

import ast
import dataclasses
import importlib
import inspect
import pkgutil
import subprocess
import sys
from functools import cache

import pytest
from doc_examples import DOCS, blocks

import gearbody

NAMESPACES = ("gearbody.analysis", "gearbody.studies", "gearbody.render", "gearbody.extend")


def _public() -> dict[str, set[str]]:
    """module -> its public names."""
    out = {"gearbody": set(gearbody.__all__)}
    for name in NAMESPACES:
        out[name] = set(importlib.import_module(name).__all__)
    return out


def test_the_top_level_names_and_namespaces_are_there():
    top = {"simulate", "modes", "load_scenario", "Scenario", "Result", "GearbodyError"}
    assert top <= set(gearbody.__all__)
    for name in NAMESPACES:
        short = name.split(".")[1]
        assert short in gearbody.__all__
        assert getattr(gearbody, short) is importlib.import_module(name)
    for module, names in _public().items():
        assert len(names) == len(importlib.import_module(module).__all__), f"{module}.__all__ repeats a name"
        missing = [n for n in names if not hasattr(importlib.import_module(module), n)]
        assert not missing, f"{module}.__all__ names what it does not have: {missing}"
    assert set(gearbody.__all__) <= set(dir(gearbody))


def test_one_simulate_and_one_modes():
    from gearbody import engine

    assert gearbody.simulate is engine.simulate
    assert gearbody.modes is engine.scene_modes
    by_name = gearbody.modes("one-stage").frequencies_hz
    assert list(by_name) == list(gearbody.modes(gearbody.load_scenario("one-stage")).frequencies_hz)


def test_import_gearbody_leaves_the_engine_and_the_namespaces_unimported():
    code = (
        "import sys, gearbody; "
        "print(sorted(m for m in ('exudyn', 'matplotlib', 'gearbody.engine', *"
        f"{NAMESPACES!r}) if m in sys.modules))"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert run.stdout.strip() == "[]", run.stdout


# --- docstrings ----------------------------------------------------------------------------------


@cache
def _attribute_docstrings() -> dict[str, list[tuple[str, str]]]:
    """name -> [(module, docstring)] of every module-level ``NAME = ...`` of gearbody followed by a string
    (an attribute docstring, as Sphinx reads them)."""
    found: dict[str, list[tuple[str, str]]] = {}
    for info in [*pkgutil.walk_packages(gearbody.__path__, "gearbody."), None]:
        name = "gearbody" if info is None else info.name
        if name.endswith(".__main__"):
            continue
        spec = importlib.util.find_spec(name)
        if not spec.origin.endswith(".py"):  # the compiled path's extension module
            continue
        tree = ast.parse(open(spec.origin).read())
        body = tree.body
        for node, after in zip(body, body[1:], strict=False):
            targets = node.targets if isinstance(node, ast.Assign) else [getattr(node, "target", None)]
            is_doc = isinstance(after, ast.Expr) and isinstance(after.value, ast.Constant)
            if isinstance(node, ast.Assign | ast.AnnAssign) and is_doc and isinstance(after.value.value, str):
                for t in targets:
                    if isinstance(t, ast.Name):
                        found.setdefault(t.id, []).append((name, after.value.value))
    return found


def _docstring(obj, name: str) -> str:
    """The public name's own docstring ('' when it has none)."""
    if inspect.ismodule(obj) or inspect.isroutine(obj):
        return (obj.__doc__ or "").strip()
    if inspect.isclass(obj):
        doc = (obj.__dict__.get("__doc__") or "").strip()
        generated = dataclasses.is_dataclass(obj) and doc.startswith(f"{obj.__name__}(")
        return "" if generated else doc
    # a constant: the docstring under its assignment, in a module that binds this very object
    for module, doc in _attribute_docstrings().get(name, []):
        if getattr(importlib.import_module(module), name, None) is obj and doc.strip():
            return doc.strip()
    return ""


@pytest.mark.parametrize("module", ["gearbody", *NAMESPACES])
def test_every_public_name_has_a_docstring(module):
    mod = importlib.import_module(module)
    assert (mod.__doc__ or "").strip(), module
    bare = sorted(n for n in mod.__all__ if not _docstring(getattr(mod, n), n))
    assert not bare, f"{module}: public names without a docstring: {bare}"


# --- the examples --------------------------------------------------------------------------------


def _python_blocks():
    return [b for doc in DOCS for b in blocks(doc) if b.lang == "python"]


def _non_public_imports(code: str) -> list[str]:
    """Every gearbody import of ``code`` that is not of a public name, and every ``gearbody.X`` /
    ``gb.X.Y`` attribute of an imported public module that is not public."""
    public = _public()
    bad, modules = [], {}  # modules: local name -> public module it is bound to
    tree = ast.parse(code)
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] != "gearbody":
                    continue
                if alias.name not in public:
                    bad.append(f"import {alias.name}")
                elif alias.asname:  # import gearbody.analysis as ga
                    modules[alias.asname] = alias.name
                else:  # import gearbody / import gearbody.analysis: binds gearbody
                    modules["gearbody"] = "gearbody"
        elif isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] == "gearbody":
            names = public.get(node.module)
            for alias in node.names:
                if names is None or alias.name not in names:
                    bad.append(f"from {node.module} import {alias.name}")
                elif f"{node.module}.{alias.name}" in public:
                    modules[alias.asname or alias.name] = f"{node.module}.{alias.name}"
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id in modules:
            module = modules[node.value.id]
            if node.attr not in public[module]:
                bad.append(f"{module}.{node.attr}")
    for node in ast.walk(tree):  # gearbody.analysis.X: X public in the namespace
        if (
            isinstance(node, ast.Attribute)
            and isinstance(node.value, ast.Attribute)
            and isinstance(node.value.value, ast.Name)
            and modules.get(node.value.value.id) == "gearbody"
            and f"gearbody.{node.value.attr}" in public
            and node.attr not in public[f"gearbody.{node.value.attr}"]
        ):
            bad.append(f"gearbody.{node.value.attr}.{node.attr}")
    return bad


def test_the_checker_tells_public_from_internal_names():
    code = (
        "import gearbody as gb\nimport gearbody.engine\nfrom gearbody import simulate, modes\n"
        "from gearbody.analysis import label_peaks\nfrom gearbody.analysis.features import Record\n"
        "from gearbody.engine import scene_modes\ngb.analysis.label_peaks\ngb.analysis.carrier_window\n"
        "gb.load_scenario('x')\ngb.model\nfrom gearbody import studies\nstudies.run_study\nstudies.tasks\n"
    )
    assert _non_public_imports(code) == [
        "import gearbody.engine",
        "from gearbody.analysis.features import Record",
        "from gearbody.engine import scene_modes",
        "gearbody.model",
        "gearbody.studies.tasks",
        "gearbody.analysis.carrier_window",
    ]


def test_the_readme_and_docs_examples_use_public_names_only():
    checked, bad = 0, []
    for block in _python_blocks():
        if "gearbody" in block.code:
            checked += 1
        bad += [f"{block.where}: {b}" for b in _non_public_imports(block.code)]
    assert checked >= 10
    assert not bad, "\n".join(bad)
