"""Command lines a hostile user types (issue 26): every command of ``gearbody`` on every shipped scene,
with extreme option values (huge, tiny, negative, NaN, inf, non-numeric, empty, odd paths), odd scene
files (sizes, nesting, special files, bad UTF-8, binary) and odd output paths. Each command line ends
in exit 0, exit 2 with argparse's usage or one line, exit 3 with one line (a numerical failure) or exit
1 where documented (validate above tolerance, failed study runs, a file that cannot be written); never
a traceback, never a hang (every command is bounded in time), never a process left behind, and a
refused command leaves no output folder behind.

Each command starts from a cheap valid baseline (a few ms simulated, small renders, two-case studies)
and 1-3 options are drawn to extreme values; the runs that pass every check are therefore short. With
``--max-wall-minutes`` (where the command line has it) the baseline also bounds what an accepted
extreme may cost. Draws: tests/fuzzing.py (derandomized, no database, no local constants); a failure
prints the command line that reproduces it, with how its files were made.
"""

from __future__ import annotations

import os
import shutil
import socket
from dataclasses import dataclass
from pathlib import Path

import pytest
from fuzzing import GOOD, SCALE, CommandRunner, Report, fuzz_settings, leaves, runner_fixture
from hypothesis import given
from hypothesis import strategies as st

from gearbody.cli import COMMANDS, _parser
from gearbody.model import load_scenario, scenario_to_dict
from gearbody.model.io import MAX_NESTING, MAX_SCENARIO_BYTES
from gearbody.model.scenes import list_scenes, scene_path

pytestmark = pytest.mark.slow

SCENES = list_scenes()
REPORT = Report("cli")
KEY = "condition.friction_coefficient"  # a key every drive has


def _has_option(command: str, option: str) -> bool:
    sub = next(a for a in _parser()._actions if a.dest == "command").choices[command]
    return option in sub._option_string_actions


WALL = ["--max-wall-minutes", "0.5"]
"""Bounds what an accepted extreme may cost, where the command line estimates wall time."""


def _wall(command: str) -> list[str]:
    return WALL if _has_option(command, "--max-wall-minutes") else []


BASE = {
    "list": [],
    "info": [],
    "new": ["--out", "drive.toml"],
    "run": ["--t-end", "0.003", "--no-plots", "--quiet", "--out", "out"],
    "modes": ["--harmonics", "2"],
    "mesh": ["--no-plots", "--out", "out"],
    "validate": ["--short"],
    "sweep": ["--vary", f"{KEY}=0.0,0.05", "--t-end", "0.003", "--workers", "1", "--quiet"]
    + ["--no-results", "--out", "out"],
    "sensitivity": ["--key", f"{KEY}=0.0:0.05", "--feature", "kd_max", "--samples", "2", "--t-end", "0.003"]
    + ["--workers", "1", "--quiet", "--out", "out"],
    "calibrate": ["--param", f"{KEY}=0.0:0.05", "--target", "kd_max", "1.5", "0.5", "--budget", "2"]
    + ["--polish-evaluations", "0", "--t-end", "0.003", "--workers", "1", "--quiet", "--out", "out"],
    "render": ["--kinematic", "--frames", "1", "--format", "none", "--width", "32", "--height", "24"]
    + ["--quiet", "--out", "out"],
    "analyze": ["--out", "out"],
    "compare": ["--out", "out"],
}
VALIDATE_SCENE = "two-wheel"  # validate simulates each case twice (gearbody and the reference): the cheapest


# -- values ------------------------------------------------------------------------------------------

