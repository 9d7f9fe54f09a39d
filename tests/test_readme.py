"""What the README says of itself: its quick start is CI's test command, its examples write their own
folders, and its Fig. 9 sweep is docs/sweep.md's. That its examples run and print what it says:
tests/test_docs.py, with every other document (the machinery: tests/doc_examples.py)."""

import re
from pathlib import Path

from doc_examples import examples

README = Path(__file__).resolve().parents[1] / "README.md"


def test_readme_quick_start_is_the_ci_test_command():
    text = README.read_text()
    ci = (README.parent / ".ci" / "run").read_text()
    assert 'pip install ".[test]" && pytest' in text and 'pip install ".[test]" && pytest' in ci


def _readme_commands() -> list[list[str]]:
    """Every ``gearbody ...`` command of the README's shell blocks, as written."""
    return [w[1:] for b in examples(README) if b.shell for w in b.commands() if w[0] == "gearbody"]


def test_readme_examples_write_their_own_folders():
    """No two README examples that write run output write the same folder (issue 17: every example
    overwrote runs/one-stage)."""
    from gearbody.cli import _parser
    from gearbody.cli.common import default_out

    writers: dict[str, set[str]] = {}  # folder -> the different commands writing it
    commands = _readme_commands()
    assert len(commands) >= 10
    for words in commands:
        args = _parser().parse_args(words)
        if args.command in ("run", "sweep", "mesh"):
            sub = {"mesh": ("mesh",)}.get(args.command, ())
            folder = str(args.out or default_out(args.scene, *sub))
            writers.setdefault(folder, set()).add(" ".join(words))
    assert len(writers) >= 5
    shared = {folder: commands for folder, commands in writers.items() if len(commands) > 1}
    assert not shared, shared


def test_readme_fig9_sweep_runs_at_rated_speed_and_load_like_docs_sweep():
    def fig9(text: str) -> set[str]:
        block = next(b for b in re.findall(r"```bash\n(.*?)```", text, re.S) if "error_mode.e_um=0:20:5" in b)
        line = next(ln for ln in block.replace("\\\n", " ").splitlines() if "e_um=0:20:5" in ln)
        return {w for w in line.split() if "=" in w}

    readme = fig9(README.read_text())
    docs = fig9((README.parent / "docs" / "sweep.md").read_text())
    assert docs <= readme, docs - readme
    assert any("speed_profile" in w for w in readme) and any("load_profile" in w for w in readme)


def test_readme_says_which_scenes_have_a_run_up_case_and_which_lose_their_backlash_in_it():
    from gearbody_validation.compare import NO_RUN_UP, cases

    from gearbody.model.scenes import list_scenes

    text = " ".join(README.read_text().split())
    said = re.search(r"for every scene but (.*?) \(on bearings", text)
    assert said and set(re.findall(r"`([\w-]+)`", said.group(1))) == set(NO_RUN_UP)
    kept = re.search(r"It runs without backlash on every scene but `([\w-]+)`", text)
    with_run_up = [s for s in list_scenes() if s not in NO_RUN_UP]
    keep_backlash = [
        s for s in with_run_up if not next(c for c in cases(s) if c.name == "run-up").no_backlash
    ]
    assert kept and keep_backlash == [kept.group(1)]
