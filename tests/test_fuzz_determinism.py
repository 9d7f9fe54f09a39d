"""The fuzzers draw the same inputs however pytest is invoked (issue 26): derandomized, no example
database, and no constants mined from the local modules imported so far (tests/fuzzing.py), which
differ with the test files collected before a fuzzer runs."""

from __future__ import annotations

import importlib
import struct
import sys

import fuzzing
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.internal.conjecture import providers

LOCAL_INT, LOCAL_FLOAT = 918_273_645, 7_654.321_987
"""The constants of the module imported in between (numbers no draw would give by chance)."""


def _draws() -> list:
    seen: list = []

    @fuzzing.fuzz_settings(300)
    @given(st.one_of(st.integers(), st.floats()))
    def record(value):
        seen.append(struct.pack("<d", value).hex() if isinstance(value, float) else value)  # NaN bits too

    record()
    return seen


def _import_local_module(tmp_path, name: str) -> None:
    """A module in a local folder (not site-packages, stdlib or a test folder), as a test collected
    earlier imports gearbody's modules: Hypothesis mines its constants if it may."""
    folder = tmp_path / "mined"
    folder.mkdir(exist_ok=True)
    (folder / f"{name}.py").write_text(f"A = {LOCAL_INT}\nB = {LOCAL_FLOAT!r}\n")
    sys.path.insert(0, str(folder))
    try:
        importlib.import_module(name)
    finally:
        sys.path.remove(str(folder))


def test_draws_do_not_change_with_the_modules_imported_before(tmp_path):
    assert fuzzing.LOCAL_CONSTANTS_SWITCHED_OFF  # this Hypothesis mines them: the switch is needed
    before = _draws()
    _import_local_module(tmp_path, "fuzz_mined_constants_a")
    after = _draws()
    assert after == before
    assert LOCAL_INT not in after and struct.pack("<d", LOCAL_FLOAT).hex() not in after


def test_without_the_switch_the_draws_take_the_mined_constants(tmp_path, monkeypatch):
    """The control: Hypothesis's own mining draws constants of the local modules imported so far (so the
    draws would depend on what was imported before); the switch is what keeps them out."""
    original = fuzzing.ORIGINAL_LOCAL_CONSTANTS
    monkeypatch.setattr(providers, "_get_local_constants", original)
    providers.CONSTANTS_CACHE.cache.clear()
    _import_local_module(tmp_path, "fuzz_mined_constants_b")
    mined = original()
    assert LOCAL_INT in mined.integers and LOCAL_FLOAT in mined.floats  # the new module's, among others
    local = set(mined.integers) | {struct.pack("<d", f).hex() for f in mined.floats}
    known = set(providers.GLOBAL_CONSTANTS.integers)
    known |= {struct.pack("<d", f).hex() for f in providers.GLOBAL_CONSTANTS.floats}
    drawn = _draws()
    monkeypatch.undo()
    providers.CONSTANTS_CACHE.cache.clear()
    assert {v for v in drawn if v in local and v not in known}, "no mined constant drawn"
    assert drawn != _draws()  # with the switch (back on), other draws
