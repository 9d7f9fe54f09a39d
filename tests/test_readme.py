"""The README's Python example runs as written."""

import re
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[1] / "README.md"


@pytest.mark.slow
def test_readme_python_examples_run():
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), re.S)
    assert blocks
    for code in blocks:
        exec(compile(code, "README.md", "exec"), {})


def test_readme_quick_start_is_the_ci_test_command():
    text = README.read_text()
    ci = (README.parent / ".ci" / "run").read_text()
    assert 'pip install ".[test]" && pytest' in text and 'pip install ".[test]" && pytest' in ci


def _readme_commands() -> list[list[str]]:
    """Every ``gearbody ...`` command of the README's bash blocks, continuation lines joined, comments cut."""
    import shlex

    commands = []
    for block in re.findall(r"```bash\n(.*?)```", README.read_text(), re.S):
        for line in block.replace("\\\n", " ").splitlines():
            words = shlex.split(line, comments=True)
            if words[:1] == ["gearbody"]:
                commands.append(words[1:])
    return commands


def test_readme_commands_parse():
    from gearbody.cli import _parser

    commands = _readme_commands()
    assert len(commands) >= 10
    for words in commands:
        _parser().parse_args(words)  # SystemExit (exit 2) on an unknown option or a bad value


def test_readme_examples_write_their_own_folders():
    """No two README examples that write run output write the same folder (issue 17: every example
    overwrote runs/one-stage)."""
    from gearbody.cli import _parser
    from gearbody.cli.common import default_out

    writers: dict[str, set[str]] = {}  # folder -> the different commands writing it
    for words in _readme_commands():
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
