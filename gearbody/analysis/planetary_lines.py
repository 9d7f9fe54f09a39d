"""Kinematic lines of a planetary stage as a ring-fixed sensor sees them: carrier orders, planet pass,
mesh harmonics with their carrier sidebands, and the sun, planet and ring tooth-fault frequencies.

A stage is its tooth numbers, its number of planets and the four member speeds,
:class:`PlanetarySources` (the speeds are inputs, checked against the Willis equation, not computed
here). :func:`planetary_lines` turns it into a catalogue of labelled lines, :class:`PlanetaryLine`, a
:class:`~gearbody.analysis.kinematics.KinematicLine` that :func:`~gearbody.analysis.peaks.label_peaks`
and :func:`~gearbody.analysis.peak_report.peaks_table` accept as they are. Engine-free.

Formulas (f_c, f_s, f_r, f_p: carrier, sun, ring and planet speeds, signed, absolute [Hz]; the sensor
turns with the ring, so with the usual fixed ring every line is an absolute frequency):

- carrier as the sensor sees it: f_c' = |f_c - f_r|; sun: |f_s - f_r|
- mesh frequency (every sun-planet and ring-planet mesh): f_m = Z_r |f_r - f_c| = Z_s |f_s - f_c|
  = Z_p |f_p - f_c|  (the meshes turn with the carrier: a ring tooth passes a planet once per tooth
  pitch of relative rotation)
- planet pass: f_pp = N |f_c - f_r|  (N planets pass a point of the ring per relative carrier turn)
- sun tooth fault: f_sf = N |f_s - f_c|  (one sun tooth meets N planets per sun turn relative to the
  carrier)
- planet tooth fault: f_pf = |f_p - f_c|  (a fault on one flank meets the sun, or the ring, once per
  planet turn relative to the carrier); a fault on both flanks (a crack or broken tooth meets the sun
  on one flank and the ring on the other) shows at 2 f_pf
- ring tooth fault: f_rf = N |f_r - f_c|  (one ring tooth meets N planets per relative carrier turn;
  equal to f_pp)
- sidebands: k f_m +- n f_c' (the planets' transfer to the sensor varies at the carrier speed)

The fault frequencies are also f_sf = N f_m / Z_s, f_pf = f_m / Z_p and f_rf = N f_m / Z_r (a member's
speed relative to the carrier is f_m over its tooth number), the form of Feng & Zuo (2012), Mech. Syst.
Signal Process. 34:165-178.

Sources: McFadden & Smith (1985), Proc. IMechE 199(C1):65-70 (ring-fixed sensor, planet pass, carrier
sidebands); Inalpolat & Kahraman (2009), J. Sound Vib. 323:677-696 (sidebands of a fixed sensor, the
sun, planet and ring fault modulations); Feng & Zuo (2012); docs/references.md,
"Planetary stages". The citations of the fault frequencies are from memory; the formulas themselves
follow from the tooth counting above and are checked by the Willis identities in the tests. For
equally spaced, identical planets McFadden and Smith's rule says which of these lines survive the sum
over the planets (:attr:`PlanetaryLine.survives_equal_spacing`, :mod:`gearbody.analysis.planet_pass`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Literal

from gearbody.analysis._validate import integer_at_least, is_real, positive_frequency
from gearbody.analysis.kinematics import KinematicLine, _combination_label

from ..errors import InputError

__all__ = [
    "CANCELLED_MARK",
    "SYMBOLS",
    "PlanetaryFamily",
    "PlanetaryLine",
    "PlanetarySources",
    "is_cancelled_label",
    "mark_cancelled",
    "planetary_lines",
]

CANCELLED_MARK = "(cancelled)"
"""Ends the label of a line McFadden and Smith's rule cancels (:func:`mark_cancelled`)."""

PlanetaryFamily = Literal["shaft", "planet_pass", "mesh", "sideband", "fault", "fault_sideband"]

