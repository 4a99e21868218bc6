"""Analysis of a mechanism's motion: `check` (motion range, limit and change points, extremes,
transmission and pressure angles, Grashof), `check_region` (the singular curves of a two-input
mechanism), `transmission_angles`, `pressure_angles`, `contact_angles`.
"""

from ._check import (AngleRange, CheckReport, Extreme, LimitReport, RegionReport, Separation, check, check_region,
                     contact_angles, format_region, format_report, grashof, pressure_angles, transmission_angles,
                     transmission_triples)

__all__ = ["check", "CheckReport", "Extreme", "AngleRange", "LimitReport", "Separation", "grashof", "transmission_angles",
           "transmission_triples", "pressure_angles", "contact_angles", "format_report", "check_region",
           "RegionReport", "format_region"]
