"""Result of a simulation: named time signals on a fixed output grid, plus metadata.

Signals carry their unit in their name (``mesh_force_N``, ``pinion_speed_rad_s``). The metadata holds
the resolved scenario, the seed, gearbody and Exudyn versions, the output rate and solver statistics,
so a saved result says where it came from.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np


@dataclass
class Result:
    time_s: np.ndarray
    signals: dict[str, np.ndarray]
    meta: dict[str, Any] = field(default_factory=dict)

    def __getitem__(self, name: str) -> np.ndarray:
        if name == "time_s":
            return self.time_s
        try:
            return self.signals[name]
        except KeyError:
            raise KeyError(f"no signal {name!r}; signals: {', '.join(sorted(self.signals))}") from None

    def __contains__(self, name: str) -> bool:
        return name == "time_s" or name in self.signals

    @property
    def names(self) -> list[str]:
        return ["time_s", *self.signals]

    # Short aliases the paper's reader expects.
    @property
    def time(self) -> np.ndarray:
        return self.time_s

    @property
    def mesh_force(self) -> np.ndarray:
        return self.signals["mesh_force_N"]

    @property
    def kd(self) -> np.ndarray:
        return self.signals["kd"]

    @property
    def sample_rate_hz(self) -> float:
        return float(self.meta["output_rate_hz"])

    def save_npz(self, path: str | Path) -> Path:
        """Named arrays (``time`` and ``time_s``, every signal) plus the metadata as JSON in ``meta_json``."""
        path = Path(path)
        arrays = {"time": self.time_s, "time_s": self.time_s, **self.signals}
        np.savez_compressed(path, **arrays, meta_json=np.array(json.dumps(self.meta, default=_jsonable)))
        return path

    @classmethod
    def load_npz(cls, path: str | Path) -> Result:
        with np.load(path, allow_pickle=False) as data:
            meta = json.loads(str(data["meta_json"])) if "meta_json" in data else {}
            signals = {k: data[k] for k in data.files if k not in ("time", "time_s", "meta_json")}
            return cls(time_s=data["time_s"], signals=signals, meta=meta)


def _jsonable(obj: Any) -> Any:
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, Path):
        return str(obj)
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")
