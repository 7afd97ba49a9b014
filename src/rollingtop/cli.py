"""Command-line interface: thin wrappers that parse, call the library, print or write.

Every input error is reported as one line on stderr with exit status 2 and no traceback.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import re
import sys
import warnings

import click

from rollingtop._errors import (
    ContactLostWarning,
    IntegrationError,
    Interrupted,
    RollingTopError,
)
from rollingtop.io import WriteFailed

EXIT_USAGE = 2
_NO_ARGS_IS_HELP = getattr(click.exceptions, "NoArgsIsHelpError", ())
EXIT_FAILURE = 1
#: Bounds of the figure and animation commands' own options (samples and frames they imply).
MAX_PERIODS = 1e5
MAX_FRAMES = 100_000


_LINE_BREAKS = {
    ord(c): c.encode("unicode_escape").decode() for c in "\n\r\v\f\x1c\x1d\x1e\x85\u2028\u2029"
}


_LONG_QUOTE = re.compile(r"'([^']{80})[^']+'")
_MAX_MESSAGE = 2000


def _one_line(message: str) -> str:
    """``message`` with line breaks escaped and long quoted values cut (click's messages quote
    the whole value given): every report is one line of reasonable length."""
    message = _LONG_QUOTE.sub(r"'\1…'", message.strip().translate(_LINE_BREAKS))
    return message if len(message) <= _MAX_MESSAGE else message[: _MAX_MESSAGE - 1] + "…"


def _note(message: str) -> None:
    click.echo(f"rollingtop: note: {_one_line(message)}", err=True)


def _fail(message: str, status: int = EXIT_USAGE) -> None:
    click.echo(f"rollingtop: error: {_one_line(message)}", err=True)
    sys.exit(status)


@contextlib.contextmanager
def _warnings_as_lines():
    """Python warnings that reach the command line (numerical ones from NumPy, say) as one
    ``rollingtop: warning:`` line each, naming where they arose, instead of two raw lines."""
    previous = warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):
        where = f"{os.path.basename(filename)}:{lineno}"
        click.echo(f"rollingtop: warning: {_one_line(f'{message} ({where})')}", err=True)

    warnings.showwarning = show
    try:
        yield
    finally:
        warnings.showwarning = previous


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="rollingtop")
@click.pass_context
def cli(ctx: click.Context) -> None:
    """Rolling spherical tops under nonholonomic constraints (Kilin & Ivanova 2023)."""
    ctx.with_resource(_warnings_as_lines())


def _progress_bar():
    """A rich progress bar on stderr when it is a terminal, else ``None``."""
    from rich.console import Console
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    console = Console(stderr=True)
    if not console.is_terminal:
        return None
    return Progress(
        TextColumn("integrating"),
        BarColumn(),
        TextColumn("t = {task.completed:.4g} / {task.total:.4g}"),
        TimeRemainingColumn(),
        console=console,
        transient=True,
    )


def _console():
    """Console on stdout; when stdout is not a terminal, wide enough that no table is cut."""
    from rich.console import Console

    console = Console()
    return console if console.is_terminal else Console(width=160)


def _integrals_table(summary: dict):
    from rich.table import Table

    table = Table(title=f"{summary['model']} model, t = 0 .. {summary['t_end']:g}")
    for col in ("integral", "initial", "final", "max |drift|", "relative"):
        table.add_column(col, justify="right" if col != "integral" else "left")
    for name, row in summary["integrals"].items():
        rel = row["max_rel_drift"]
        table.add_row(
            name,
            f"{row['initial']:.15g}",
            f"{row['final']:.15g}",
            f"{row['max_abs_drift']:.2e}",
            "-" if rel is None else f"{rel:.2e}",
        )
    return table


def _print_report(summary: dict) -> None:
    console = _console()
    console.print(_integrals_table(summary))
    c, r, s = summary["constraints"], summary["reactions"], summary["stats"]
    lost = r["contact_lost_at"]
    console.print(
        f"constraints: max |residual| {c['max_abs_residual']:.2e}, "
        f"orthonormality error {c['orthonormality_max_error']:.2e}\n"
        f"reactions: min normal force {r['min_normal_force']:.6g}, friction coefficient needed "
        f"{r['max_friction_ratio']:.6g}"
        + ("" if lost is None else f", CONTACT LOST at t = {lost:.6g}")
        + f"\nsteps {s['steps']} (+{s['rejected_steps']} rejected), {s['rhs_evals']} rhs "
        f"evaluations, {s['wall_time_s']:.3f} s (+{s['compile_time_s']:.2f} s compile/load)",
        highlight=False,
    )


@cli.command()
@click.argument("scenario", type=click.Path(dir_okay=False))
@click.option("--t-end", type=float, default=None, help="End time (overrides the scenario).")
@click.option("--rtol", type=float, default=None, help="Relative tolerance.")
@click.option("--atol", type=float, default=None, help="Absolute tolerance.")
@click.option("--samples", type=int, default=None, help="Number of output samples.")
@click.option(
    "--model",
    type=str,
    default=None,
    help="Contact model, overriding the scenario's: meridian, smooth, rough.",
)
@click.option(
    "-o", "--output", type=click.Path(), default=None, help="Write samples to OUT.nc or OUT.csv."
)
@click.option("--json", "as_json", is_flag=True, help="Print exactly one JSON object on stdout.")
def simulate(scenario, t_end, rtol, atol, samples, model, output, as_json):
    """Simulate SCENARIO.toml and print its integrals, constraints and reactions."""
    from rollingtop.io import check_output_path
    from rollingtop.simulate import simulate as run
    from rollingtop.trajectory import OUTPUT_SUFFIXES

    if output is not None:
        check_output_path(output, OUTPUT_SUFFIXES)
    from rollingtop.scenario import load_scenario
    from rollingtop.simulate import switch_model

    sc = load_scenario(scenario).with_overrides(t_end=t_end, rtol=rtol, atol=atol, samples=samples)
    if model is not None and model != sc.model.name:
        sc, change = switch_model(sc, model)
        dv, dw = math.hypot(*change[:3]), math.hypot(*change[3:])
        _note(
            f"initial state projected onto the {sc.model.name} model's constraints (velocities "
            f"changed by |dv| = {dv:.3g}, |d omega| = {dw:.3g})"
        )
    traj = _run_with_progress(run, sc)
    if output is not None:
        traj.save(output)
    summary = traj.summary()
    if as_json:
        click.echo(json.dumps(summary))
    else:
        _print_report(summary)
        if output is not None:
            click.echo(f"wrote {output}")


def _level_of(scenario_path: str):
    from rollingtop.scenario import load_scenario

    sc = load_scenario(scenario_path)
    return sc, sc.level_set()


def _level_json(level, **extra) -> dict:
    return {"M3": level.M3, "C1": level.C1, "C2": level.C2, "pole": level.pole, **extra}


def _steady_table(level, motions):
    from rich.table import Table

    spin = level.M3 / level.body.I3
    table = Table(title=f"steady motions on {level.describe()} (spin w3 = {spin:.7g})")
    cols = ("gamma3", "U", "type", "omega", "period", "psi'", "|v_CoM|", "CoM radius")
    for col in cols:
        table.add_column(col, justify="left" if col == "type" else "right")

    def num(x):
        return "-" if x is None or x != x else f"{x:.7g}"

    for m in motions:
        table.add_row(num(m.gamma3), num(m.U), m.type, num(m.frequency), num(m.period),
                      num(m.precession_rate), num(m.com_speed), num(m.com_radius))  # fmt: skip
    return table


@cli.command()
@click.argument("scenario", type=click.Path(dir_okay=False))
@click.option("--json", "as_json", is_flag=True, help="Print exactly one JSON object on stdout.")
def equilibria(scenario, as_json):
    """Steady motions (critical points of U) on the scenario's level set, sorted by gamma3.

    The level set is the scenario's [level] table, else the one of its initial state.
    """
    from rollingtop.reduction import steady_motions

    _, level = _level_of(scenario)
    motions = steady_motions(level)
    if as_json:
        click.echo(json.dumps({"level": _level_json(level),
                               "equilibria": [m.to_dict() for m in motions]}))  # fmt: skip
    else:
        _console().print(_steady_table(level, motions))


@cli.command()
@click.argument("scenario", type=click.Path(dir_okay=False))
@click.option("--h", "h", type=float, default=None, help="Reduced energy h (overrides [level]).")
@click.option("--json", "as_json", is_flag=True, help="Print exactly one JSON object on stdout.")
def orbits(scenario, h, as_json):
    """Orbits on the level set (M3, C1, C2, h): turning points and periods, sorted by gamma3_min."""
    from rollingtop.absolute import period_map
    from rollingtop.reduction import orbits as find_orbits

    if h is not None and not math.isfinite(h):
        raise click.UsageError(f"--h {h:g} must be finite")
    sc, level = _level_of(scenario)
    h = sc.level_h() if h is None else h
    from rollingtop.reduction.near_pole import near_pole

    found = find_orbits(level, h)
    maps = [period_map(level, h, o) if o.kind == "periodic" else None for o in found]
    poles = [near_pole(level, h, o) for o in found]
    if as_json:
        rows = []
        for o, pm, npl in zip(found, maps, poles, strict=True):
            row = o.to_dict()
            row["near_pole"] = None if npl is None else npl.to_dict()
            if pm is not None:
                row.update(
                    delta_psi=pm.delta_psi,
                    delta_psi_error=pm.delta_psi_error,
                    motion=pm.motion,
                    near_resonant=pm.near_resonant,
                    displacement=list(pm.displacement),
                )
                if pm.motion == "bounded":
                    row.update(center=list(pm.center), radius=pm.radius)
                else:
                    row.update(drift_velocity=list(pm.drift_velocity))
            rows.append(row)
        click.echo(json.dumps({"level": _level_json(level, h=h), "orbits": rows}))
        return
    from rich.table import Table

    table = Table(title=f"orbits on {level.describe()}, h = {h:g}")
    cols = (
        "gamma3_min",
        "gamma3_max",
        "period",
        "+-",
        "delta_psi",
        "motion",
        "circle / drift",
        "note",
    )
    for col in cols:
        table.add_column(col, justify="left" if col in ("motion", "note") else "right")
    for o, pm, npl in zip(found, maps, poles, strict=True):
        if pm is None:
            extra = ("-", o.kind, "-")
        elif pm.motion == "bounded":
            extra = (
                f"{pm.delta_psi:.10g}",
                "bounded" + (" (near-resonant)" if pm.near_resonant else ""),
                f"r = {pm.radius:.6g} about ({pm.center[0]:.4g}, {pm.center[1]:.4g})",
            )
        else:
            vx, vy = pm.drift_velocity
            extra = (f"{pm.delta_psi:.10g}", "drifting", f"v = ({vx:.6g}, {vy:.6g})")
        table.add_row(
            f"{o.gamma3_min:.10g}",
            f"{o.gamma3_max:.10g}",
            f"{o.period:.12g}",
            f"{o.period_error:.1e}",
            *extra,
            "; ".join(x for x in (o.note, npl.note() if npl else "") if x),
        )
    # fmt: skip
    _console().print(table)


@cli.command()
@click.argument("scenario", type=click.Path(dir_okay=False))
@click.option("-o", "--output", type=click.Path(), required=True, help="FIG.png, .svg or .pdf.")
@click.option(
    "--h-levels",
    type=str,
    default=None,
    help="Comma-separated energies h of the orbits drawn (default: a spread from the minimum of "
    "U to above the saddles, plus the separatrices).",
)
@click.option("--no-contact", is_flag=True, help="Do not shade where the normal force is < 0.")
def portrait(scenario, output, h_levels, no_contact):
    """Phase portrait (gamma3, w_tau) on the scenario's level set; prints the steady motions."""
    from rollingtop.io import check_output_path
    from rollingtop.plot import FIGURE_SUFFIXES, phase_portrait, save_figure
    from rollingtop.reduction import steady_motions

    check_output_path(output, FIGURE_SUFFIXES)
    levels = None
    if h_levels is not None:
        from rollingtop.scenario import short_repr

        try:
            levels = [float(x) for x in h_levels.split(",") if x.strip()]
        except ValueError:
            raise click.UsageError(
                f"--h-levels {short_repr(h_levels)}: expected comma-separated numbers"
            ) from None
        if not levels:
            raise click.UsageError("--h-levels: no value given")
        if not all(math.isfinite(x) for x in levels):
            raise click.UsageError(f"--h-levels {short_repr(h_levels)}: values must be finite")
    _, level = _level_of(scenario)
    fig = phase_portrait(level, levels, show_contact=not no_contact)
    save_figure(fig, output)
    _console().print(_steady_table(level, steady_motions(level)))
    click.echo(f"wrote {output}")


