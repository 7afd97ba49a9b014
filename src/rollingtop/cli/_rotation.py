"""``rollingtop rotation``: rotation numbers and the classes of motion in absolute space."""

from __future__ import annotations

import json
from typing import Any

import click

from rollingtop.cli import _output
from rollingtop.cli._errors import BadInput
from rollingtop.cli._options import json_option, parse_range, scenario_argument

__all__ = ["rotation"]


@click.command()
@scenario_argument
@json_option
@click.option(
    "-o",
    "--output",
    type=click.Path(),
    default=None,
    help="Also draw the map and a path of each class: FIG.png, .svg, .pdf.",
)
@click.option(
    "--c2-range",
    default=None,
    metavar="LO,HI",
    help="C2 window (default: the bifurcation diagram's).",
)
@click.option(
    "--axis-range",
    default=None,
    metavar="LO,HI",
    help="Another reduced model's axis window (smooth: C1, rough: jellett; default "
    "its value +- max(1, |value|)).",
)
@click.option(
    "--h-range",
    default=None,
    metavar="LO,HI",
    help="h window (default: the bifurcation diagram's).",
)
@click.option(
    "--resolution",
    type=int,
    default=41,
    show_default=True,
    help="Grid points along C2 and along h.",
)
def rotation(
    scenario: str,
    as_json: bool,
    output: str | None,
    c2_range: str | None,
    h_range: str | None,
    resolution: int,
    axis_range: str | None,
) -> None:
    """Rotation numbers N = Delta psi / 2 pi over the (C2, h) plane at the scenario's (M3, C1):
    where the body drifts (N an integer), where its paths close (N = p/q) and where they fill
    an annulus (quasi-periodic), with the limit of N at each centre of the scenario's level."""
    from rollingtop.reduction import LevelSet, steady_motions
    from rollingtop.reduction.bifurcation import bifurcation_diagram
    from rollingtop.reduction.rotation import (
        centre_rotation_number,
        class_examples,
        rotation_map,
    )
    from rollingtop.scenario import load_scenario

    if not 3 <= resolution <= 1000:
        raise BadInput(f"--resolution {resolution}: must be between 3 and 1000")
    c2_window, h_window = parse_range("--c2-range", c2_range), parse_range("--h-range", h_range)
    if output is not None:
        from rollingtop.io import check_output_path
        from rollingtop.plot import FIGURE_SUFFIXES

        check_output_path(output, FIGURE_SUFFIXES)
    sc = load_scenario(scenario)
    from rollingtop.reduction.models import closed_form_diagram

    if sc.model.reduction and not closed_form_diagram(sc.model):
        if c2_range is not None:
            raise BadInput(
                f"--c2-range: the paper's model's window; the {sc.model.name} "
                "model's is --axis-range"
            )
        _other_model(
            sc, as_json, output, parse_range("--axis-range", axis_range), h_window, resolution
        )
        return
    if axis_range is not None:
        raise BadInput(
            "--axis-range: another reduced model's window; the meridian model's is --c2-range"
        )
    M3, C1, C2 = sc.level_integrals("`rollingtop rotation`")
    diagram = bifurcation_diagram(sc.body, M3, C1, C2_range=c2_window, h_range=h_window)
    c2w = (float(diagram.C2_grid[0]), float(diagram.C2_grid[-1]))
    hw = (float(diagram.h_grid[0]), float(diagram.h_grid[-1]))
    with _output.counting("rotation numbers", resolution) as progress:
        rmap = rotation_map(
            sc.body,
            M3,
            C1,
            C2_range=c2w,
            h_range=hw,
            resolution=(resolution, resolution),
            progress=progress,
        )
    if rmap.to_dict()["N_range"] is None:
        raise BadInput(
            f"no periodic orbit in the window C2 in [{c2w[0]:.6g}, {c2w[1]:.6g}], "
            f"h in [{hw[0]:.6g}, {hw[1]:.6g}]: widen --h-range or "
            "--c2-range"
        )
    examples = class_examples(sc.body, rmap)
    summary: dict[str, Any] = {**rmap.to_dict(), "classes": examples}
    if C2 is not None:
        level = LevelSet(sc.body, M3, C1, C2)
        summary["centres"] = [
            {"C2": C2, "gamma3": m.gamma3, "h": m.U, "N": centre_rotation_number(m)}
            for m in steady_motions(level)
            if m.type == "center"
        ]
    if output is not None:
        from rollingtop.plot import save_figure
        from rollingtop.plot.rotation import rotation_figure

        save_figure(rotation_figure(diagram, rmap, examples), output)
    if as_json:
        click.echo(json.dumps(summary))
        return
    console = _output.console()
    lo, hi = summary["N_range"]
    console.print(
        f"rotation number N over C2 in [{c2w[0]:.5g}, {c2w[1]:.5g}], h in "
        f"[{hw[0]:.5g}, {hw[1]:.5g}]: N from {lo:.6g} to {hi:.6g}; "
        f"{sum(r['q'] == 1 for r in rmap.resonances)} points with N an integer, "
        f"{sum(r['q'] > 1 for r in rmap.resonances)} with N = p/2 or p/3"
    )
    for name, ex in examples.items():
        frac = "" if ex["q"] in (None, 1) else f" = {ex['p']}/{ex['q']}"
        console.print(f"{name}: N = {ex['N']:.6g}{frac} at C2 = {ex['C2']:.6g}, h = {ex['h']:.6g}")
    for c in summary.get("centres", []):
        console.print(f"centre at gamma3 = {c['gamma3']:.6g} (C2 = {c['C2']:g}): N -> {c['N']:.6g}")
    if output is not None:
        click.echo(f"wrote {output}")


def _other_model(
    sc: Any, as_json: bool, output: str | None, window: Any, h_window: Any, resolution: int
) -> None:
    """``rotation`` for a reduced model other than the paper's: ``N`` over its axis integral and
    ``h`` (:func:`rollingtop.reduction.classify.rotation_grid`)."""
    import numpy as np

    from rollingtop.reduction.classify import rotation_grid
    from rollingtop.reduction.rotation import classify_rotation

    level = sc.level_set()
    with _output.counting("rotation numbers", resolution) as progress:
        grid = rotation_grid(
            level, window=window, h_range=h_window, resolution=resolution, progress=progress
        )
    summary = grid.to_dict()
    if summary["N_range"] is None:
        raise BadInput(
            f"no periodic orbit in the window of {grid.axis} and h: widen --h-range or --c2-range"
        )
    finite = grid.N[np.isfinite(grid.N)]
    kinds = [classify_rotation(float(n))["class"] for n in finite]
    summary["classes"] = {k: kinds.count(k) for k in sorted(set(kinds))}
    if output is not None:
        from rollingtop.plot import save_figure
        from rollingtop.plot.classification import rotation_grid_figure

        save_figure(rotation_grid_figure(grid), output)
    if as_json:
        click.echo(json.dumps(summary))
        return
    lo, hi = summary["N_range"]
    counts = ", ".join(f"{v} {k}" for k, v in summary["classes"].items())
    _output.console().print(
        f"rotation number N of the {grid.model} model over {grid.axis} in "
        f"[{grid.x[0]:.5g}, {grid.x[-1]:.5g}], h in [{grid.h[0]:.5g}, {grid.h[-1]:.5g}]: "
        f"N from {lo:.6g} to {hi:.6g}; orbits by class: {counts}"
    )
    if output is not None:
        click.echo(f"wrote {output}")