SYMBOLS: dict[str, str] = {
    "f_c": "carrier speed relative to the ring (the sensor's frame) |f_c - f_r|",
    "f_s": "sun speed relative to the ring |f_s - f_r|",
    "f_m": "mesh frequency Z_r |f_r - f_c|",
    "f_pp": "planet-pass frequency N |f_c - f_r|",
    "f_sf": "sun tooth-fault frequency N |f_s - f_c|",
    "f_pf": "planet tooth-fault frequency |f_p - f_c| (one flank; both flanks: 2 f_pf)",
    "f_rf": "ring tooth-fault frequency N |f_r - f_c|",
}
"""What each symbol in a planetary line's label stands for (a legend for tables and reports)."""


@dataclass(frozen=True)
class PlanetaryLine(KinematicLine):
    """A labelled line of a planetary stage; its ``orders`` use the symbols of :data:`SYMBOLS`."""

    family: PlanetaryFamily  # type: ignore[assignment]
    """"shaft" (carrier or sun orders), "planet_pass", "mesh", "sideband" (k f_m +- n f_c), "fault"
    (orders of f_sf, f_pf, f_rf) or "fault_sideband" (k f_m +- n fault frequency)."""
    survives_equal_spacing: bool | None = field(default=None)
    """For N equally spaced identical planets: whether the line survives the sum over the planets at a
    ring-fixed sensor (McFadden & Smith: a line (k Z_r + q) f_c survives iff (k Z_r + q) = 0 mod N);
    None where the rule says nothing (sun orders, fault lines)."""


def _signed_speed(name: str, value: float) -> float:
    if not (is_real(value) and math.isfinite(value)):
        raise InputError(f"{name} must be a finite signed speed [Hz], got {value!r}")
    return float(value)


