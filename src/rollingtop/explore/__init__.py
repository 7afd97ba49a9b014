"""``rollingtop explore``: the reduced system in the browser (a Panel app).

- :mod:`.view`: what the page shows, as functions of an :class:`~.view.ExploreState` (no Panel):
  the readout, ``U``, the phase portrait, the bifurcation diagram, a trajectory started from a
  point of the portrait, a Poincare section for a model without a reduction; the URL's query.
- :mod:`.app`: the Panel page over it (needs the ``explore`` extra: ``pip install
  'rollingtop[explore]'``).
- :mod:`.server`: serving the page, as the command does.
"""

from __future__ import annotations
