"""Measured and simulated signals in one container: :class:`Recording` (channels with unit, sensitivity,
location and direction on one sample rate, a :class:`Tacho`, operating metadata), its readers and
writers (:mod:`gearbody.recording.files`), a simulated run's export (``Result.to_recording``) and its
virtual instruments (housing accelerometers behind housing modes, a tacho: :mod:`.instruments`).
"""

from .channel import QUANTITIES, UNIT_SCALE, Channel, quantity_of_unit, to_si_unit
from .container import Recording
from .from_run import recording_from_run
from .instruments import Accelerometer, HousingMode, housing_acceleration, virtual_instruments
from .tacho import Tacho

__all__ = [
    "Accelerometer",
    "HousingMode",
    "housing_acceleration",
    "virtual_instruments",
    "QUANTITIES",
    "UNIT_SCALE",
    "Channel",
    "Recording",
    "Tacho",
    "quantity_of_unit",
    "recording_from_run",
    "to_si_unit",
]
