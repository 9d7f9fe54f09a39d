"""``gearbody new SCENE``: a newcomer's starting scenario. Written from any shipped scene it loads to the
same resolved scenario (named after the file), every key carries a comment with its meaning, unit,
range and origin, ``gearbody run`` takes it unchanged, and a value gearbody resolves follows edits of
the keys it comes from."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest

from gearbody.cli import main
from gearbody.model import load_scenario
from gearbody.model.scenes import list_scenes
from gearbody.model.template import UNITS, unit_of

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

KEY = re.compile(r"^(#\s)?([a-z_][A-Za-z0-9_]*) = ")


def _new(tmp_path: Path, scene: str, *extra: str, name: str = "my-drive.toml") -> Path:
    out = tmp_path / name
    assert main(["new", scene, *extra, "--out", str(out)]) == 0
    return out


@pytest.mark.parametrize("scene", list_scenes())
def test_the_written_file_loads_to_the_scenes_resolved_scenario(scene, tmp_path, capsys):
    out = _new(tmp_path, scene)
    assert f"wrote {out}" in capsys.readouterr().out
    written, shipped = load_scenario(out), load_scenario(scene)
    assert written.meta.name == "my-drive"  # named after its file, as any scenario file
    assert written == shipped.replace(meta=shipped.meta.replace(name="my-drive"))


@pytest.mark.parametrize(
    "scene", ["one-stage", "two-stage-geometry", "planetary-conveyor", "lateral-8dof-ball"]
)
def test_every_key_has_a_comment_with_its_unit_and_where_its_value_comes_from(scene, tmp_path):
    lines = _new(tmp_path, scene).read_text().splitlines()
    keys = 0
    for at, line in enumerate(lines):
        m = KEY.match(line)
        if not m or line.startswith("#   "):
            continue
        commented, key = m.groups()
        note = []  # the comment lines right above the key
        k = at - 1
        while k >= 0 and lines[k].startswith("#") and not KEY.match(lines[k]):
            note.insert(0, lines[k].lstrip("# "))
            k -= 1
        text = " ".join(note)
        assert note, f"{key} (line {at + 1}) has no comment"
        if unit_of(key):
            assert f"[{unit_of(key)}]" in text, (key, text)
        if not commented:
            assert re.search(r"set by the scene|gearbody's default|set by --set", text), (key, text)
        else:
            assert "uncomment to fix it" in text, (key, text)
            assert key == "name" or "resolved by gearbody" in text, (key, text)
        keys += 1
    assert keys > 40
    data = tomllib.loads("\n".join(lines))  # the file is TOML as a whole (tables, arrays of tables)
    assert "stages" in data["design"]


def test_units_come_from_the_end_of_a_key():
    assert unit_of("inertia_kg_m2") == "kg m^2" and unit_of("stiffness_Nm_per_rad") == "N m/rad"
    assert unit_of("damping_Nms_per_rad") == "N m s/rad" and unit_of("mass_kg") == "kg"
    assert unit_of("t_end_s") == "s" and unit_of("teeth") == "" and unit_of("backlash_um") == "um"
    assert len({s for s, _ in UNITS}) == len(UNITS)


def test_gearbody_run_takes_the_file_unchanged(tmp_path, capsys):
    out = _new(tmp_path, "one-stage")
    run = tmp_path / "runs" / "mine"
    assert main(["run", str(out), "--t-end", "0.02", "--no-plots", "--quiet", "--out", str(run)]) == 0
    assert (run / "result.npz").exists() and (run / "scenario.toml").exists()
    assert load_scenario(run / "scenario.toml").meta.name == "my-drive"


def test_a_resolved_value_follows_an_edit_of_the_keys_it_comes_from(tmp_path):
    """one-stage-geometry's base radii and contact ratio come from its geometry: the file lists them as
    comments, so a changed module resolves them anew instead of being refused as a contradiction."""
    out = _new(tmp_path, "one-stage-geometry")
    text = out.read_text()
    assert re.search(r"^# base_radius_m = 0\.0681277", text, re.M)
    assert re.search(r"^module_mm = 5\.0$", text, re.M)
    out.write_text(re.sub(r"^module_mm = 5\.0$", "module_mm = 4.0", text, flags=re.M))
    edited = load_scenario(out)
    assert edited.stages[0].pinion.base_radius_m == pytest.approx(0.0681277 * 4 / 5, rel=1e-6)


def test_set_overrides_are_written_and_marked(tmp_path):
    out = _new(tmp_path, "one-stage", "--set", "production.error_mode.e_um=15")
    text = out.read_text()
    assert re.search(r"set by --set\n(#.*\n)*e_um = 15", text)
    assert "`gearbody new one-stage --set production.error_mode.e_um=15`" in text
    assert load_scenario(out).stages[0].error_mode.e_um == 15.0


def test_an_existing_file_is_kept_unless_overwritten_and_dash_prints(tmp_path, capsys):
    out = _new(tmp_path, "two-wheel")
    out.write_text("mine")
    assert main(["new", "two-wheel", "--out", str(out)]) == 2
    assert f"--out {out}: exists already; give --overwrite" in capsys.readouterr().err
    assert out.read_text() == "mine"
    assert main(["new", "two-wheel", "--out", str(out), "--overwrite"]) == 0 and out.read_text() != "mine"
    out.write_text("mine")  # --force: the earlier name of --overwrite, still understood
    assert main(["new", "two-wheel", "--out", str(out), "--force"]) == 0 and out.read_text() != "mine"
    capsys.readouterr()
    assert main(["new", "two-wheel", "--out", "-"]) == 0
    assert capsys.readouterr().out == out.read_text().replace("my-drive.toml", "this file")
    assert main(["new", "two-wheel", "--out", str(tmp_path)]) == 2
    assert "is a folder, not a file" in capsys.readouterr().err


def test_bad_input_is_one_line_naming_it(tmp_path, capsys):
    assert main(["new", "no-such-scene", "--out", str(tmp_path / "x.toml")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "no-such-scene" in err
    assert (
        main(["new", "one-stage", "--set", "design.pinion.teeth=3", "--out", str(tmp_path / "y.toml")]) == 2
    )
    assert "design.pinion.teeth = 3: must be >= 6" in capsys.readouterr().err
    assert not (tmp_path / "y.toml").exists()


def test_the_default_file_is_named_after_the_scene_in_the_current_folder(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["new", "muller"]) == 0
    assert load_scenario(tmp_path / "muller.toml").meta.name == "muller"


@pytest.mark.parametrize("where", ["file", "folder"])
def test_a_name_too_long_for_the_file_system_is_refused_naming_its_length(tmp_path, capsys, where):
    """300 bytes, beyond NAME_MAX (255 on common file systems): refused as input (exit 2) like run's
    --out, not a write failure (exit 1) whose message was only the system's 'File name too long'."""
    long = "y" * 300
    out = tmp_path / long if where == "file" else tmp_path / long / "drive.toml"
    assert main(["new", "two-wheel", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "300 bytes" in err and "give a shorter name" in err
    assert list(tmp_path.iterdir()) == []
