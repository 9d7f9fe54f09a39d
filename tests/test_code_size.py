"""Issue 27, deliverable 5 (size): no module of gearbody/ over 400 lines and no function over 80 lines
without a one-line reason at its top.

The reason is a comment of the form ``# size: <reason>``:

- a module: on one of its first 10 lines;
- a function: inside it, before its first statement (the docstring may come first), i.e. the first
  comment of its body.

Lengths are counted as in ``benchmarks/code_shape.py``: a module's lines, a function from its ``def``
line to its last line (nested functions and methods included, each on its own).
"""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "gearbody"
MODULE_LINES, FUNCTION_LINES = 400, 80
REASON = "# size: "
MODULE_REASON_LINES = 10

# Items over the limit while other parts of issue 27 restructured their files (the engine, the assembly,
# the renderer, the result, the scenario and planetary model, stage geometry). Emptied by issue 27: keep
# it empty (split an item, or give it a `# size:` reason). The test fails when an item listed here is no
# longer over the limit (or has its reason, or no longer exists), so the list cannot go stale.
PENDING: set[str] = set()


def _is_reason(line: str) -> bool:
    text = line.strip()
    return text.startswith(REASON) and bool(text[len(REASON) :].strip())


def _function_has_reason(node: ast.FunctionDef | ast.AsyncFunctionDef, lines: list[str]) -> bool:
    """A ``# size:`` comment before the function's first statement (after its docstring or before it)."""
    body = node.body
    docstring = isinstance(body[0], ast.Expr) and isinstance(getattr(body[0], "value", None), ast.Constant)
    first = body[1] if docstring and len(body) > 1 else body[0]
    start = node.lineno  # the def line (decorators come before it)
    return any(_is_reason(line) for line in lines[start : first.lineno - 1])


def oversized() -> dict[str, int]:
    """``{name: lines}`` of every module and function over its limit without a ``# size:`` reason;
    names relative to gearbody/: ``studies/runner.py`` and ``studies/runner.py:run_study``."""
    found: dict[str, int] = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        if "__pycache__" in path.parts:
            continue
        rel = path.relative_to(PACKAGE).as_posix()
        lines = path.read_text().splitlines()
        if len(lines) > MODULE_LINES and not any(_is_reason(line) for line in lines[:MODULE_REASON_LINES]):
            found[rel] = len(lines)
        for node in ast.walk(ast.parse("\n".join(lines))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = node.end_lineno - node.lineno + 1
                if n > FUNCTION_LINES and not _function_has_reason(node, lines):
                    found[f"{rel}:{node.name}"] = n
    return found


def test_no_module_or_function_over_the_limit_without_a_reason():
    over = {name: n for name, n in oversized().items() if name not in PENDING}
    assert not over, (
        "over the size limit (modules 400 lines, functions 80) without a '# size: <reason>' line at the "
        "top: split them, or give the reason: " + ", ".join(f"{k} ({n})" for k, n in sorted(over.items()))
    )


def test_the_pending_allowlist_holds_only_items_still_over_the_limit():
    stale = sorted(PENDING - set(oversized()))
    assert not stale, f"no longer over the limit (or given a reason): remove from PENDING: {', '.join(stale)}"


def test_the_reason_is_recognised_where_it_is_documented():
    source = '''
def f():
    """Doc."""
    # size: a reason
    return 1

def g():
    # size: a reason
    return 1

def h():
    """Doc."""
    x = 1
    # size: too late
    return x

def k():
    # size:
    return 1
'''
    lines = source.splitlines()
    fns = {n.name: n for n in ast.parse(source).body}
    assert _function_has_reason(fns["f"], lines)
    assert _function_has_reason(fns["g"], lines)
    assert not _function_has_reason(fns["h"], lines)
    assert not _function_has_reason(fns["k"], lines)
