"""What a user reads on the command line: every command described, every default stated, the modes
table's value columns under their headers."""

from __future__ import annotations

import argparse

import pytest

from gearbody.cli import _parser, main


def _commands() -> dict[str, argparse.ArgumentParser]:
    sub = next(a for a in _parser()._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


def test_every_command_is_described_in_the_overview_and_its_own_help():
    overview = _parser().format_help()
    for name, parser in _commands().items():
        lines = overview.splitlines()
        at = next((k for k, ln in enumerate(lines) if ln.split()[:1] == [name]), None)
        assert at is not None, f"{name} is not listed in gearbody --help"
        # argparse puts a long command's description on the next line, indented
        text = lines[at].split()[1:] or (lines[at + 1].split() if at + 1 < len(lines) else [])
        assert len(text) > 2, f"{name} has no description in gearbody --help"
        assert parser.description, f"gearbody {name} --help has no description"


def test_every_option_with_a_default_states_it():
    for name, parser in _commands().items():
        for action in parser._actions:
            if action.default in (None, False, [], argparse.SUPPRESS) or not action.option_strings:
                continue
            assert "default" in (action.help or "").lower(), f"gearbody {name} {action.option_strings[0]}"


@pytest.mark.parametrize("scene", ["one-stage", "lateral-8dof"])
def test_modes_values_sit_under_their_headers(scene, capsys):
    assert main(["modes", scene, "--harmonics", "2"]) == 0
    lines = capsys.readouterr().out.splitlines()
    head = next(ln for ln in lines if ln.lstrip().startswith("mode"))
    rows = [ln for ln in lines[lines.index(head) + 1 :] if ln[:4].strip().isdigit()]
    assert rows
    for title in ("f_n Hz", "w(1f_z) rad/s", "w(2f_z) rad/s"):
        end = head.index(title) + len(title)  # right-aligned: a value ends where its header ends
        for row in rows:
            assert len(row) >= end and row[end - 1] != " " and (len(row) == end or row[end] == " "), (
                f"{title!r} column misaligned in {row!r}"
            )
    start = head.index("dominant motion")  # left-aligned text column
    for row in rows:
        assert row[start - 1] == " " and row[start] != " "
