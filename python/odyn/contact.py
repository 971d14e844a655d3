"""Helpers for the contact elements (sphere_plane, sphere_sphere, circle_line, circle_circle;
docs/contact.md)."""

import math


def hunt_crossley_dissipation(restitution: float, impact_speed: float) -> float:
    """The dissipation d (s/m) of the contact law k delta^n (1 + d delta') for which an impact
    at `impact_speed` (m/s) with no other force leaves at `restitution` times that speed.

    It solves the law's first integral, x - ln(1 + x) = -e x - ln(1 - e x) with x = d v_in,
    whatever k and n. e = 1 gives 0; e must be in (0, 1]."""
    e, v = float(restitution), float(impact_speed)
    if not 0.0 < e <= 1.0:
        raise ValueError(f"restitution is {restitution}; it must be in (0, 1]")
    if not (v > 0.0 and math.isfinite(v)):
        raise ValueError(f"impact_speed is {impact_speed} m/s; it must be positive")
    if e == 1.0:
        return 0.0

    # In u = -ln(1 - e x), which runs over (0, inf) as x runs over (0, 1/e): the excess of the
    # entry's loss x - ln(1 + x) over the exit's -e x - ln(1 - e x) starts positive and falls
    # to -inf, and d v_in is where it crosses zero.
    def excess(u: float) -> float:
        x = -math.expm1(-u) / e
        return (x - math.log1p(x)) + e * x - u

    lo, hi = 0.0, 1.0
    while excess(hi) > 0.0:
        lo, hi = hi, 2.0 * hi
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if excess(mid) > 0.0:
            lo = mid
        else:
            hi = mid
    return -math.expm1(-0.5 * (lo + hi)) / e / v
