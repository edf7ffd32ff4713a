"""costmap_2d in Python: a layered master grid of costs (0 free .. 252, 253 inscribed, 254 lethal, 255 unknown).

``LayeredCostmap`` builds its layers from a costmap parameter dict (ROS 1 names; Nav2 spellings accepted);
``StaticLayer``, ``ObstacleLayer`` and ``InflationLayer`` (one module each, beside ``layer``, the
interface) are registered as the ``costmap_layer`` plugins
``costmap_2d::StaticLayer``, ``costmap_2d::ObstacleLayer`` and ``costmap_2d::InflationLayer``.
"""

from navlab.navigation.costmap.footprint import Footprint, make_footprint, parse_polygon
from navlab.navigation.costmap.inflation_layer import InflationLayer
from navlab.navigation.costmap.layer import Layer
from navlab.navigation.costmap.layered import LayeredCostmap
from navlab.navigation.costmap.obstacle_layer import ObstacleLayer
from navlab.navigation.costmap.params import (
    CostmapParams,
    InflationLayerParams,
    ObservationSource,
    ObstacleLayerParams,
    PluginSpec,
    StaticLayerParams,
    costmap_params,
)
from navlab.navigation.costmap.static_layer import StaticLayer

__all__ = [
    "CostmapParams",
    "Footprint",
    "InflationLayer",
    "InflationLayerParams",
    "Layer",
    "LayeredCostmap",
    "ObservationSource",
    "ObstacleLayer",
    "ObstacleLayerParams",
    "PluginSpec",
    "StaticLayer",
    "StaticLayerParams",
    "costmap_params",
    "make_footprint",
    "parse_polygon",
]
