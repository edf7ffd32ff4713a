"""Localization on a known map: AMCL (adaptive Monte Carlo localization, as in ROS 1 amcl)."""

from navlab.localization.amcl import Amcl, AmclParams, Scan
from navlab.localization.errors import LocalizationError
from navlab.localization.field import MapField, build_field, field_from_map
from navlab.localization.raycast import cast_rays

__all__ = ["Amcl", "AmclParams", "LocalizationError", "MapField", "Scan", "build_field", "cast_rays",
           "field_from_map"]
