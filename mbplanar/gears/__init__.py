"""Involute spur gears: a pair with profile shift (geometry, path of contact, checks), the block contour
of admissible shifts and a choice by a stated criterion, the exact tooth profile a rack cutter generates
(with its self-check, DXF, SVG), and planetary trains chosen by tooth numbers.

    >>> from mbplanar.gears import choose_shifts, gear_profile, planetary_trains
    >>> c = choose_shifts(10e-3, (12, 30), "balanced")          # m = 10 mm, z = 12, 30
    >>> c.pair.success, round(c.pair.contact_ratio, 4)
    (True, 1.2)
    >>> gear_profile(c.pair, 1).check.success                    # involute and thickness to 1e-9 m
    True
    >>> planetary_trains(7.0, "A", planets=3).trains[0].teeth    # sun, planet, ring
    (18, 45, 108)

Modules: `involute` (inv α and its inverse), `rack` (the basic rack), `pair` (a pair and its checks),
`shifts` (block contour, choice of shifts), `profile` (the generated outline and its self-check),
`planetary` (2K-H schemes, tooth numbers, Willis), `trainmodel` (a train as a model with `gear` joints),
`spec` (the `[gears]` section), `export` (CSV, DXF, SVG), `plots` (pictures), `command` (the
`mbplanar gear` command, JSON), `report` (the report's section). Data flows one way: gears uses errors,
viz and cam's writers; only the CLI imports gears.
"""

from .involute import arcinv, inv
from .pair import Check, Gear, GearPair, gear_pair
from .planetary import SCHEMES, PlanetarySearch, Train, planetary_trains, willis
from .profile import GearProfile, gear_profile
from .rack import Rack
from .shifts import BlockContour, ShiftChoice, block_contour, choose_shifts

__all__ = ["inv", "arcinv", "Rack", "gear_pair", "GearPair", "Gear", "Check", "block_contour", "BlockContour",
           "choose_shifts", "ShiftChoice", "gear_profile", "GearProfile", "planetary_trains", "PlanetarySearch",
           "Train", "SCHEMES", "willis"]
