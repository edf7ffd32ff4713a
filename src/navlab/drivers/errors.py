"""The drivers' error."""

from navlab.mapping import MappingError


class DriverError(MappingError):
    """A driver (exploration, teleop, route) refused its input: one line naming the file, key or device.

    A ``MappingError`` for one release, so ``except MappingError`` around the drivers' old home still catches it.
    """