def _meridian_map(sc):
    """The per-period map of the scenario's motion, when it is a meridian orbit (else None)."""
    from rollingtop.absolute import period_map
    from rollingtop.reduction import LevelSetError, orbits, reduce_state

    if sc.model.name != "meridian" or not sc.body.symmetric:
        return None
    try:
        level, h = sc.level_set(), sc.level_h()
        theta = float(reduce_state(sc.require_state())["theta"])
        found = [o for o in orbits(level, h) if o.theta_min - 1e-9 <= theta <= o.theta_max + 1e-9]
        if not found or found[0].kind != "periodic":
            return None
        return period_map(level, h, found[0])
    except LevelSetError:
        return None


def _run_with_progress(run, sc, **kwargs):
    bar = _progress_bar()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ContactLostWarning)
        if bar is None:
            result = run(sc, **kwargs)
        else:
            with bar:
                task = bar.add_task("integrate", total=sc.integration.t_end)
                result = run(sc, progress=lambda t: bar.update(task, completed=t), **kwargs)
    for w in caught:
        click.echo(f"rollingtop: warning: {w.message}", err=True)
    return result


def _figure_scenario(scenario: str, output: str, **overrides):
    """Check the figure's output path first (nothing runs for an unwritable one), then load."""
    from rollingtop.io import check_output_path
    from rollingtop.plot import FIGURE_SUFFIXES
    from rollingtop.scenario import load_scenario

    check_output_path(output, FIGURE_SUFFIXES)
    return load_scenario(scenario).with_overrides(**overrides)


