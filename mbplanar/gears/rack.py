"""The basic rack: the tool profile that generates the teeth (ISO 53, GOST 13755).

Coefficients are in modules: addendum h_a* (of the gear; the tool's dedendum), clearance c* (the tool's
addendum is h_a* + c*), the radius ρ_f* of the round at the tool's tip. Its straight flank ends at
h_fe* = h_a* + c* − ρ_f*(1 − sin α) below the datum line; the default ρ_f* = c*/(1 − sin α) (0.37995 at
20°; ISO 53 profile A rounds it to 0.38) makes h_fe* = h_a*, which is what the textbooks' undercut limit
x_min = h_a* − z sin²α/2 assumes; where that round does not fit on the tool's tooth (α = 25°, c* = 0.25)
the default is the largest that does.

    >>> from mbplanar.gears.rack import Rack
    >>> r = Rack()
    >>> round(r.tip_radius, 5), round(r.flank_end, 12)
    (0.37995, 1.0)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..errors import ModelError

__all__ = ["Rack"]


@dataclass(frozen=True)
class Rack:
    """The basic rack profile, in modules (lengths) and radians.

    Parameters
    ----------
    pressure_angle : float
        α, rad (default 20°); 0 < α < 45°.
    addendum : float
        h_a* > 0 (default 1).
    clearance : float
        c* ≥ 0 (default 0.25).
    tip_radius : float, optional
        ρ_f* of the tool's tip round (default c*/(1 − sin α), or the largest that fits if smaller); at
        most the round that reaches the middle of the tool's tooth.

    Attributes
    ----------
    flank_end : float
        h_fe* = h_a* + c* − ρ_f*(1 − sin α): depth below the datum line where the straight flank ends.

    Raises
    ------
    ModelError
        a value out of its range, named with the value.

    Examples
    --------
    >>> import math
    >>> from mbplanar.gears import Rack
    >>> round(Rack(math.radians(25)).tip_radius, 6)      # c*/(1 − sin 25°) does not fit: the largest that does
    0.317883
    """

    pressure_angle: float = math.radians(20.0)
    addendum: float = 1.0
    clearance: float = 0.25
    tip_radius: float | None = None
    flank_end: float = field(init=False)

    def __post_init__(self):
        a, ha, c = self.pressure_angle, self.addendum, self.clearance
        if not (isinstance(a, (int, float)) and 0 < a < math.radians(45)):
            raise ModelError(f"pressure angle must be between 0° and 45°, got {math.degrees(a):g}°")
        if not (math.isfinite(ha) and ha > 0):
            raise ModelError(f"addendum coefficient must be > 0, got {ha:g}")
        if not (math.isfinite(c) and c >= 0):
            raise ModelError(f"clearance coefficient must be ≥ 0, got {c:g}")
        largest = self.largest_tip_radius()
        rho = min(c / (1 - math.sin(a)), largest) if self.tip_radius is None else self.tip_radius
        if not (math.isfinite(rho) and 0 <= rho <= largest * (1 + 1e-12)):
            raise ModelError(f"tool tip radius coefficient must be between 0 and {largest:.6g} "
                             f"(the round reaching the middle of the tool's tooth), got {rho:g}")
        object.__setattr__(self, "tip_radius", float(rho))
        object.__setattr__(self, "flank_end", ha + c - rho * (1 - math.sin(a)))

    def largest_tip_radius(self) -> float:
        """The tip round (in modules) whose centre sits on the middle of the tool's tooth: beyond it the
        two rounds of one tooth would overlap."""
        a, depth = self.pressure_angle, self.addendum + self.clearance
        # centre x of a round ρ: π/4 + (depth − ρ(1 − sin α)) tan α + ρ cos α  ≤  π/2
        slope = math.cos(a) - (1 - math.sin(a)) * math.tan(a)
        return max(0.0, (math.pi / 4 - depth * math.tan(a)) / slope)

    def tooth_depth(self) -> float:
        """h_a* + c*: the tool's addendum, the gear's dedendum (in modules)."""
        return self.addendum + self.clearance