@dataclass(frozen=True)
class PlanetarySources:
    """A planetary stage: tooth numbers, number of planets and the member speeds (signed, absolute).

    The speeds must obey the Willis equation to ``rtol`` of the mesh frequency:
    Z_s (f_s - f_c) = -Z_r (f_r - f_c) (sun and ring turn opposite ways relative to the carrier) and
    Z_p (f_p - f_c) = Z_r (f_r - f_c) (planet and ring turn the same way relative to the carrier).
    Speeds from a simulation's mean, say, may carry a small error; raise ``rtol`` for them.
    """

    z_sun: int
    z_planet: int
    z_ring: int
    n_planets: int
    carrier_hz: float
    """Carrier speed [Hz], signed."""
    sun_hz: float
    """Sun speed [Hz], signed."""
    ring_hz: float
    """Ring speed [Hz], signed (0 for the usual fixed ring)."""
    planet_hz: float
    """Planet spin, absolute [Hz], signed."""
    rtol: float = 1e-6
    """Largest Willis residual relative to the mesh frequency."""

    def __post_init__(self) -> None:
        z_s = integer_at_least("z_sun", self.z_sun, 3)
        z_p = integer_at_least("z_planet", self.z_planet, 3)
        z_r = integer_at_least("z_ring", self.z_ring, 3)
        if z_r <= max(z_s, z_p):
            raise InputError(
                f"z_ring must exceed z_sun = {z_s} and z_planet = {z_p} (an internal gear round the "
                f"planets), got {z_r}"
            )
        integer_at_least("n_planets", self.n_planets, 1)
        for name in ("carrier_hz", "sun_hz", "ring_hz", "planet_hz"):
            object.__setattr__(self, name, _signed_speed(name, getattr(self, name)))
        if not (is_real(self.rtol) and 0 < self.rtol < 1):
            raise InputError(f"rtol must be a number in (0, 1), got {self.rtol!r}")
        f_c, f_r = self.carrier_hz, self.ring_hz
        mesh_hz = z_r * abs(f_r - f_c)
        if mesh_hz == 0:
            raise InputError(
                f"carrier_hz = {f_c!r} equals ring_hz = {f_r!r}: the stage turns as one block and nothing "
                "meshes; the carrier must turn relative to the ring"
            )
        sun_expected = f_c - z_r * (f_r - f_c) / z_s
        planet_expected = f_c + z_r * (f_r - f_c) / z_p
        for name, value, expected, teeth in (
            ("sun_hz", self.sun_hz, sun_expected, z_s),
            ("planet_hz", self.planet_hz, planet_expected, z_p),
        ):
            if abs(value - expected) * teeth > self.rtol * mesh_hz:
                raise InputError(
                    f"{name} must be {expected:.9g} Hz by the Willis equation for carrier_hz = {f_c!r}, "
                    f"ring_hz = {f_r!r} and teeth {z_s}/{z_p}/{z_r} (sun/planet/ring), got {value!r} "
                    f"(allowed mismatch {self.rtol:g} of the mesh frequency)"
                )

    @property
    def carrier_relative_hz(self) -> float:
        """f_c' = |f_c - f_r|: the carrier speed in the sensor's (ring's) frame [Hz]."""
        return abs(self.carrier_hz - self.ring_hz)

    @property
    def sun_relative_hz(self) -> float:
        """|f_s - f_r|: the sun speed in the sensor's (ring's) frame [Hz]."""
        return abs(self.sun_hz - self.ring_hz)

    @property
    def mesh_hz(self) -> float:
        """f_m = Z_r |f_r - f_c| [Hz]."""
        return self.z_ring * abs(self.ring_hz - self.carrier_hz)

    @property
    def planet_pass_hz(self) -> float:
        """f_pp = N |f_c - f_r| [Hz]."""
        return self.n_planets * abs(self.carrier_hz - self.ring_hz)

    @property
    def sun_fault_hz(self) -> float:
        """f_sf = N |f_s - f_c| [Hz]."""
        return self.n_planets * abs(self.sun_hz - self.carrier_hz)

    @property
    def planet_fault_hz(self) -> float:
        """f_pf = |f_p - f_c| [Hz], a fault on one flank; on both flanks the fault shows at 2 f_pf."""
        return abs(self.planet_hz - self.carrier_hz)

    @property
    def ring_fault_hz(self) -> float:
        """f_rf = N |f_r - f_c| [Hz]."""
        return self.n_planets * abs(self.ring_hz - self.carrier_hz)

    def frequency_hz(self, symbol: str) -> float:
        """The frequency of a :data:`SYMBOLS` symbol [Hz]."""
        values = {
            "f_c": self.carrier_relative_hz,
            "f_s": self.sun_relative_hz,
            "f_m": self.mesh_hz,
            "f_pp": self.planet_pass_hz,
            "f_sf": self.sun_fault_hz,
            "f_pf": self.planet_fault_hz,
            "f_rf": self.ring_fault_hz,
        }
        if symbol not in values:
            raise InputError(f"symbol must be one of {sorted(values)}, got {symbol!r}")
        return values[symbol]