def _save_figure(fig, output: str) -> None:
    from rollingtop.plot import save_figure

    save_figure(fig, output)
    click.echo(f"wrote {output}")


@cli.command()
@click.argument("scenario", type=click.Path(dir_okay=False))
@click.option("-o", "--output", type=click.Path(), required=True, help="FIG.png, .svg or .pdf.")
@click.option(
    "--periods",
    type=float,
    default=30.0,
    show_default=True,
    help="Periods of gamma3 to draw (meridian orbits; else the scenario's t_end).",
)
@click.option("--t-end", type=float, default=None, help="End time (overrides --periods).")
def path(scenario, output, periods, t_end):
    """Contact-point and CoM paths on the plane, with the once-per-period points and, for a
    meridian orbit, the predicted circle (bounded) or drift."""
    from rollingtop.plot.paths import path_figure
    from rollingtop.simulate import simulate as run

    if not 0 < periods <= MAX_PERIODS:
        raise click.UsageError(f"--periods {periods:g} must lie in (0, {MAX_PERIODS:g}]")
    sc = _figure_scenario(scenario, output)
    pm = _meridian_map(sc)
    if t_end is None and pm is not None:
        t_end = periods * pm.period
    sc = sc.with_overrides(t_end=t_end, samples=max(2001, int(200 * periods)))
    traj = _run_with_progress(run, sc, events="w_tau", event_direction=1)
    _save_figure(path_figure(traj, pm), output)


