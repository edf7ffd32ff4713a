"""``range_sensor_layer::RangeSensorLayer``: sonar and IR cones (``sensor_msgs/Range``) into a costmap, by
the package's Bayesian update.

Each cell holds an occupancy probability (stored as ``p * 255``, 0.5 at the start). A reading ``r`` from a
sensor at ``(x, y, yaw)`` with field of view ``fov`` updates every cell in its cone (half-angle
``fov / 2 * inflate_cone``, out to ``r`` plus a margin): ``p <- s p / (s p + (1 - s)(1 - p))`` with the sensor
model ``s(r, d, theta)`` of range_sensor_layer (``d``: the cell's distance, ``theta``: its angle off the axis;
cells short of the reading are pushed towards free, those at the reading towards occupied, weighted by
``gamma(theta) = 1 - (theta / half_angle)^2`` and ``delta(d) = 1 - (1 + tanh(2 (d - phi))) / 2``). A reading at
``max_range`` clears the cone only with ``clear_on_max_reading``. Into the master: lethal where
``p > mark_threshold``, free where ``p < clear_threshold``, untouched otherwise.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar, Self

import numpy as np

from navlab.core import ParamSpec, read_params
from navlab.grid import COST_FREE, COST_LETHAL, COST_UNKNOWN, Grid
from navlab.navigation.costmap.kernels import combine
from navlab.navigation.costmap.layer import Layer, origin_shift, same_geometry, shifted
from navlab.navigation.errors import NavigationError
from navlab.plugins import PluginContext


@dataclass
class RangeSensorLayerParams:
    """range_sensor_layer's parameters (ROS 1 names and defaults)."""

    enabled: bool = True
    topics: str = "/sonar"  # a list in YAML; the topics of sensor_msgs/Range
    no_readings_timeout: float = 0.0
    clear_threshold: float = 0.2
    mark_threshold: float = 0.8
    clear_on_max_reading: bool = False
    phi: float = 1.2
    inflate_cone: float = 1.0
    input_sensor_type: str = "ALL"  # ALL | VARIABLE | FIXED
    ns: str = ""
    PARAMS: ClassVar[ParamSpec]

    def validate(self) -> None:
        """What spans two parameters (one error line)."""
        if not self.clear_threshold < self.mark_threshold:
            raise NavigationError(
                f"range_sensor_layer parameters clear_threshold {self.clear_threshold} and "
                f"mark_threshold {self.mark_threshold}: expected clear < mark"
            )


def _topics_joined(values: dict[str, Any]) -> dict[str, Any]:
    """A YAML list of ``topics`` as ROS's space-separated string."""
    if isinstance(values.get("topics"), list | tuple):
        values = {**values, "topics": " ".join(map(str, values["topics"]))}
    return values


RangeSensorLayerParams.PARAMS = ParamSpec(
    "range_sensor_layer",
    NavigationError,
    prepare=_topics_joined,
    ignored=frozenset({"enabled_topics"}),
    at_least={"clear_threshold": 0.0, "no_readings_timeout": 0.0},
    at_most={"mark_threshold": 1.0},
    above={"inflate_cone": 0.0},
    choices={"input_sensor_type": ("ALL", "VARIABLE", "FIXED")},
)


def sensor_model(
    r: float, d: np.ndarray, theta: np.ndarray, half_angle: float, phi_v: float, resolution: float
) -> np.ndarray:
    """range_sensor_layer's ``sensor_model``: probability of occupancy of cells at distance ``d`` (m) and angle
    ``theta`` (rad off the axis) given a reading ``r`` (m)."""
    gamma = np.where(np.abs(theta) > half_angle, 0.0, 1.0 - (theta / half_angle) ** 2)
    lbda = (1.0 - (1.0 + np.tanh(2.0 * (d - phi_v))) / 2.0) * gamma
    delta = resolution
    out = np.full(d.shape, 0.5)
    a = (d >= 0) & (d < r - 2 * delta * r)
    out[a] = (1 - lbda[a]) * 0.5
    b = ~a & (d < r - delta * r)
    out[b] = lbda[b] * 0.5 * ((d[b] - (r - 2 * delta * r)) / (delta * r)) ** 2 + (1 - lbda[b]) * 0.5
    c = ~a & ~b & (d < r + delta * r)
    j = (r - d[c]) / (delta * r)
    out[c] = lbda[c] * ((1 - 0.5 * j**2) - 0.5) + 0.5
    return out