NUMBERS = [
    "0", "-0", "-1", "1", "2", "0.5", "1e-4", "1e-300", "5e-324", "-1e-300", "1e300",
    "1.7976931348623157e308", "1e309", "-1e308", "1e400", "nan", "NaN", "-nan", "inf", "-inf", "Infinity",
    "1_000", "0x10", "1,5", "10**3", "1e", "--", "-", "", " ", "abc", "１", "٣", "½", "9" * 400, "2147483648",
    "9223372036854775808", "-9223372036854775809", "3.0", "+2", " 2 ", "2\n", "1e-12", "\x00",
]  # fmt: skip
COUNTS = [
    "0", "-1", "1", "2", "3", "2.5", "2.0", "1e3", "nan", "inf", "", "abc", "10001", "2001", "2147483648",
    "9223372036854775808", "9" * 40, "-9223372036854775809", "0x2", "٣", "+3", " 2",
]  # fmt: skip
SEEDS = [*COUNTS, "4294967295", "4294967296", "18446744073709551616", "2" + "0" * 30]
TEXTS = [
    "", " ", "x", "-", "--", "kd_max", "\x00", "a\nb", "é", "\udcff", "%s%n", "{}", "[", "'", '"', "x" * 5000,
]  # fmt: skip


@dataclass(frozen=True)
class File:
    """A path made in the command's folder before it runs (``kind``: see :func:`make`)."""

    kind: str


SCENARIO_FILES = [
    "scene-copy", "crlf", "bom", "empty", "comments-only", "bad-utf8", "binary", "nul", "surrogates",
    "too-big", "at-limit", "deep-array", "deep-inline", "deep-header", "just-deep-enough", "garbage",
    "fifo", "/dev/zero", "/dev/null", "/dev/urandom", "/proc/self/status", "folder", "symlink-loop",
    "broken-symlink", "symlink", "unreadable", "socket", "missing", "empty-name", "dash", "dot",
    "newline-name", "long-name", "non-utf8-name",
]  # fmt: skip
"""Scenario-file kinds (the SCENE argument)."""
RESULT_FILES = [
    "npz-corrupt", "npz-empty", "npz-object", "npz-text", "npz-time-only", "empty-folder", "fifo",
    "/dev/zero", "folder", "symlink-loop", "missing", "empty-name", "binary",
]  # fmt: skip
"""``render --result`` kinds."""
RECORDING_FILES = [
    "rec-h5", "rec-wav", "rec-csv", "rec-csv-nan", "rec-csv-ragged", "rec-wav-empty", "run-folder", "run-npz",
    "run-instruments",
]  # fmt: skip
"""``analyze`` / ``compare`` RECORDING kinds (a logger's files, good and bad, a run, and a run folder with
its virtual instruments' instruments.mat)."""
OUT_PATHS = [
    "fresh", "nested-fresh", "existing-file", "fifo", "symlink-loop", "broken-symlink", "dir-with-junk",
    "through-file", "long-name", "newline-name", "empty-name", "dot", "symlink-to-folder", "non-utf8-name",
    "socket",
]  # fmt: skip
"""``--out`` kinds (inside the command's folder only: nothing outside the sandbox is ever written)."""


def _scene_text(scene: str) -> str:
    return scene_path(scene).read_text()


