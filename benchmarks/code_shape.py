"""The shape counts of issue 27, measured on gearbody/ (or another checkout's): lines that branch on the
stage kind and on topology or lateral freedom, inline copies of the stage naming rule, modules over 400
lines and functions over 80 lines.

    python benchmarks/code_shape.py [PACKAGE_DIR]      # default: gearbody/ of this checkout

The patterns are textual (stated below), so the counts compare two versions of the code, not two
projects.
"""

from __future__ import annotations

import ast
import re
import sys
from pathlib import Path

STAGE_KIND = re.compile(
    r"isinstance\([^)]*\b\w*Stage\b|\.type\b\s*[!=]=|get\(\"type\"\)\s*[!=]=|stage_kind\([^)]*\)\s*[!=]="
    r"|getattr\([^)]*\"type\"[^)]*\)\s*[!=]=|_is_planetary\("
)
"""A line that branches on a stage's kind: isinstance on a *Stage class, a comparison of a stage's type."""
TOPOLOGY = re.compile(r"\btopology\b\s*(?:[!=]=|in\b|not in\b)|\.is_lateral\b|\.lateral is (?:not )?None")
"""A line that branches on the topology or on lateral freedom."""
NAMING_COPIES = re.compile(
    r'f"_?stage_\{|f"(?:pinion|wheel)_\{|"" if \w+ == 0 else f"|\("pinion", "wheel"\) if \w+ == 0'
)
"""An inline spelling of the stage prefix, the stage file tag or the gear names."""
MODULE_LINES, FUNCTION_LINES = 400, 80


def counts(package: Path) -> dict:
    files = sorted(p for p in package.rglob("*.py") if "__pycache__" not in p.parts)
    kind, topo, copies, long_modules, long_functions = {}, {}, {}, [], []
    for path in files:
        rel = str(path.relative_to(package.parent))
        text = path.read_text()
        lines = text.splitlines()
        for pattern, where in ((STAGE_KIND, kind), (TOPOLOGY, topo), (NAMING_COPIES, copies)):
            hits = sum(1 for line in lines if pattern.search(line) and not line.lstrip().startswith("#"))
            if hits and not (where is copies and path.name == "signals.py" and path.parent == package):
                where[rel] = hits
        if len(lines) > MODULE_LINES:
            long_modules.append((rel, len(lines)))
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = node.end_lineno - node.lineno + 1
                if n > FUNCTION_LINES:
                    long_functions.append((f"{rel}:{node.name}", n))
    return {
        "stage-kind branch lines": (sum(kind.values()), len(kind)),
        "topology/lateral branch lines": (sum(topo.values()), len(topo)),
        "inline naming-rule copies": (sum(copies.values()), len(copies)),
        "modules over 400 lines": long_modules,
        "functions over 80 lines": long_functions,
    }


def main(argv: list[str]) -> int:
    package = Path(argv[0]) if argv else Path(__file__).resolve().parents[1] / "gearbody"
    for name, value in counts(package).items():
        if isinstance(value, tuple):
            print(f"{name}: {value[0]} in {value[1]} modules")
        else:
            print(f"{name}: {len(value)}")
            for item, n in sorted(value, key=lambda r: -r[1]):
                print(f"    {n:5d}  {item}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
