"""The examples of the README and docs/*.md as a new user runs them: every ```python block and every
``gearbody ...`` line of a ```bash / ```sh block, in order, in a fresh folder per document, with the
printed numbers the text quotes checked.

A block takes its test settings from an HTML comment right before its fence (invisible on the rendered
page, beside the example in the source), one directive per line::

    <!-- doc-test
    replace: --frames 100 => --frames 2 --width 160 --height 120
    expect: eps_alpha ([0-9.]+) ~ 1.742 +- 0.0005
    expect: mean k_z ([0-9.e+]+) N/m ~ 1.07e9 +- 0.5%
    -->

- ``skip: REASON``: the block is not run (a Dask cluster, a display); its commands still parse.
- ``replace: OLD => NEW``: run the block with OLD replaced by NEW: the reduced settings of an inherently
  long example (a full validation, a 100-frame render), stated where the example is. OLD must occur.
  ``replace: OLD =>`` (nothing after the arrow) leaves OLD out: a command another test runs already.
- ``expect: REGEX``: the block's output (stdout and stderr of all its commands, or what its Python
  prints) must match REGEX. ``expect: REGEX ~ VALUE +- TOL`` (TOL absolute, or relative with ``%``): the
  number in REGEX's first group lies within TOL of VALUE, the figure the text quotes.

A one-line form works too: ``<!-- doc-test: skip: needs a display -->``. Shell lines other than
``gearbody`` commands are refused unless the block is skipped, except ``pip install ...`` and
``pytest ...``: the test environment is their outcome.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import shlex
import time
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOCS = (ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")))
SHELLS = ("bash", "sh", "shell", "console")
PROVIDED = ("pip", "pytest")
"""Shell commands the test environment stands for (the suite runs because they were run)."""

_FENCE = re.compile(r"^```(\w*)[^\n]*\n(.*?)^```[ \t]*$", re.S | re.M)
_DIRECTIVE = re.compile(r"<!--\s*doc-test:?\s*(.*?)-->\s*\Z", re.S)
_EXPECT = re.compile(r"^(?P<regex>.*?)(?:\s+~\s+(?P<value>\S+)\s+\+-\s+(?P<tol>\S+?)(?P<rel>%)?)?$")


@dataclass(frozen=True)
class Expect:
    regex: str
    value: float | None = None
    tolerance: float = 0.0
    relative: bool = False

    def check(self, output: str) -> str:
        """'' when the output holds, else why not."""
        m = re.search(self.regex, output, re.M)
        if not m:
            return f"expected output matching {self.regex!r}"
        if self.value is None:
            return ""
        got = float(m.group(1))
        tol = self.tolerance * abs(self.value) / 100 if self.relative else self.tolerance
        if not abs(got - self.value) <= tol:
            return f"{self.regex!r}: printed {got:g}, the text says {self.value:g} +- {tol:g}"
        return ""


@dataclass(frozen=True)
class Block:
    doc: Path
    line: int  # of the opening fence, 1-based
    lang: str
    code: str
    skip: str = ""
    replace: tuple[tuple[str, str], ...] = ()
    expect: tuple[Expect, ...] = field(default_factory=tuple)

    @property
    def where(self) -> str:
        return f"{self.doc.relative_to(ROOT)}:{self.line}"

    @property
    def shell(self) -> bool:
        return self.lang in SHELLS

    def runnable_code(self) -> str:
        """The code with the ``replace`` settings applied (ValueError when one no longer applies)."""
        code = self.code
        for old, new in self.replace:
            if old not in code:
                raise ValueError(f"{self.where}: replace: {old!r} is not in the block")
            code = code.replace(old, new)
        return code

    def commands(self, code: str | None = None) -> list[list[str]]:
        """The shell block's commands as words: continuation lines joined, comments cut, ``&&`` split."""
        out = []
        text = (self.code if code is None else code).replace("\\\n", " ")
        for line in text.splitlines():
            words = shlex.split(line, comments=True)
            while words:
                cut = words.index("&&") if "&&" in words else len(words)
                out.append(words[:cut])
                words = words[cut + 1 :]
        return out


