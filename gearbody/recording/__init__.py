"""Measured and simulated signals in one container: :class:`Recording` (channels with unit, sensitivity,
location and direction on one sample rate, a :class:`Tacho`, operating metadata), its readers and
writers (:mod:`gearbody.recording.files`), and a simulated run's export (``Result.to_recording``).
"""

from .channel import QUANTITIES, UNIT_SCALE, Channel, quantity_of_unit, to_si_unit
from .container import Recording
from .from_run import recording_from_run
from .tacho import Tacho

__all__ = [
    "QUANTITIES",
    "UNIT_SCALE",
    "Channel",
    "Recording",
    "Tacho",
    "quantity_of_unit",
    "recording_from_run",
    "to_si_unit",
]
