"""rclpy's parameter types (rclpy.parameter.Parameter, its value and the set-parameters result)."""

from __future__ import annotations

import dataclasses
import enum
from typing import Any

__all__ = ["Parameter", "ParameterValue", "SetParametersResult"]


@dataclasses.dataclass(frozen=True)
class SetParametersResult:
    """rcl_interfaces/SetParametersResult as rclpy returns it."""

    successful: bool
    reason: str = ""


class ParameterValue:
    """rclpy's ``get_parameter_value()``: the value under its typed field names."""

    def __init__(self, value: Any) -> None:
        self.bool_value = value if isinstance(value, bool) else False
        self.integer_value = value if isinstance(value, int) and not isinstance(value, bool) else 0
        self.double_value = float(value) if isinstance(value, int | float) and not isinstance(value, bool) else 0.0
        self.string_value = value if isinstance(value, str) else ""
        is_list = isinstance(value, list | tuple)
        self.double_array_value = list(value) if is_list and all(isinstance(v, float) for v in value) else []
        self.integer_array_value = list(value) if is_list and all(isinstance(v, int) for v in value) else []
        self.string_array_value = list(value) if is_list and all(isinstance(v, str) for v in value) else []
        self.bool_array_value = list(value) if is_list and all(isinstance(v, bool) for v in value) else []


class Parameter:
    """``rclpy.parameter.Parameter``: ``name``, ``value`` and ``get_parameter_value()``."""

    class Type(enum.Enum):
        """rclpy's parameter types (``Parameter.Type.DOUBLE``); navlab takes the type from the value."""

        NOT_SET = 0
        BOOL = 1
        INTEGER = 2
        DOUBLE = 3
        STRING = 4
        BYTE_ARRAY = 5
        BOOL_ARRAY = 6
        INTEGER_ARRAY = 7
        DOUBLE_ARRAY = 8
        STRING_ARRAY = 9

    def __init__(self, name: str, type_: Parameter.Type | None = None, value: Any = None) -> None:
        self.name = name
        self.value = value
        self.type_ = type_

    def get_parameter_value(self) -> ParameterValue:
        """The value under rclpy's typed field names (``double_value``, ``string_value``, ...)."""
        return ParameterValue(self.value)

    def __repr__(self) -> str:
        return f"Parameter({self.name!r}, value={self.value!r})"
