"""Localization on a known map: AMCL (adaptive Monte Carlo localization, as in ROS 1 amcl)."""

from typing import TYPE_CHECKING

from navlab.lazy import lazy_exports

if TYPE_CHECKING:
    from navlab.localization.amcl import Amcl, AmclParams, Scan
    from navlab.localization.amcl_node import Amcl as AmclNode
    from navlab.localization.errors import LocalizationError
    from navlab.localization.field import MapField, build_field, field_from_map
    from navlab.localization.models import Beams
    from navlab.localization.raycast import cast_rays
    from navlab.localization.synthetic import room_field, simulated_scan

_EXPORTS = {
    "Amcl": "navlab.localization.amcl",
    "AmclParams": "navlab.localization.amcl",
    "LocalizationError": "navlab.localization.errors",
    "MapField": "navlab.localization.field",
    "Scan": "navlab.localization.amcl",
    "build_field": "navlab.localization.field",
    "cast_rays": "navlab.localization.raycast",
    "field_from_map": "navlab.localization.field",
    "AmclNode": "navlab.localization.amcl_node:Amcl",
    "Beams": "navlab.localization.models",
    "room_field": "navlab.localization.synthetic",
    "simulated_scan": "navlab.localization.synthetic",
}
__all__ = [
    "Amcl",
    "AmclNode",
    "AmclParams",
    "Beams",
    "LocalizationError",
    "MapField",
    "Scan",
    "build_field",
    "cast_rays",
    "field_from_map",
    "room_field",
    "simulated_scan",
]
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