@cli.command()
@click.argument("scenario", type=click.Path(dir_okay=False))
@click.option("-o", "--output", type=click.Path(), required=True, help="FIG.png, .svg or .pdf.")
@click.option("--t-end", type=float, default=None, help="End time (overrides the scenario).")
def plot(scenario, output, t_end):
    """Time series: gamma3, the integrals' drift and the contact reactions."""
    from rollingtop.plot.paths import timeseries_figure
    from rollingtop.simulate import simulate as run

    sc = _figure_scenario(scenario, output, t_end=t_end)
    _save_figure(timeseries_figure(_run_with_progress(run, sc)), output)


@cli.command()
@click.argument("scenario", type=click.Path(dir_okay=False))
@click.option("-o", "--output", type=click.Path(), required=True, help="FIG.png, .svg or .pdf.")
@click.option("--t-end", type=float, default=None, help="End time (overrides the scenario).")
def compare(scenario, output, t_end):
    """The scenario's initial state under the meridian, smooth and rough models: paths and
    integrals overlaid (each model's state is the scenario's, projected on its constraints)."""
    from rollingtop.plot.paths import compare_figure
    from rollingtop.simulate import simulate_models

    sc = _figure_scenario(scenario, output, t_end=t_end)
    runs = _run_with_progress(lambda s, **kw: simulate_models(s), sc)
    _save_figure(compare_figure(runs), output)