def make(kind: str, folder: Path, scene: str = "one-stage") -> str:
    """Make the path of ``kind`` in ``folder`` (the command's working directory); its text on the
    command line. System paths (``/dev/zero``, ``/proc/self/status``) are only ever read."""
    if kind.startswith("/"):
        return kind
    names = {"empty-name": "", "dash": "-", "dot": "."}
    if kind in names:
        return names[kind]
    p = folder / f"{kind}.toml"
    if kind == "scene-copy":
        p.write_text(_scene_text(scene))
    elif kind == "crlf":
        p.write_bytes(_scene_text(scene).replace("\n", "\r\n").encode())
    elif kind == "bom":
        p.write_bytes(b"\xef\xbb\xbf" + _scene_text(scene).encode())
    elif kind == "empty":
        p.write_bytes(b"")
    elif kind == "comments-only":
        p.write_text("# nothing\n" * 3)
    elif kind == "bad-utf8":
        p.write_bytes(b'[meta]\ntitle = "\xff\xfe\xc3("\n')
    elif kind in ("binary", "npz-text"):
        p.write_bytes(bytes(range(256)) * 8 if kind == "binary" else b"not a zip file\n")
    elif kind == "nul":
        text = _scene_text(scene)
        p.write_bytes(text[: len(text) // 2].encode() + b"\x00" + text[len(text) // 2 :].encode())
    elif kind == "surrogates":
        p.write_bytes('[meta]\ntitle = "\ud800"\n'.encode("utf-8", "surrogatepass"))
    elif kind == "too-big":
        p.write_text(_scene_text(scene) + "#" * (MAX_SCENARIO_BYTES + 1) + "\n")
    elif kind == "at-limit":
        text = _scene_text(scene) + "\n#"
        p.write_text(text + "x" * (MAX_SCENARIO_BYTES - len(text.encode()) - 1) + "\n")
        assert p.stat().st_size == MAX_SCENARIO_BYTES
    elif kind == "deep-array":
        p.write_text("a = " + "[" * 600 + "]" * 600 + "\n")
    elif kind == "deep-inline":
        p.write_text("a = " + "{b=" * 600 + "1" + "}" * 600 + "\n")
    elif kind == "deep-header":
        p.write_text("[" + ".".join(["a"] * 900) + "]\n")
    elif kind == "just-deep-enough":  # as deep as allowed, in a key no scenario has
        p.write_text("x = " + "[" * (MAX_NESTING - 1) + "]" * (MAX_NESTING - 1) + "\n" + _scene_text(scene))
    elif kind == "garbage":
        p.write_text("= = [[[ ]\n{{{\n'''\n")
    elif kind == "fifo":
        os.mkfifo(p)
    elif kind in ("folder", "empty-folder"):
        p.mkdir()
    elif kind == "symlink-loop":
        (folder / "loop-b.toml").symlink_to(p.name)
        p.symlink_to("loop-b.toml")
    elif kind == "broken-symlink":
        p.symlink_to("nowhere.toml")
    elif kind == "symlink":
        (folder / "target.toml").write_text(_scene_text(scene))
        p.symlink_to("target.toml")
    elif kind == "unreadable":
        p.write_text(_scene_text(scene))
        p.chmod(0)  # (root reads it all the same)
    elif kind == "socket":
        p = folder / "s.sock"  # AF_UNIX paths are short
        s = socket.socket(socket.AF_UNIX)
        s.bind(str(p))
        s.close()
    elif kind == "missing":
        pass
    elif kind == "newline-name":
        p = folder / "a\nb.toml"
        p.write_text(_scene_text(scene))
    elif kind == "long-name":
        p = folder / ("x" * 300 + ".toml")  # longer than a file name may be
    elif kind == "non-utf8-name":
        p = folder / "\udcff.toml"
        p.write_text(_scene_text(scene))
    elif kind.startswith(("rec-", "run-")):
        return make_recording(kind, folder)
    elif kind.startswith("npz-"):
        import numpy as np

        p = folder / f"{kind}.npz"
        if kind == "npz-corrupt":
            np.savez(p, time=np.linspace(0, 1, 11))
            p.write_bytes(p.read_bytes()[:-40])
        elif kind == "npz-empty":
            np.savez(p)
        elif kind == "npz-object":
            np.savez(p, time=np.array([{"a": 1}], dtype=object))
        elif kind == "npz-time-only":
            np.savez(p, time=np.zeros(0), meta_json=np.array("{}"))
    else:
        raise ValueError(kind)
    return os.path.relpath(p, folder) if kind != "long-name" else str(p.name)


_RUN: list[Path] = []


def _run_folder() -> Path:
    """A short run of two-wheel (made once per process, copied where a test needs it)."""
    if not _RUN:
        import tempfile

        import gearbody as gb

        where = Path(tempfile.mkdtemp(prefix="fuzz-run-"))
        gb.simulate(gb.load_scenario("two-wheel", ["operation.t_end_s=0.3"])).save_npz(where / "result.npz")
        _RUN.append(where)
    return _RUN[0]


def make_recording(kind: str, folder: Path) -> str:
    """A recording of ``kind`` in ``folder``: a logger's file (HDF5, WAV, CSV; good, with NaN, ragged,
    empty) or a run (its folder or result.npz); its text on the command line."""
    import numpy as np

    fs = 5000.0
    t = np.arange(int(2 * fs)) / fs
    acc = np.sin(2 * np.pi * 29 * 17.3 * t) + 0.1 * np.sin(2 * np.pi * 17.3 * t)
    tacho = (np.mod(17.3 * t, 1.0) < 0.05).astype(float)
    if kind == "rec-h5":
        from gearbody.recording import Channel, Recording
        from gearbody.recording.files import write_recording

        rec = Recording(fs, [Channel("acc", acc, "m/s^2"), Channel("tacho", tacho, "V")])
        return write_recording(rec, folder / "rec.h5").name
    if kind in ("rec-wav", "rec-wav-empty"):
        from scipy.io import wavfile

        data = np.stack([acc / 2, tacho], axis=1)[: 0 if kind == "rec-wav-empty" else None]
        wavfile.write(folder / "rec.wav", int(fs), np.round(data * 32767).astype(np.int16))
        return "rec.wav"
    if kind.startswith("rec-csv"):
        rows = [f"{a!r},{b!r},{c!r}" for a, b, c in zip(t, acc, tacho, strict=True)]
        if kind == "rec-csv-nan":
            rows[100] = f"{t[100]!r},nan,0.0"
        elif kind == "rec-csv-ragged":
            rows[100] = f"{t[100]!r},1.0"
        (folder / "rec.csv").write_text("time_s,acc [m/s^2],tacho [V]\n" + "\n".join(rows) + "\n")
        return "rec.csv"
    run = next(folder / f"run{k}" for k in range(100) if not (folder / f"run{k}").exists())
    shutil.copytree(_run_folder(), run)
    if kind == "run-instruments":  # the run's mesh force seen by an accelerometer behind a 2 kHz mode
        import gearbody as gb
        from gearbody.model import scenario_to_dict

        result = gb.Result.load_npz(run / "result.npz")
        mode = {"frequency_hz": 2000.0, "damping_ratio": 0.05, "participation": {"mesh_force_N": 0.02}}
        table = {"accelerometers": [{"name": "acc", "noise_rms_g": 0.01, "modes": [mode]}]}
        scenario = gb.load_scenario({**result.meta["scenario"], "instruments": table})
        result.meta["scenario"] = scenario_to_dict(scenario)
        gb.write_recording(gb.virtual_recording(result), run / "instruments.mat")
    return run.name if kind in ("run-folder", "run-instruments") else os.path.join(run.name, "result.npz")


def make_out(kind: str, folder: Path) -> str:
    """An output path of ``kind`` in ``folder``."""
    if kind in ("fresh", "nested-fresh", "long-name", "newline-name", "non-utf8-name"):
        return {
            "fresh": "new-out",
            "nested-fresh": "a/b/c/new-out",
            "long-name": "y" * 300,
            "newline-name": "out\nput",
            "non-utf8-name": "\udcfe-out",
        }[kind]
    if kind == "existing-file":
        (folder / "a-file").write_text("x")
        return "a-file"
    if kind == "through-file":
        (folder / "a-file").write_text("x")
        return "a-file/sub"
    if kind == "dir-with-junk":
        (folder / "junk").mkdir()
        (folder / "junk" / "notes.txt").write_text("mine")
        return "junk"
    if kind == "symlink-to-folder":
        (folder / "real").mkdir()
        (folder / "link").symlink_to("real")
        return "link"
    return make(kind, folder)


# -- strategies --------------------------------------------------------------------------------------


def _numbers_of(scene: str) -> list[str]:
    return sorted(leaves(scenario_to_dict(load_scenario(scene))))


def set_values():
    """``--set KEY=VALUE``: a numeric key of some scene (or an odd key) at an extreme value."""
    keys = sorted({k for s in SCENES for k in _numbers_of(s)})
    return st.builds(
        lambda k, v: f"{k}={v}",
        st.one_of(st.sampled_from(keys), st.sampled_from(["", "=", "a..b", ".", "design", "x" * 300])),
        st.sampled_from([*NUMBERS, '"steady"', "[]", "{}", "[1,[2]]", "true", "'''", "1979-05-27"]),
    )


def _key():
    return st.one_of(st.just(KEY), st.sampled_from(["production.error_mode.e_um", "nope.key", "", "="]))


def vary_values():
    n = st.sampled_from(NUMBERS)
    c = st.sampled_from(COUNTS)
    return st.one_of(
        st.builds(lambda k, a, b, m: f"{k}={a}:{b}:{m}", _key(), n, n, c),
        st.builds(lambda k, a, b: f"{k}={a},{b}", _key(), n, n),
        st.builds(lambda k, t: f"{k}={t}", _key(), st.sampled_from(TEXTS)),
    )


def random_values():
    n = st.sampled_from(NUMBERS)
    return st.builds(
        lambda k, kind, a, b: f"{k}={kind}({a},{b})",
        _key(),
        st.sampled_from(["uniform", "normal", "choice", "gamma", ""]),
        n,
        n,
    )


def range_values(log: bool = False):
    n = st.sampled_from(NUMBERS)
    tail = st.sampled_from([":log", "", ":lin", ":log:log"]) if log else st.just("")
    return st.builds(lambda k, a, b, t: f"{k}={a}:{b}{t}", _key(), n, n, tail)


def feature_values():
    from gearbody.analysis.features import FEATURES

    names = sorted(FEATURES)
    options = sorted({o for opts in FEATURES.values() for o in opts})
    option = st.builds(
        lambda o, v: f"{o}={v}", st.sampled_from([*options, "bogus"]), st.sampled_from([*NUMBERS, "kd"])
    )
    return st.one_of(
        st.sampled_from([*names, "", "nope", ":", "kd_max:", "kd_max:,,"]),
        st.builds(
            lambda f, os_: f + ":" + ",".join(os_), st.sampled_from(names), st.lists(option, max_size=2)
        ),
    )


def scheduler_values():
    return st.sampled_from(["", "not a url", "tcp://", "tcp://127.0.0.1", "tcp://127.0.0.1:0", "http://x:1"])


def paths(kinds: list[str]):
    return st.sampled_from(kinds).map(File)


def recording_options() -> dict:
    """The options of analyze and compare that say how to read a recording."""
    n, c = st.sampled_from(NUMBERS), st.sampled_from(COUNTS)
    return {
        "--scene": st.one_of(st.sampled_from(SCENES), st.sampled_from(TEXTS), paths(SCENARIO_FILES)),
        "--channel": st.sampled_from([*TEXTS, "acc", "tacho", "ch1", "pinion_accel_rad_s2"]),
        "--tacho": st.sampled_from([*TEXTS, "tacho", "ch2", "acc"]),
        "--pulses-per-rev": c,
        "--tacho-shaft": st.sampled_from(["input", "output", "pinion", "wheel", "motor", "", "x", "wheel_9"]),
        "--unit": st.sampled_from(["acc=g", "acc=furlong", "=", "acc", "ch1=g", "tacho=rad", "x=m"]),
        "--calibration": st.sampled_from([*NUMBERS, "1,2", "1,,2", "1,2,3"]),
        "--sample-rate": n,
        "--input-speed": n,
        "--start": n,
        "--end": n,
        "--no-envelope": st.none(),
        "--prewhiten": st.none(),
    }


@dataclass(frozen=True)
class Option:
    """An option of a command and the values drawn for it (strings, a File, or a list: nargs > 1)."""

    name: str
    values: st.SearchStrategy


def options(command: str) -> list[Option]:
    n, c = st.sampled_from(NUMBERS), st.sampled_from(COUNTS)
    common = {
        "--set": set_values(),
        "--t-end": n,
        "--out": paths(OUT_PATHS),
        "--overwrite": st.none(),
        "--quiet": st.none(),
        "--workers": st.sampled_from([*COUNTS, "256", "257"]),
        "--scheduler": scheduler_values(),
        "--max-wall-minutes": n,
        "--bogus-option": st.sampled_from(["", "1"]),
        "-h": st.none(),
    }
    own = {
        "list": {},
        "info": {},
        "new": {"--out": st.one_of(paths(OUT_PATHS), st.just("-")), "--force": st.none()},
        "run": {"--no-plots": st.none(), "--report": st.none()},
        "modes": {"--harmonics": c},
        "mesh": {"--stage": c, "--load": n, "--no-plots": st.none()},
        "validate": {"--tolerance": n, "--no-cache": st.none()},
        "sweep": {
            "--vary": vary_values(),
            "--random": random_values(),
            "--samples": c,
            "--max-cases": c,
            "--study-seed": st.sampled_from(SEEDS),
            "--seeds": c,
            "--plot-value": st.sampled_from([*TEXTS, "kd_max", "wall_time_s"]),
            "--plot-key": st.sampled_from([*TEXTS, KEY]),
            "--no-results": st.none(),
            "--retry-failed": st.none(),
        },
        "sensitivity": {
            "--key": range_values(),
            "--feature": feature_values(),
            "--method": st.sampled_from(["morris", "sobol", "", "MORRIS"]),
            "--samples": c,
            "--seed": st.sampled_from(SEEDS),
            "--levels": c,
            "--no-second-order": st.none(),
            "--force": st.none(),
            "--retry-failed": st.none(),
            "--exclude-failed": st.none(),
        },
        "calibrate": {
            "--param": range_values(log=True),
            "--start": st.builds(lambda k, v: f"{k}={v}", _key(), n),
            "--target": st.tuples(feature_values(), n, n).map(list),
            "--case": st.tuples(st.sampled_from(["c", "", "-", "kd_max"]), set_values()).map(list),
            "--budget": c,
            "--batch": c,
            "--polish-evaluations": c,
            "--seed": st.sampled_from(SEEDS),
            "--force": st.none(),
        },
        "render": {
            "--result": paths(RESULT_FILES),
            "--kinematic": st.none(),
            "--frames": c,
            "--start": n,
            "--end": n,
            "--format": st.sampled_from(["gif", "mp4", "none", "", "png"]),
            "--fps": n,
            "--width": st.sampled_from(["0", "-1", "15", "16", "17", "8193", "1e3", "nan", "", "10**9"]),
            "--height": st.sampled_from(["0", "-1", "15", "16", "17", "8193", "1e3", "nan", "", "10**9"]),
            "--view": st.sampled_from(["iso", "front", "back", "side", "top", "", "ISO", "x"]),
            "--azimuth": n,
            "--elevation": n,
            "--zoom": n,
            "--frame": st.sampled_from(["drive", "gears", "mesh", "", "x"]),
            "--housing": st.none(),
            "--no-housing": st.none(),
            "--lateral-scale": n,
            "--lateral-static": st.none(),
            "--interactive": st.none(),  # (the runner has no display: refused before anything runs)
            "--background": st.sampled_from(
                ["1,1,1", "0,0,0", "2,0,0", "nan,0,0", "1,1", "1,1,1,1", "", "a,b,c"]
            ),
        },
        "analyze": {**recording_options(), "--run-signals": st.none()},
        "compare": {**recording_options(), "--run-channel": st.sampled_from([*TEXTS, "pinion_accel_rad_s2"])},
    }[command]
    names = {**common, **own}
    if command == "validate":  # the cheap cases only: --short stays, the one scene runs
        names = {"--tolerance": own["--tolerance"], "--bogus-option": common["--bogus-option"]}
    if command in ("list", "modes"):
        names = {k: v for k, v in names.items() if k not in ("--out", "--overwrite", "--quiet", "--t-end")}
    if command in ("new", "modes", "mesh"):
        names = {
            k: v for k, v in names.items() if k not in ("--t-end", "--quiet", "--workers", "--scheduler")
        }
    if command not in ("sweep", "sensitivity", "calibrate"):
        names.pop("--workers", None)
        names.pop("--scheduler", None)
    if command == "list":
        names.pop("--set", None)
    return [Option(k, v) for k, v in names.items()]


@st.composite
def command_lines(draw, command: str) -> list:
    """A command line of ``command``: its baseline with 1 option (mostly; 0-3) drawn to an extreme value,
    on a shipped scene (one draw in eight: an odd scene file); Files are made when it runs. One extreme
    at a time reaches past the first check; two or three try them together."""
    tokens: list = [command]
    odd = draw(st.integers(0, 7)) == 0
    if command == "validate":
        tokens.append(draw(paths(SCENARIO_FILES)) if odd else VALIDATE_SCENE)
    elif command == "analyze":  # a recording (odd: any odd file) on a scene
        tokens += [
            draw(paths(SCENARIO_FILES if odd else RECORDING_FILES)),
            "--scene",
            draw(st.sampled_from(SCENES)),
        ]
    elif command == "compare":  # a run (odd: any odd file or recording) beside a recording
        first = paths([*SCENARIO_FILES, *RECORDING_FILES]) if odd else st.just(File("run-folder"))
        tokens += [draw(first), draw(paths(RECORDING_FILES))]
    elif command not in ("list", "info"):
        tokens.append(draw(paths(SCENARIO_FILES)) if odd else draw(st.sampled_from(SCENES)))
    tokens += BASE[command] + _wall(command)
    if command in ("run", "new", "mesh", "render") and draw(st.integers(0, 3)) == 0:
        tokens = _without(tokens, "--out")  # the default folder runs/SCENE/... (in the command's folder)
    how_many = draw(st.sampled_from([1, 1, 1, 1, 1, 1, 2, 2, 3, 0]))
    for _ in range(how_many if options(command) else 0):
        option = draw(st.sampled_from(options(command)))
        value = draw(option.values)
        if option.name == "-h" and draw(st.integers(0, 3)):
            continue  # help is one answer: seldom
        tokens.append(option.name)
        if value is not None:
            tokens += value if isinstance(value, list) else [value]
    if command in ("list", "info") and draw(st.booleans()):
        tokens.append(draw(st.sampled_from(["one-stage", "", "--set", "x=1"])))
    return tokens


def _without(tokens: list, option: str) -> list:
    i = tokens.index(option)
    return tokens[:i] + tokens[i + 2 :]


def materialise(tokens: list, folder: Path, scene: str) -> tuple[list[str], str]:
    """The command line with its Files made in ``folder``; and how they were made (for reproducing)."""
    argv, made = [], []
    for i, t in enumerate(tokens):
        if isinstance(t, File):
            previous = tokens[i - 1] if i else ""
            text = make_out(t.kind, folder) if previous == "--out" else make(t.kind, folder, scene)
            made.append(f"{text!r}: {t.kind}")
            argv.append(text)
        else:
            argv.append(t)
    return argv, "; ".join(made)


# -- the tests ---------------------------------------------------------------------------------------


runner = runner_fixture("fuzz-cli", REPORT)


def check(runner: CommandRunner, tokens: list, kind: str, expected: set[str] = GOOD) -> None:
    """Run the command line; assert its outcome is one of ``expected``, with what reproduces it if not."""
    folder = runner.folder()
    scene = next((t for t in tokens[1:2] if isinstance(t, str) and t in SCENES), "one-stage")
    scene = VALIDATE_SCENE if tokens[0] == "validate" else scene
    argv, setup = materialise(tokens, folder, scene)
    before = set(os.listdir(folder))
    outcome = runner.run(argv, folder)
    what = outcome.kind()
    REPORT.add(kind, what)
    outcome.log(setup)
    assert what in expected, outcome.describe(setup)
    if outcome.code == 2 and argv[0] not in ("new",):
        made = set(os.listdir(folder)) - before - {"stdout.txt", "stderr.txt"}
        assert not made, f"refused, but made {sorted(made)}\n" + outcome.describe(setup)
    leftovers = [p for p in folder.rglob(".*.tmp*") if p.is_file()]
    assert not leftovers, f"temporary files left: {leftovers}\n" + outcome.describe(setup)
    shutil.rmtree(folder, ignore_errors=True)  # passed: nothing to keep (a failure keeps its folder)


COMMAND_NAMES = [
    "list" if c.__name__.endswith("listing") else c.__name__.rsplit(".", 1)[-1] for c in COMMANDS
]
EXAMPLES = {
    "list": 4, "info": 2, "new": 10, "run": 14, "modes": 10, "mesh": 10, "validate": 2, "sweep": 8,
    "sensitivity": 6, "calibrate": 6, "render": 10, "analyze": 10, "compare": 6,
}  # fmt: skip


def test_every_command_is_fuzzed():
    assert set(COMMAND_NAMES) == set(BASE) == set(EXAMPLES)


@pytest.mark.parametrize("command", COMMAND_NAMES)
def test_command_lines_with_extreme_values_end_cleanly(runner, command):
    @fuzz_settings(EXAMPLES[command], shrink=False)
    @given(command_lines(command))
    def fuzz(tokens):
        check(runner, tokens, command)

    fuzz()


VALID_FILES = {
    "scene-copy", "crlf", "bom", "symlink", "unreadable", "at-limit", "newline-name", "non-utf8-name",
}  # fmt: skip


@pytest.mark.parametrize("kind", SCENARIO_FILES)
def test_every_scenario_file_kind_on_every_command_ends_cleanly(runner, kind):
    """Each odd scenario file given to each command that reads one: refused in one line (exit 2), or,
    where it holds a valid scenario, run (``gearbody run`` only: the others read it the same way)."""
    if kind in VALID_FILES:
        check(runner, ["run", File(kind), *BASE["run"], *_wall("run")], f"file {kind}", {"ok"})
        return
    for command in [c for c in COMMAND_NAMES if c not in ("list", "info")]:  # the ones that read a scenario
        where = {"analyze": ["--scene", File(kind)], "compare": ["--scene", File(kind)]}.get(command, [])
        first = {"analyze": [File("rec-h5")], "compare": [File("run-folder"), File("rec-h5")]}
        tokens = [command, *first.get(command, [File(kind)]), *where, *BASE[command], *_wall(command)]
        check(runner, tokens, f"file {kind}", {"refused"})
        if command in first:  # the odd file as the recording (compare: as the run) too
            tokens = [
                command,
                File(kind),
                *(["--scene", "one-stage"] if command == "analyze" else [File("rec-h5")]),
            ]
            check(runner, [*tokens, *BASE[command]], f"recording {kind}", {"refused"})


@pytest.mark.parametrize("kind", OUT_PATHS)
def test_every_output_path_kind_on_every_writing_command_ends_cleanly(runner, kind):
    """Each odd --out given to each command that writes one: written, or refused in one line (at the
    default scale four of them: CI's time)."""
    writers = ("new", "run", "mesh", "sweep", "sensitivity", "calibrate", "render")
    for command in writers if SCALE >= 2 else ("new", "run", "sweep", "render"):
        tokens = [
            command,
            "two-wheel",
            *_without(BASE[command], "--out"),
            *_wall(command),
            "--out",
            File(kind),
        ]
        # new writes one file at once: a name the system refuses is the writer's one line (exit 1)
        check(
            runner,
            tokens,
            f"out {kind}",
            {"ok", "refused", "failed"} if command == "new" else {"ok", "refused"},
        )


@pytest.mark.parametrize("kind", RESULT_FILES)
def test_every_result_file_kind_in_render_is_refused_in_one_line(runner, kind):
    tokens = [
        "render",
        "one-stage",
        *[t for t in BASE["render"] if t != "--kinematic"],
        "--result",
        File(kind),
    ]
    check(runner, tokens, f"result {kind}", {"refused"})


def test_every_scene_loads_in_the_baselines():
    """The baselines are valid on every shipped scene (what the extremes start from)."""
    for scene in SCENES:
        load_scenario(scene, ["operation.t_end_s=0.003", f"{KEY}=0.05"])
