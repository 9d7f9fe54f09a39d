"""The legacy (one-mesh) shape of a scenario dict, for the reference's self-checks that address a
one-stage drive by ``design.pinion``, ``production.error_mode``, ``condition.pitted_teeth``, ... The
reference reads both shapes (tests/test_reference_canonical.py proves them equal); gearbody writes the
canonical one. Plain dict work, no gearbody import."""

from __future__ import annotations

import copy


def legacy(sc: dict) -> dict:
    """``sc`` (canonical, shorthand with meta.topology, or already legacy) in the legacy shape:
    ``meta.scene`` in {"muller", "two-wheel", "one-stage", "train"}; a one-stage drive by its
    single-stage keys, a train of two or more stages by its stages."""
    sc = copy.deepcopy(sc)
    meta, d = sc["meta"], sc["design"]
    if "scene" in meta:
        return sc
    topology = meta.pop("topology")
    stages = d.get("stages")
    if topology == "train" and stages is not None and len(stages) > 1:
        meta["scene"] = "train"
        return sc
    meta["scene"] = "one-stage" if topology == "train" else topology
    if stages is None:  # shorthand already
        sc.setdefault("production", {}).setdefault("error_mode", {"a": 0.5, "e_um": 0.0, "r": 0.0})
        sc["production"].setdefault("eccentricity", [])
        sc.setdefault("condition", {}).setdefault("pitted_teeth", [])
        sc["condition"].setdefault("damaged_teeth", [])
        return sc
    (st,) = stages
    shafts = d.get("shafts", [])
    sc["design"] = {"motor": d["motor"], "machine": d["machine"]}
    sc["design"].update(pinion=st["pinion"], wheel=st["wheel"], mesh=st["mesh"])
    if topology == "train":
        sc["design"]["coupling"], sc["design"]["output_shaft"] = shafts
    sc["production"] = {"error_mode": st["error_mode"], "eccentricity": st.get("eccentricity", [])}
    sc["condition"] = {
        "friction_coefficient": sc.get("condition", {}).get("friction_coefficient", 0.0),
        "damaged_teeth": st.get("damaged_teeth", []),
        "pitted_teeth": st.get("pitted_teeth", []),
    }
    return sc
