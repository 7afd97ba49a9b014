"""``rollingtop bifurcation``: the classification of the reduced motions at fixed ``(M3, C1)``."""

from __future__ import annotations

import json
from typing import Any

import click

from rollingtop.cli import _output
from rollingtop.cli._errors import BadInput
from rollingtop.cli._options import json_option, parse_range, scenario_argument

__all__ = ["bifurcation"]


def _table(summary: dict[str, Any]) -> Any:
    from rich.table import Table

    table = Table(
        title=f"regions of the (C2, h) plane, M3 = {summary['M3']:g}, C1 = {summary['C1']:g}"
    )
    text = ("region", "what a level holds", "centres at gamma3")
    for col in (*text, "C2", "h", "C2 from", "to"):
        table.add_column(col, justify="left" if col in text else "right")
    for r in summary["regions"]:
        where = " | ".join(", ".join(f"{g:.3f}" for g in orbit) for orbit in r["centre_gamma3"])
        table.add_row(
            r["name"],
            r["label"],
            where,
            f"{r['C2']:.5g}",
            f"{r['h']:.5g}",
            f"{r['C2_range'][0]:.5g}",
            f"{r['C2_range'][1]:.5g}",
        )
    return table


@click.command()
@scenario_argument
@json_option
@click.option(
    "-o",
    "--output",
    type=click.Path(),
    default=None,
    help="Also draw the diagram: FIG.png, .svg or .pdf.",
)
@click.option(
    "--c2-range", default=None, metavar="LO,HI", help="C2 window (default: around the folds)."
)
@click.option(
    "--h-range",
    default=None,
    metavar="LO,HI",
    help="h window (default: min U to above the saddles).",
)
@click.option(
    "--c1-range",
    default=None,
    metavar="LO,HI",
    help="C1 window of the steady-motion count (default +-2 max |M3|,|C1|).",
)
@click.option(
    "--axis-range",
    default=None,
    metavar="LO,HI",
    help="Another reduced model's axis window (smooth: C1, rough: jellett, "
    "rubber: rubber_spin, shell-rotor: C2; default its value +- "
    "max(1, |value|)).",
)
def bifurcation(
    scenario: str,
    as_json: bool,
    output: str | None,
    c2_range: str | None,
    h_range: str | None,
    c1_range: str | None,
    axis_range: str | None,
) -> None:
    """Bifurcation diagram of the reduced system at the scenario's (M3, C1).

    M3 and C1 come from [level] (its other keys are ignored), else from the initial state.
    Prints the folds (where a centre and a saddle are born) and the regions of the (C2, h) plane
    with what a level in each holds, and the number of steady motions over (C1, C2).

    The other reduced models get their critical values along one integral of their level
    instead (smooth: C1, rough: jellett, rubber: rubber_spin, shell-rotor: C2), with the number
    of steady motions along it (--axis-range; rollingtop.reduction.classify.critical_values).
    That integral may be left out of [level]: it is then scanned around 0.
    """
    from rollingtop.reduction.bifurcation import bifurcation_diagram, steady_count_map
    from rollingtop.scenario import load_scenario

    ranges = {
        "C2": parse_range("--c2-range", c2_range),
        "h": parse_range("--h-range", h_range),
        "C1": parse_range("--c1-range", c1_range),
    }
    if output is not None:
        from rollingtop.io import check_output_path
        from rollingtop.plot import FIGURE_SUFFIXES

        check_output_path(output, FIGURE_SUFFIXES)
    sc = load_scenario(scenario)
    from rollingtop.reduction.models import closed_form_diagram

    if sc.model.reduction and not closed_form_diagram(sc.model):
        given = [
            f
            for f, v in (("--c2-range", c2_range), ("--h-range", h_range), ("--c1-range", c1_range))
            if v is not None
        ]
        if given:
            raise BadInput(
                f"{', '.join(given)}: the paper's model's windows; the "
                f"{sc.model.name} model's is --axis-range"
            )
        _other_model(sc, as_json, output, parse_range("--axis-range", axis_range))
        return
    if axis_range is not None:
        raise BadInput(
            "--axis-range: another reduced model's window; the meridian model's are "
            "--c2-range, --h-range and --c1-range"
        )
    M3, C1, C2 = sc.level_integrals("`rollingtop bifurcation`")
    diagram = bifurcation_diagram(sc.body, M3, C1, C2_range=ranges["C2"], h_range=ranges["h"])
    width = 2.0 * max(abs(M3), abs(C1), 1e-3)
    c1_window = ranges["C1"] or (-width, width)
    fold_c2 = [f.C2 for f in diagram.folds]
    lo, hi = diagram.C2_grid[0], diagram.C2_grid[-1]
    counts = steady_count_map(
        sc.body, M3, C1_range=c1_window, C2_range=(min([lo, *fold_c2]), max([hi, *fold_c2]))
    )
    summary = {**diagram.to_dict(), "C2": C2, "steady_count": counts.to_dict()}
    if output is not None:
        from rollingtop.plot import save_figure
        from rollingtop.plot.bifurcation import bifurcation_figure

        save_figure(bifurcation_figure(diagram, counts, mark_C2=C2), output)
    if as_json:
        click.echo(json.dumps(summary))
        return
    console = _output.console()
    folds = (
        ", ".join(
            f"C2 = {f['C2']:.10g} at gamma3 = {f['gamma3']:.10g}, h = {f['h']:.10g}"
            for f in summary["folds"]
        )
        or "none"
    )
    console.print(f"folds: {folds}")
    console.print(_table(summary))
    if output is not None:
        click.echo(f"wrote {output}")


def _other_model(
    sc: Any, as_json: bool, output: str | None, window: tuple[float, float] | None
) -> None:
    """``bifurcation`` for a reduced model other than the paper's: its critical values along
    its axis integral (:func:`rollingtop.reduction.classify.critical_values`)."""
    from dataclasses import replace

    from rich.table import Table

    from rollingtop.reduction.classify import AXES, critical_values

    axis = AXES[sc.model.name]
    scanned_only = sc.level is not None and getattr(sc.level, axis, 0.0) is None
    if scanned_only:
        # the scanned integral left out of [level] (the shell-rotor pair's C2, as the paper's):
        # scanned around 0, over twice the size of the level's other integrals
        level = replace(sc.level, **{axis: 0.0}).level_set(sc.body, sc.model)
        size = max([1.0, *(2.0 * abs(v) for k, v in level.values().items() if k != axis)])
        window = window or (-size, size)
    else:
        level = sc.level_set()
    cv = critical_values(level, window=window, n=241)
    if output is not None:
        from rollingtop.plot import save_figure
        from rollingtop.plot.classification import critical_values_figure

        save_figure(critical_values_figure(cv, level, mark=not scanned_only), output)
    if as_json:
        click.echo(json.dumps(cv.to_dict()))
        return
    fixed = ", ".join(f"{k} = {v:g}" for k, v in cv.fixed.items())
    table = Table(
        title=f"steady motions of the {cv.model} model along {cv.axis}"
        + (f" ({fixed})" if fixed else "")
    )
    for col in (f"{cv.axis} from", "to", "steady motions"):
        table.add_column(col, justify="right")
    start = 0
    for i in range(1, cv.x.size + 1):
        if i == cv.x.size or cv.count[i] != cv.count[start]:
            n = int(cv.count[start])
            table.add_row(
                f"{cv.x[start]:.6g}",
                f"{cv.x[i - 1]:.6g}",
                "refused (pole level)" if n < 0 else str(n),
            )
            start = i
    _output.console().print(table)
    if output is not None:
        click.echo(f"wrote {output}")
