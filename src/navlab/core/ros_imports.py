"""``from geometry_msgs.msg import Twist`` and ``import rclpy`` without ROS: an import hook over navlab.

:func:`install` appends a finder to the *end* of ``sys.meta_path``, so a real ROS installation (its
``rclpy``, its message packages) is always found first and nothing of it is shadowed; only names that
nothing else provides are served:

- ``PKG.msg`` for every package of rosbags' ROS 2 typestore: message classes that take keyword
  arguments and default the rest as rclpy's do (``Twist()``, then ``msg.linear.x = 0.2``);
- ``rclpy`` (``init``, ``shutdown``, ``ok``, ``spin``, ``spin_once``, ``create_node``), ``rclpy.node``
  (``Node``), ``rclpy.parameter`` (``Parameter``), ``rclpy.qos`` (``QoSProfile`` and its policies),
  ``rclpy.time`` (``Time``) and ``rclpy.executors`` (``SingleThreadedExecutor``, ``MultiThreadedExecutor``),
  all navlab's (see docs/core-api.md).
"""

from __future__ import annotations

import dataclasses
import enum
import importlib.abc
import importlib.machinery
import importlib.util
import sys
import types
from functools import cache
from typing import Any

import numpy as np

from navlab.msgs import NUMPY_DTYPES, TYPESTORE, zero_value


def _default(node: tuple[Any, Any]) -> Any:
    """The value rclpy gives a field of this rosbags field definition when it is not passed."""
    kind, spec = int(node[0]), node[1]
    if kind == 1:  # BASE: (name, string bound)
        return zero_value(spec[0])
    if kind == 2:  # NAME: a nested message
        return message_class(spec)()
    (sub_kind, sub_spec), length = spec
    if int(sub_kind) == 1 and sub_spec[0] in NUMPY_DTYPES:
        return np.zeros(length if kind == 3 else 0, dtype=NUMPY_DTYPES[sub_spec[0]])
    return [_default((sub_kind, sub_spec)) for _ in range(length if kind == 3 else 0)]


@cache
def message_class(msgtype: str) -> type:
    """rosbags' class for ``pkg/msg/Name``, taking keyword arguments and defaulting the others."""
    base = TYPESTORE.types[msgtype]
    fields = TYPESTORE.fielddefs[msgtype][1]

    def __init__(self: Any, *args: Any, **kwargs: Any) -> None:
        names = [f.name for f in dataclasses.fields(base)]  # type: ignore[arg-type]
        kwargs.update(zip(names, args, strict=False))
        for name, node in fields:
            if name not in kwargs:
                kwargs[name] = _default(node)
        base.__init__(self, **kwargs)

    return type(base.__name__, (base,), {"__init__": __init__, "__module__": msgtype.split("/")[0] + ".msg"})


class DurabilityPolicy(enum.Enum):
    """rclpy's durability policies; TRANSIENT_LOCAL latches as ROS 1 does."""

    SYSTEM_DEFAULT = 0
    TRANSIENT_LOCAL = 1
    VOLATILE = 2


class ReliabilityPolicy(enum.Enum):
    """rclpy's reliability policies (navlab delivers every message)."""

    SYSTEM_DEFAULT = 0
    RELIABLE = 1
    BEST_EFFORT = 2


class HistoryPolicy(enum.Enum):
    """rclpy's history policies."""

    SYSTEM_DEFAULT = 0
    KEEP_LAST = 1
    KEEP_ALL = 2


@dataclasses.dataclass
class QoSProfile:
    """rclpy's ``QoSProfile(depth=10, durability=DurabilityPolicy.TRANSIENT_LOCAL, ...)``."""

    depth: int = 10
    history: HistoryPolicy = HistoryPolicy.KEEP_LAST
    reliability: ReliabilityPolicy = ReliabilityPolicy.RELIABLE
    durability: DurabilityPolicy = DurabilityPolicy.VOLATILE