def _directives(before: str, where: str) -> dict:
    m = _DIRECTIVE.match(before[before.rfind("<!--") :]) if "<!--" in before else None
    found: dict = {"skip": "", "replace": [], "expect": []}
    if not m:
        return found
    for raw in m.group(1).strip().splitlines():
        line = raw.strip()
        if not line:
            continue
        key, _, value = line.partition(":")
        key, value = key.strip(), value.strip()
        if key == "skip":
            found["skip"] = value or "skipped"
        elif key == "replace":
            old, sep, new = (value[:-3], " =>", "") if value.endswith(" =>") else value.partition(" => ")
            if not sep or not old:
                raise ValueError(f"{where}: replace needs 'OLD => NEW', got {value!r}")
            found["replace"].append((old, new))
        elif key == "expect":
            e = _EXPECT.match(value)
            number = e.group("value")
            found["expect"].append(
                Expect(
                    e.group("regex"),
                    None if number is None else float(number),
                    float(e.group("tol") or 0.0),
                    bool(e.group("rel")),
                )
            )
        else:
            raise ValueError(f"{where}: unknown doc-test directive {key!r} (skip, replace, expect)")
    return found


def blocks(doc: Path) -> list[Block]:
    """Every fenced block of ``doc`` with its directives."""
    text = doc.read_text()
    found = []
    for m in _FENCE.finditer(text):
        line = text.count("\n", 0, m.start()) + 1
        where = f"{doc.relative_to(ROOT)}:{line}"
        before = text[max(0, m.start() - 2000) : m.start()]
        d = _directives(before, where)
        found.append(
            Block(doc, line, m.group(1), m.group(2), d["skip"], tuple(d["replace"]), tuple(d["expect"]))
        )
    return found


def examples(doc: Path) -> list[Block]:
    """The blocks a user runs: Python and shell."""
    return [b for b in blocks(doc) if b.lang == "python" or b.shell]


@dataclass
class Outcome:
    block: Block
    seconds: float
    output: str
    failure: str = ""


def run_block(block: Block) -> Outcome:
    """Run one block in the current folder (the caller's per-document folder) and check its output."""
    from gearbody.cli import main

    t0 = time.perf_counter()
    out = io.StringIO()
    failure = ""
    try:
        code = block.runnable_code()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(out):
            if block.lang == "python":  # compiled as a user's script is: without this module's __future__
                exec(compile(code, block.where, "exec", dont_inherit=True), {"__name__": "__main__"})
            else:
                for words in block.commands(code):
                    if words[0] in PROVIDED:
                        continue
                    if words[0] != "gearbody":
                        raise ValueError(f"{shlex.join(words)}: not a gearbody command; mark the block")
                    print(f"$ {shlex.join(words)}")
                    code_ = main(words[1:])
                    if code_ != 0:
                        raise RuntimeError(f"{shlex.join(words)} exited with {code_}")
    except BaseException as exc:  # a failing example is reported, with what it printed
        if isinstance(exc, KeyboardInterrupt):
            raise
        failure = f"{type(exc).__name__}: {exc}"
    output = out.getvalue()
    if not failure:
        failure = "; ".join(filter(None, (e.check(output) for e in block.expect)))
    return Outcome(block, time.perf_counter() - t0, output, failure)


def run_doc(doc: Path, folder: Path) -> list[Outcome]:
    """Every example of ``doc`` in order, in ``folder`` (so ``runs/...`` of one block is there for the
    next), skipped ones left out."""
    previous = Path.cwd()
    os.chdir(folder)
    try:
        return [run_block(b) for b in examples(doc) if not b.skip]
    finally:
        os.chdir(previous)
        import matplotlib.pyplot as plt

        plt.close("all")


def report(outcomes: list[Outcome]) -> str:
    """Per block: where, seconds, and the failure with the tail of the output."""
    lines = []
    for o in outcomes:
        lines.append(f"{o.block.where}: {o.seconds:.1f} s{' FAILED' if o.failure else ''}")
        if o.failure:
            lines.append(f"  {o.failure}")
            lines.extend(f"  | {ln}" for ln in o.output.strip().splitlines()[-15:])
    return "\n".join(lines)
