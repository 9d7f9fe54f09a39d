"""Induction motor with the Kloss characteristic, converter-fed (ramped synchronous speed)."""

from __future__ import annotations

import math

from numba import njit

from .profiles import profile_integral, profile_value


@njit(cache=True)
def kloss_torque_Nm(
    speed_rad_s: float,
    synchronous_speed_rad_s: float,
    rated_synchronous_speed_rad_s: float,
    breakdown_torque_Nm: float,
    breakdown_slip: float,
) -> float:
    """Kloss torque M_s = 2 M_b s s_b / (s^2 + s_b^2).

    The slip is the slip *speed* over the rated synchronous speed, ``s = (w_s(t) - w) / w_s,rated``:
    with a frequency converter the characteristic shifts with the supply frequency (constant V/f),
    so a start ramp of ``w_s`` does not make the slip blow up as ``w_s -> 0``.
    """
    s = (synchronous_speed_rad_s - speed_rad_s) / rated_synchronous_speed_rad_s
    return 2.0 * breakdown_torque_Nm * s * breakdown_slip / (s * s + breakdown_slip * breakdown_slip)


def steady_slip(load_torque_Nm: float, breakdown_torque_Nm: float, breakdown_slip: float) -> float:
    """Slip on the stable branch where the Kloss torque equals ``load_torque_Nm``.

    Raises ValueError when the load exceeds the breakdown torque (the motor would stall).
    """
    if load_torque_Nm == 0.0:
        return 0.0
    if abs(load_torque_Nm) > breakdown_torque_Nm:
        raise ValueError(
            f"load torque {load_torque_Nm:.6g} N m exceeds the motor's breakdown torque "
            f"{breakdown_torque_Nm:.6g} N m: the motor cannot carry it"
        )
    mb, m = breakdown_torque_Nm, load_torque_Nm
    return breakdown_slip * (mb - math.copysign(math.sqrt(mb * mb - m * m), m)) / m


def viscous_equivalent_Nms(
    breakdown_torque_Nm: float, breakdown_slip: float, synchronous_speed_rad_s: float
) -> float:
    """Slope -dM/dw of the Kloss curve at synchronous speed: c_e = 2 M_b / (s_b w_s)."""
    return 2.0 * breakdown_torque_Nm / (breakdown_slip * synchronous_speed_rad_s)


# -- drive: motor characteristic and load torque under the operating profiles ------------------
# Packed layout: [w_s rated, M_b, s_b, rated load torque, n_speed, n_load, speed t.., speed f..,
#                 load t.., load f..]


@njit(cache=True)
def _speed_profile(D):
    n = int(D[4])
    return D[6 : 6 + n], D[6 + n : 6 + 2 * n]


@njit(cache=True)
def _load_profile(D):
    n, k = int(D[4]), int(D[5])
    o = 6 + 2 * n
    return D[o : o + k], D[o + k : o + 2 * k]


@njit(cache=True)
def synchronous_speed_at(t: float, D) -> float:
    """w_s(t) = rated synchronous speed x speed-profile fraction, rad/s."""
    times, fr = _speed_profile(D)
    return D[0] * profile_value(t, times, fr)


@njit(cache=True)
def synchronous_angle_at(t: float, D) -> float:
    """Integral of w_s from 0 to t, rad (the prescribed pinion angle of the Muller model)."""
    times, fr = _speed_profile(D)
    return D[0] * profile_integral(t, times, fr)


@njit(cache=True)
def motor_torque_at(t: float, speed_rad_s: float, D) -> float:
    """Kloss motor torque at time t and rotor speed, N m."""
    return kloss_torque_Nm(speed_rad_s, synchronous_speed_at(t, D), D[0], D[1], D[2])


@njit(cache=True)
def load_fraction_at(t: float, D) -> float:
    times, fr = _load_profile(D)
    return profile_value(t, times, fr)


@njit(cache=True)
def load_torque_at(t: float, D) -> float:
    """Driven-machine load torque M_r(t), N m."""
    return D[3] * load_fraction_at(t, D)