class SingleThreadedExecutor:
    """``rclpy.executors.SingleThreadedExecutor``: spins its nodes in the context's simulated time (every
    node of a context shares its one executor, so this only keeps the node list rclpy code expects)."""

    def __init__(self, *, context: Any = None) -> None:
        self.nodes: list[Any] = []

    def add_node(self, node: Any) -> bool:
        """Add a node (rclpy returns whether it was added)."""
        if node in self.nodes:
            return False
        self.nodes.append(node)
        return True

    def remove_node(self, node: Any) -> None:
        """Forget a node."""
        if node in self.nodes:
            self.nodes.remove(node)

    def get_nodes(self) -> list[Any]:
        """The nodes added."""
        return list(self.nodes)

    def spin(self) -> None:
        """Run simulated time until shutdown (or ``navlab run``'s ``--duration``)."""
        from navlab.core import rclpy_api

        if self.nodes:
            rclpy_api.spin(self.nodes[0])

    def spin_once(self, timeout_sec: float | None = None) -> None:
        """Run simulated time for ``timeout_sec`` (default: to the next event)."""
        from navlab.core import rclpy_api

        if self.nodes:
            rclpy_api.spin_once(self.nodes[0], timeout_sec=timeout_sec)

    def shutdown(self, timeout_sec: float | None = None) -> bool:
        """Nothing to stop here; rclpy returns True when done."""
        return True


class MultiThreadedExecutor(SingleThreadedExecutor):
    """``rclpy.executors.MultiThreadedExecutor``: the same one simulated-time executor (callbacks stay ordered)."""

    def __init__(self, num_threads: int | None = None, *, context: Any = None) -> None:
        super().__init__(context=context)


def _rclpy_modules() -> dict[str, dict[str, Any]]:
    from navlab.core import rclpy_api
    from navlab.core.node import Node, Parameter, Time

    api = {n: getattr(rclpy_api, n) for n in ("init", "shutdown", "ok", "spin", "spin_once", "create_node")}
    return {
        "rclpy": api,
        "rclpy.node": {"Node": Node},
        "rclpy.parameter": {"Parameter": Parameter},
        "rclpy.time": {"Time": Time},
        "rclpy.executors": {
            "SingleThreadedExecutor": SingleThreadedExecutor,
            "MultiThreadedExecutor": MultiThreadedExecutor,
        },
        "rclpy.qos": {
            "QoSProfile": QoSProfile,
            "DurabilityPolicy": DurabilityPolicy,
            "ReliabilityPolicy": ReliabilityPolicy,
            "HistoryPolicy": HistoryPolicy,
            "qos_profile_sensor_data": QoSProfile(depth=5, reliability=ReliabilityPolicy.BEST_EFFORT),
        },
    }


@cache
def _packages() -> frozenset[str]:
    return frozenset(name.split("/")[0] for name in TYPESTORE.types if "/msg/" in name)


class _Finder(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Serves ``rclpy``'s modules and ``PKG``/``PKG.msg`` for the typestore's message packages."""

    def find_spec(self, fullname: str, path: Any = None, target: Any = None) -> importlib.machinery.ModuleSpec | None:
        head, _, rest = fullname.partition(".")
        if fullname in ("rclpy", "rclpy.node", "rclpy.parameter", "rclpy.qos", "rclpy.time", "rclpy.executors"):
            return importlib.util.spec_from_loader(fullname, self, is_package=fullname == "rclpy")
        if head in _packages() and rest in ("", "msg"):
            return importlib.util.spec_from_loader(fullname, self, is_package=not rest)
        return None

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> types.ModuleType | None:
        return None

    def exec_module(self, module: types.ModuleType) -> None:
        name = module.__name__
        if name.startswith("rclpy"):
            module.__dict__.update(_rclpy_modules()[name])
        elif name.endswith(".msg"):
            pkg = name.split(".")[0]
            for msgtype in TYPESTORE.types:
                if msgtype.startswith(f"{pkg}/msg/"):
                    setattr(module, msgtype.rsplit("/", 1)[1], message_class(msgtype))


def install() -> None:
    """Serve ``rclpy`` and ``PKG.msg`` from navlab where nothing else does (idempotent)."""
    if not any(isinstance(f, _Finder) for f in sys.meta_path):
        sys.meta_path.append(_Finder())
