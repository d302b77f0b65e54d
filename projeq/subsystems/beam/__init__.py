"""The elastic beam by a direct Ritz approach (B(19)–(25), docs/theory.md §10).

- :mod:`.beam`: :class:`RitzBeam`, its Gauss-form terms and ports for joints at its stations;
- :mod:`.shapes`: Ritz shape-function families; :mod:`.integrals`: precomputed shape integrals;
- :mod:`.probes`: displacement, slopes and section forces along a trajectory;
- :mod:`.checks`: input checks.
"""

from projeq.subsystems.beam.beam import RitzBeam

__all__ = ["RitzBeam"]