@cli.command()
@click.argument("scenario", type=click.Path(dir_okay=False))
@click.option("-o", "--output", type=click.Path(), required=True, help="roll.mp4 or roll.gif.")
@click.option("--fps", type=click.IntRange(min=1), default=25, show_default=True)
@click.option(
    "--duration",
    type=click.FloatRange(min=0, min_open=True),
    default=8.0,
    show_default=True,
    help="Length of the video in seconds.",
)
@click.option(
    "--speed",
    type=click.FloatRange(min=0, min_open=True),
    default=1.0,
    show_default=True,
    help="Simulated time per second of video.",
)
@click.option(
    "--camera", type=click.Choice(["follow", "fixed"]), default="follow", show_default=True
)
def animate(scenario, output, fps, duration, speed, camera):
    """3D animation of the rolling sphere (meridians and axis show the spin, contact trail)."""
    from rollingtop.io import check_output_path
    from rollingtop.plot.animation import ANIMATION_SUFFIXES
    from rollingtop.plot.animation import animate as render
    from rollingtop.scenario import load_scenario
    from rollingtop.simulate import simulate as run

    check_output_path(output, ANIMATION_SUFFIXES)
    if not duration * fps <= MAX_FRAMES:
        raise click.UsageError(
            f"--duration {duration:g} at --fps {fps} makes more than {MAX_FRAMES} frames"
        )
    n_frames = int(round(duration * fps))
    t_end = (n_frames - 1) / fps * speed if n_frames > 1 else speed / fps
    sc = load_scenario(scenario).with_overrides(t_end=t_end, samples=max(2, 4 * n_frames))
    traj = _run_with_progress(run, sc)
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn

    console = Console(stderr=True)
    if console.is_terminal:
        with Progress(
            TextColumn("rendering"),
            BarColumn(),
            MofNCompleteColumn(),
            console=console,
            transient=True,
        ) as bar:
            task = bar.add_task("render", total=n_frames)
            render(
                traj,
                output,
                fps=fps,
                duration=duration,
                speed=speed,
                camera=camera,
                progress=lambda i, n: bar.update(task, completed=i),
            )
    else:
        render(traj, output, fps=fps, duration=duration, speed=speed, camera=camera)
    click.echo(f"wrote {output} ({n_frames} frames)")


@cli.command()
@click.argument("scenario", type=click.Path(dir_okay=False))
@click.option(
    "--initial",
    "initial_csv",
    type=click.Path(dir_okay=False),
    default=None,
    help="CSV of initial conditions: columns gamma1..3, omega1..3, alpha1..3, "
    "position1..2, v1..3, the model's free components (v_tau, v_horizontal1..2) or "
    "theta; missing ones take the scenario's values.",
)
@click.option(
    "--grid",
    type=str,
    default=None,
    help="Cartesian grid instead of a file: 'omega3=1:3:20,v_tau=-0.5:0.5:50'.",
)
@click.option("-o", "--output", type=click.Path(), default=None, help="Write OUT.nc.")
@click.option("--t-end", type=float, default=None, help="End time (overrides the scenario).")
@click.option("--rtol", type=float, default=None, help="Relative tolerance.")
@click.option("--atol", type=float, default=None, help="Absolute tolerance.")
@click.option(
    "--samples",
    type=click.IntRange(min=2),
    default=None,
    help="Keep this many samples per trajectory in OUT.nc (default: final states).",
)
@click.option(
    "--threads",
    type=click.IntRange(min=1),
    default=None,
    help="Threads (default: all cores; more than the cores are reduced to them, with a note).",
)
@click.option("--json", "as_json", is_flag=True, help="Print exactly one JSON object on stdout.")
def ensemble(scenario, initial_csv, grid, output, t_end, rtol, atol, samples, threads, as_json):
    """Integrate many initial states in parallel (the scenario's body and model)."""
    from rollingtop.ensemble import ensemble_from_scenario, grid_table, read_table
    from rollingtop.io import check_output_path
    from rollingtop.scenario import load_scenario

    if (initial_csv is None) == (grid is None):
        raise click.UsageError("give exactly one of --initial FILE.csv and --grid SPEC")
    if output is not None:
        check_output_path(output, (".nc",))
    sc = load_scenario(scenario).with_overrides(t_end=t_end, rtol=rtol, atol=atol)
    columns = read_table(initial_csv) if initial_csv is not None else grid_table(grid, samples)
    reduced = None
    if threads is not None:
        import numba

        cores = numba.config.NUMBA_NUM_THREADS
        if threads > cores:  # said once the input is known to be good, below
            reduced = f"--threads {threads} is more than the {cores} cores available; used {cores}"
            threads = cores
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn

    console = Console(stderr=True)
    kwargs = dict(samples=samples, threads=threads)
    if console.is_terminal:
        with Progress(
            TextColumn("ensemble"),
            BarColumn(),
            MofNCompleteColumn(),
            console=console,
            transient=True,
        ) as bar:
            task = bar.add_task("ensemble", total=len(next(iter(columns.values()))))
            result = ensemble_from_scenario(
                sc, columns, progress=lambda i, n: bar.update(task, completed=i), **kwargs
            )
    else:
        result = ensemble_from_scenario(sc, columns, **kwargs)
    if reduced is not None:
        _note(reduced)
    if output is not None:
        result.to_netcdf(output)
    summary = result.summary()
    if as_json:
        click.echo(json.dumps(summary))
        return
    click.echo(
        f"{summary['n']} trajectories of the {summary['model']} model to t = {summary['t_end']:g} "
        f"on {summary['threads']} threads: {summary['wall_time_s']:.3f} s "
        f"({summary['trajectories_per_second']:.1f} per second, "
        f"+{summary['compile_time_s']:.2f} s compile/load), {summary['failed']} failed, "
        f"{summary['contact_lost']} lose contact"
    )
    for name, drift in summary["max_rel_drift"].items():
        absolute = summary["max_abs_drift"][name]
        rel = "-" if drift is None else f"{drift:.2e}"
        absolute = "-" if absolute is None else f"{absolute:.2e}"
        click.echo(f"  {name}: max |drift| {absolute}, relative to the largest value {rel}")
    if output is not None:
        click.echo(f"wrote {output}")


