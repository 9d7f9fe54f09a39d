"""A run beside a recording: the same analysis of both (one drive, one catalogue of lines), their
features side by side with the ratio recording / run, and their order spectra on one axis."""

from __future__ import annotations

import math
from dataclasses import dataclass

from .analyze import ChannelDiagnosis, Diagnosis

__all__ = ["Comparison", "compare_diagnoses"]


@dataclass
class Comparison:
    """Features of channel ``run_channel`` of the run and ``recording_channel`` of the recording."""

    run: Diagnosis
    recording: Diagnosis
    run_channel: str
    recording_channel: str
    rows: list[dict]
    """One per feature both have: ``feature``, ``run``, ``recording``, ``ratio`` (recording / run)."""

    @property
    def run_side(self) -> ChannelDiagnosis:
        return self.run.channels[self.run_channel]

    @property
    def recording_side(self) -> ChannelDiagnosis:
        return self.recording.channels[self.recording_channel]

    def as_dict(self) -> dict:
        return {
            "run_channel": self.run_channel,
            "recording_channel": self.recording_channel,
            "run_input_speed_hz": self.run.mean_input_hz,
            "recording_input_speed_hz": self.recording.mean_input_hz,
            "units": [self.run_side.unit, self.recording_side.unit],
            "features": self.rows,
        }


def compare_diagnoses(
    run: Diagnosis, recording: Diagnosis, run_channel: str, recording_channel: str
) -> Comparison:
    """The features of both, row by row (speed first), with the ratio recording / run (nan where the run's
    value is 0)."""
    a = {"input_speed_hz": run.mean_input_hz, **run.channels[run_channel].features()}
    b = {"input_speed_hz": recording.mean_input_hz, **recording.channels[recording_channel].features()}
    rows = []
    for key in a:
        if key in b:
            ratio = b[key] / a[key] if a[key] != 0 and math.isfinite(a[key]) else math.nan
            rows.append({"feature": key, "run": a[key], "recording": b[key], "ratio": ratio})
    return Comparison(run, recording, run_channel, recording_channel, rows)