class RangeSensorLayer(Layer):
    """``range_sensor_layer::RangeSensorLayer`` (see the module docstring)."""

    def __init__(
        self, params: RangeSensorLayerParams | dict[str, Any] | None = None, *, name: str = "range_sensor_layer"
    ) -> None:
        self.params: RangeSensorLayerParams = read_params(RangeSensorLayerParams, params, what=name)
        self.name = name
        self.enabled = self.params.enabled
        self.prob: Grid | None = None

    @classmethod
    def from_params(cls, params: Mapping[str, Any] | None, *, context: PluginContext) -> Self:
        """The layer named ``context.name`` (its ``plugins:`` name) from its namespace ``params`` (ROS names)."""
        return cls(dict(params or {}), name=context.name or "range_sensor_layer")

    @property
    def topics(self) -> list[str]:
        """The Range topics this layer reads (``ns`` prefixed)."""
        ns = self.params.ns.rstrip("/")
        return [t if t.startswith("/") or not ns else f"{ns}/{t}" for t in self.params.topics.split()]

    def match_size(self, master: Grid) -> None:
        self.prob = Grid(np.full(master.data.shape, 128, np.uint8), master.resolution, master.origin, master.frame_id)

    def update_origin(self, master: Grid) -> None:
        shift = origin_shift(self.prob, master)
        if shift is None or self.prob is None:
            self.match_size(master)
            return
        self.prob = Grid(shifted(self.prob.data, *shift, 128), master.resolution, master.origin, master.frame_id)

    def add_range(
        self,
        sensor_pose: tuple[float, float, float],
        reading: float,
        *,
        field_of_view: float,
        min_range: float,
        max_range: float,
    ) -> None:
        """One ``sensor_msgs/Range`` reading (m) from a sensor at ``sensor_pose`` (x, y, yaw; costmap frame)."""
        if self.prob is None:
            raise NavigationError(f"{self.name}: no grid yet; call match_size(master) before add_range")
        if not math.isfinite(reading) or reading < min_range:
            return
        clear = reading >= max_range
        if clear and not self.params.clear_on_max_reading:
            return
        r = min(reading, max_range)
        g = self.prob
        half = field_of_view / 2.0 * self.params.inflate_cone
        x, y, yaw = sensor_pose
        reach = r + 2 * g.resolution
        lo = g.world_to_cell(np.array([[x - reach, y - reach]]))[0]
        hi = g.world_to_cell(np.array([[x + reach, y + reach]]))[0]
        i0, j0 = max(int(lo[0]), 0), max(int(lo[1]), 0)
        i1, j1 = min(int(hi[0]), g.width - 1), min(int(hi[1]), g.height - 1)
        if i0 > i1 or j0 > j1:
            return
        cx = g.origin[0] + (np.arange(i0, i1 + 1) + 0.5) * g.resolution
        cy = g.origin[1] + (np.arange(j0, j1 + 1) + 0.5) * g.resolution
        dx, dy = cx[None, :] - x, cy[:, None] - y
        d = np.hypot(dx, dy)
        theta = (np.arctan2(dy, dx) - yaw + math.pi) % (2 * math.pi) - math.pi
        cone = (np.abs(theta) <= half) & (d <= r + g.resolution)
        if not cone.any():
            return
        s = sensor_model(r, d[cone], theta[cone], max(half, 1e-9), self.params.phi, g.resolution)
        if clear:
            s = np.minimum(s, 0.5)
        block = g.data[j0 : j1 + 1, i0 : i1 + 1]
        prior = block[cone] / 255.0
        occ, free = s * prior, (1 - s) * (1 - prior)
        block[cone] = np.clip(np.rint(255.0 * occ / np.maximum(occ + free, 1e-12)), 0, 255).astype(np.uint8)

    def update_costs(self, master: Grid) -> None:
        if self.prob is None:
            return
        if not same_geometry(self.prob, master):
            self.update_origin(master)
        p = self.prob.data / 255.0
        current = np.full(p.shape, COST_UNKNOWN, np.uint8)  # unknown: the master's cell untouched
        current[p > self.params.mark_threshold] = COST_LETHAL
        current[p < self.params.clear_threshold] = COST_FREE
        combine(master.data, current, True)

    def reset(self) -> None:
        if self.prob is not None:
            self.prob.data[:] = 128