def planetary_lines(
    sources: PlanetarySources,
    f_max_hz: float,
    harmonics: int = 3,
    sidebands: int | None = None,
    member_orders: int = 3,
    fault_orders: int = 3,
    fault_sidebands: int = 0,
) -> list[PlanetaryLine]:
    """Catalogue of a planetary stage's lines in (0, f_max_hz], sorted by frequency.

    - "shaft": m f_c and m f_s, m = 1 .. member_orders, labelled "1x carrier", "2x sun", ...
    - "planet_pass": m f_pp, m = 1 .. member_orders, labelled "1 f_pp", "2 f_pp", ...
    - "mesh": k f_m, k = 1 .. harmonics, labelled "1 f_m", "2 f_m", ...
    - "sideband": k f_m +- n f_c, n = 1 .. sidebands (default 2 N: the sidebands at +-N f_c and
      +-2N f_c of equally spaced planets), labelled "f_m + 3 f_c", "2 f_m - f_c", ...
    - "fault": m f_sf, m f_pf, m f_rf, m = 1 .. fault_orders, labelled "1 f_sf", "2 f_pf", ...
    - "fault_sideband": k f_m +- n f_sf (and f_pf, f_rf), n = 1 .. fault_sidebands.

    Lines of different origin may coincide (f_rf = f_pp = N f_c); all are kept. Each line says whether
    it survives the sum over equally spaced planets (:attr:`PlanetaryLine.survives_equal_spacing`).
    """
    if not isinstance(sources, PlanetarySources):
        raise InputError(f"sources must be a PlanetarySources, got {type(sources).__name__}")
    f_max_hz = positive_frequency("f_max_hz", f_max_hz)
    harmonics = integer_at_least("harmonics", harmonics, 1)
    n = sources.n_planets
    sidebands = 2 * n if sidebands is None else integer_at_least("sidebands", sidebands, 0)
    member_orders = integer_at_least("member_orders", member_orders, 0)
    fault_orders = integer_at_least("fault_orders", fault_orders, 0)
    fault_sidebands = integer_at_least("fault_sidebands", fault_sidebands, 0)
    limit = f_max_hz * (1.0 + 1e-12)
    tiny = 1e-9 * sources.mesh_hz
    lines: list[PlanetaryLine] = []

    def add(
        family: PlanetaryFamily,
        orders: tuple[tuple[str, int], ...],
        label: str = "",
        carrier_order: int | None = None,
    ) -> None:
        f = sum(k * sources.frequency_hz(s) for s, k in orders)
        if f < 0:
            f, orders = -f, tuple((s, -k) for s, k in orders)
        if tiny < f <= limit:
            survives = None if carrier_order is None else carrier_order % n == 0
            lines.append(
                PlanetaryLine(float(f), label or _combination_label(orders), family, orders, survives)
            )

    for m in range(1, member_orders + 1):
        add("shaft", (("f_c", m),), f"{m}x carrier", carrier_order=m)
        add("shaft", (("f_s", m),), f"{m}x sun")
        add("planet_pass", (("f_pp", m),), f"{m} f_pp", carrier_order=m * n)
    for k in range(1, harmonics + 1):
        add("mesh", (("f_m", k),), f"{k} f_m", carrier_order=k * sources.z_ring)
        for q in range(1, sidebands + 1):
            for sign in (1, -1):
                add("sideband", (("f_m", k), ("f_c", sign * q)), carrier_order=k * sources.z_ring + sign * q)
    for symbol in ("f_sf", "f_pf", "f_rf"):
        for m in range(1, fault_orders + 1):
            add("fault", ((symbol, m),), f"{m} {symbol}")
        for k in range(1, harmonics + 1):
            for q in range(1, fault_sidebands + 1):
                for sign in (1, -1):
                    add("fault_sideband", (("f_m", k), (symbol, sign * q)))
    lines.sort(key=lambda line: line.frequency_hz)
    return lines


def mark_cancelled(lines: Sequence[PlanetaryLine]) -> list[PlanetaryLine]:
    """The lines, those the rule cancels for equally spaced identical planets
    (``survives_equal_spacing`` False) relabelled "<label> (cancelled)": a peak there comes from what
    breaks the symmetry (tooth errors, unequal load sharing, the planets' own motion), not from the
    mesh as the rule sees it. Lines the rule lets through, or says nothing about, keep their label. Use
    it only for equally spaced planets: otherwise the rule does not apply."""
    out = []
    for i, line in enumerate(lines):
        if not isinstance(line, PlanetaryLine):
            raise InputError(f"lines[{i}] must be a PlanetaryLine, got {type(line).__name__}")
        cancelled = line.survives_equal_spacing is False
        out.append(replace(line, label=f"{line.label} {CANCELLED_MARK}") if cancelled else line)
    return out


def is_cancelled_label(label: str) -> bool:
    """The label is that of a line :func:`mark_cancelled` marked as cancelled."""
    return label.endswith(" " + CANCELLED_MARK)
