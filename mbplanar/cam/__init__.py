"""Cam mechanisms designed from a linkage's cycle.

    >>> from mbplanar.cam import read_cam, design
    >>> d = design(read_cam("models/shaper_cam.toml"))      # timing from models/shaper.toml
    >>> round(d.follower.prime_radius, 6)                      # r0, m
    0.241791
    >>> round(float(d.rise.value), 4), round(float(d.ret.value), 4)   # pressure-angle extremes, rad
    (0.5749, -0.642)
    >>> bool(d.check.relative < 1e-7)                          # self-check error / stroke
    True

Modules: `laws` (motion laws, programs, continuity), `followers`, `geometry` (inversion, envelope,
pressure angle, curvature), `sizing` (smallest cam for the pressure limits; the seed's construction),
`selfcheck` (the follower run on the profile), `timing` (events on a linkage model), `dynamics` (spring,
inertia, contact force, torque), `spec` (the `[cam]` section), `design` (all of it), `export` (CSV, DXF,
SVG), `plots` (pictures), `present` (the `mbplanar cam` command, JSON, the report's section).
Data flows one way: cam uses model, engine, kinematics and viz (their public names); only the CLI imports cam.
"""

from .design import CamDesign, design
from .followers import Follower
from .geometry import CamGeometry, cam_geometry
from .laws import LAWS, Program, Segment, make_law, program
from .selfcheck import self_check
from .sizing import size_follower
from .spec import parse_cam, read_cam

__all__ = ["read_cam", "parse_cam", "design", "CamDesign", "Follower", "cam_geometry", "CamGeometry",
           "LAWS", "make_law", "Segment", "Program", "program", "size_follower", "self_check"]
