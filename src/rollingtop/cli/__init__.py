"""Command-line interface: thin commands that parse, call the library, print or write.

Every input error is reported as one line on stderr with exit status 2 and no traceback
(:mod:`rollingtop.cli._errors`). One module per command or family of commands:

- :mod:`._simulate`: ``simulate``;
- :mod:`._level`: ``equilibria``, ``orbits``, ``portrait`` (the reduction);
- :mod:`._bifurcation`: ``bifurcation`` (the classification of the reduced motions);
- :mod:`._classification`: ``compare-classification`` (every reduced model side by side);
- :mod:`._rotation`: ``rotation`` (rotation numbers, classes of motion in absolute space);
- :mod:`._stability`: ``stability`` (vertical spins under one model or every one);
- :mod:`._atlas`: ``atlas`` (the classification over a parameter grid, on Dask);
- :mod:`._figures`: ``path``, ``plot``, ``compare``, ``animate``;
- :mod:`._ensemble`: ``ensemble``;
- :mod:`._chaos`: ``section``, ``chaos`` (Poincare sections, Lyapunov exponent and MEGNO);
- :mod:`._periodic`: ``periodic`` (relative periodic orbits on a level, their multipliers);
- :mod:`._continuation`: ``continue`` (an orbit followed in a parameter, its bifurcations);
- :mod:`._basins`: ``basins`` (which attracting orbit each start of a section grid reaches);
- :mod:`._verify`: ``verify``;
- :mod:`._warmup`: ``warmup``.
"""

from __future__ import annotations

from rollingtop.cli._app import cli
from rollingtop.cli._atlas import atlas
from rollingtop.cli._basins import basins
from rollingtop.cli._bifurcation import bifurcation
from rollingtop.cli._chaos import chaos, section
from rollingtop.cli._classification import compare_classification
from rollingtop.cli._continuation import continue_
from rollingtop.cli._ensemble import ensemble
from rollingtop.cli._explore import explore
from rollingtop.cli._figures import animate, compare, path, plot
from rollingtop.cli._level import equilibria, orbits, portrait
from rollingtop.cli._periodic import periodic
from rollingtop.cli._rotation import rotation
from rollingtop.cli._simulate import simulate
from rollingtop.cli._stability import stability
from rollingtop.cli._verify import verify
from rollingtop.cli._warmup import warmup

__all__ = ["cli", "main"]

for _command in (
    simulate,
    equilibria,
    orbits,
    portrait,
    bifurcation,
    compare_classification,
    rotation,
    stability,
    atlas,
    path,
    plot,
    compare,
    animate,
    ensemble,
    section,
    chaos,
    periodic,
    continue_,
    basins,
    explore,
    verify,
    warmup,
):
    cli.add_command(_command)


def main(argv: list[str] | None = None) -> None:
    """Console-script entry point: ``rollingtop [ARGS]`` (``argv``: the arguments, default
    ``sys.argv[1:]``). Exits with the command's status."""
    cli.main(args=argv, prog_name="rollingtop")