@cli.command()
@click.option(
    "--model",
    "models",
    type=click.Choice(["meridian", "smooth", "rough"]),
    multiple=True,
    help="Model(s) to verify (default: all).",
)
@click.option("--json", "as_json", is_flag=True, help="Print exactly one JSON object on stdout.")
def verify(models, as_json):
    """Machine-check the equations' claims with sympy: first integrals, identities, the reduced
    system (3.3) and its invariant measure."""
    try:
        from rollingtop.symbolic import verify as run_claims
    except ImportError as exc:  # pragma: no cover - sympy missing
        raise click.UsageError(
            f"verify needs sympy ({exc}): pip install rollingtop[symbolic]"
        ) from None
    results = run_claims(models or ("meridian", "smooth", "rough"))
    if as_json:
        click.echo(json.dumps({"claims": [r.to_dict() for r in results]}))
    else:
        from rich.table import Table

        table = Table(title="rollingtop verify")
        for col in ("claim", "model", "result", "method", "time (s)"):
            table.add_column(col, justify="right" if col == "time (s)" else "left")
        for r in results:
            colour = "green" if r.result == "proved" else "red"
            table.add_row(
                r.name, r.model, f"[{colour}]{r.result}[/{colour}]", r.method, f"{r.seconds:.2f}"
            )
        _console().print(table)
    if any(r.result != "proved" for r in results):
        sys.exit(EXIT_FAILURE)


def main(argv: list[str] | None = None) -> None:
    """Console-script entry point."""
    from rollingtop._signals import handle_signals

    try:
        with handle_signals():
            cli.main(args=argv, prog_name="rollingtop", standalone_mode=False)
    except _NO_ARGS_IS_HELP as exc:  # click >= 8.2 raises this for a bare ``rollingtop``
        click.echo(exc.format_message())
        sys.exit(0)
    except click.UsageError as exc:
        _fail(exc.format_message())
    except click.exceptions.Abort:
        _fail("aborted", 130)
    except RollingTopError as exc:
        _fail(str(exc))
    except IntegrationError as exc:
        _fail(str(exc), EXIT_FAILURE)
    except Interrupted as exc:
        name = {2: "SIGINT", 15: "SIGTERM"}.get(exc.signum, f"signal {exc.signum}")
        _fail(f"interrupted by {name}; no output was written", 128 + exc.signum)
    except KeyboardInterrupt:
        _fail("interrupted; no output was written", 130)
    except WriteFailed as exc:
        _fail(str(exc), EXIT_FAILURE)
    except OSError as exc:
        _fail(f"{exc.filename or ''}: {exc.strerror or exc}".lstrip(": "), EXIT_FAILURE)


if __name__ == "__main__":  # pragma: no cover
    main()
