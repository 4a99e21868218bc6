"""Kinematics: `analyse(engine, phi, omega, epsilon)` → `Motion`, positions, analogues and real
velocities and accelerations of every link, joint and point (batch first, SI); `positions_at_limits`;
`position(engine, phi, omega, epsilon)` → `Position`, one position without the batch machinery;
`contacts(engine, motion)` → a `Contact` per higher pair (where it touches, its normal, sliding and
pressure angle).
"""

from ._contacts import Contact, ContactGeometry, contact_geometry, contacts
from ._motion import (OUTPUTS, Frames, Motion, analyse, describe_crossing, describe_limit, material_points,
                      point_table, positions_at_limits, range_text, reach_text)
from ._single import Position, position

__all__ = ["Motion", "Frames", "OUTPUTS", "analyse", "positions_at_limits", "material_points", "point_table",
           "Position", "position", "Contact", "ContactGeometry", "contact_geometry", "contacts", "describe_limit",
           "describe_crossing", "range_text", "reach_text"]
