"""A lidar's Gaussian noise draws: NumPy's own ``Generator.standard_normal`` values, drawn in a compiled loop.

Gazebo's lidar noise is one standard normal per beam from the sensor's ``numpy.random.Generator``. NumPy draws
them with O'Neill's PCG64 (the XSL-RR output of a 128-bit LCG) and Marsaglia and Tsang's 256-layer ziggurat; for
720 beams that costs ~12 µs a scan, mostly a mispredicted sign branch. :class:`NormalDraws` runs the same two
algorithms, with NumPy's ziggurat tables, on the generator's own state (a view of its memory, so the generator
stays in step with every draw made here): the same values bit for bit in ~3 µs. Whenever it cannot be sure of that
(another bit generator, a NumPy whose PCG64 state is laid out differently, the tables missing), or when a check
draw against NumPy disagrees, it draws with NumPy itself.
"""

from __future__ import annotations

# moved to the leaf module navlab.pcg64 (amcl draws with them too); the lidar's names stay importable from here
from navlab.pcg64 import CHECK_DRAWS, PCG64_MULT, NormalDraws, fill_standard_normal, pcg64_words

__all__ = ["CHECK_DRAWS", "PCG64_MULT", "NormalDraws", "fill_standard_normal", "pcg64_words"]
