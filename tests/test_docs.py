"""The README and docs/*.md hold: every Python block and ``gearbody`` command runs as a new user runs it
(in order, in a fresh folder per document), the numbers the text quotes are the ones printed, the
commands parse, and nothing cites a file outside the repository. The machinery and its directives
(``<!-- doc-test ... -->`` before a block): tests/doc_examples.py."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from doc_examples import DOCS, PROVIDED, ROOT, blocks, examples, report, run_doc

from gearbody.cli import _parser
from gearbody.model import load_scenario
from gearbody.model.io import scenario_to_dict
from gearbody.model.scenes import list_scenes


def _name(doc: Path) -> str:
    return str(doc.relative_to(ROOT))


RUNNABLE = [d for d in DOCS if any(not b.skip for b in examples(d))]


@pytest.mark.parametrize("doc", DOCS, ids=_name)
def test_every_example_parses_and_every_directive_applies(doc):
    for block in examples(doc):
        code = block.runnable_code()  # ValueError: a replace no longer applies
        if block.lang == "python":
            compile(code, block.where, "exec")
            continue
        for words in block.commands(code):
            if words[0] == "gearbody":
                try:
                    _parser().parse_args(words[1:])
                except SystemExit:
                    pytest.fail(f"{block.where}: {' '.join(words)} does not parse")
            elif words[0] not in PROVIDED and not block.skip:
                pytest.fail(f"{block.where}: {words[0]} ...: not a gearbody command; mark the block skip")


def test_the_docs_have_examples_to_run():
    assert len(RUNNABLE) >= 8 and sum(len(examples(d)) for d in DOCS) >= 25


@pytest.mark.slow
@pytest.mark.parametrize("doc", RUNNABLE, ids=_name)
def test_the_examples_run_as_written_and_print_what_the_text_says(doc, tmp_path):
    outcomes = run_doc(doc, tmp_path)
    assert not any(o.failure for o in outcomes), report(outcomes)


# --- citations -----------------------------------------------------------------------------------

OUTSIDE = re.compile(r"REFERENCES\.md|ARCHITECTURE\.md|STYLE\.md|\.\./shared|/work/")
"""Files the team keeps outside the repository: a user has none of them."""


def _texts():
    for folder, pattern in (("docs", "*.md"), ("scenes", "*.toml"), ("gearbody", "*.py"), ("tests", "*.py")):
        yield from (ROOT / folder).rglob(pattern)
    yield from (ROOT / "validation").rglob("*.py")
    yield from (ROOT / "validation").rglob("*.md")
    yield ROOT / "README.md"


def test_nothing_cites_a_file_outside_the_repository():
    own = Path(__file__).resolve()
    hits = [
        f"{path.relative_to(ROOT)}:{n}: {line.strip()}"
        for path in _texts()
        if path.resolve() != own
        for n, line in enumerate(path.read_text().splitlines(), 1)
        if OUTSIDE.search(line)
    ]
    assert not hits, "\n".join(hits)


@pytest.mark.parametrize("scene", list_scenes())
def test_a_resolved_scenario_cites_what_the_repository_holds(scene):
    """The sources a run copies into its scenario.toml name publications or files of the repository."""
    sources = scenario_to_dict(load_scenario(scene))["meta"]["sources"]
    assert sources
    for text in sources:
        assert not OUTSIDE.search(text), text
        for path in re.findall(r"\b((?:docs|scenes|validation)/[\w/.-]+\.(?:md|toml|py))\b", text):
            assert (ROOT / path).exists(), f"{scene}: {path}"


def test_references_hold_every_publication_the_scenes_cite():
    text = (ROOT / "docs" / "references.md").read_text()
    for author in ("Bartelmus", "Lin, R. G. Parker", "McFadden", "Parker", "Sainsot", "ISO 6336-1"):
        assert author in text, author


def test_relative_links_of_the_docs_resolve():
    broken = []
    for doc in DOCS:
        for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", doc.read_text()):
            if "://" in target:
                continue
            if not (doc.parent / target).exists():
                broken.append(f"{_name(doc)}: {target}")
    assert not broken, broken


def test_blocks_are_found_with_their_directives():
    """The harness reads what the docs say: a skipped block and a replaced setting exist somewhere."""
    every = [b for d in DOCS for b in blocks(d)]
    assert any(b.skip for b in every) and any(b.replace for b in every) and any(b.expect for b in every)
