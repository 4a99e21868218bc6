"""Analysis of a mechanism's motion: `check` (motion range, limit and change points, extremes,
transmission and pressure angles, Grashof), `transmission_angles`, `pressure_angles`.
"""

from ._check import (AngleRange, CheckReport, Extreme, LimitReport, RegionReport, Separation, check, check_region, format_region,
                     format_report, grashof, pressure_angles, transmission_angles)

__all__ = ["check", "CheckReport", "Extreme", "AngleRange", "LimitReport", "Separation", "grashof", "transmission_angles",
           "pressure_angles", "format_report", "check_region", "RegionReport", "format_region"]
