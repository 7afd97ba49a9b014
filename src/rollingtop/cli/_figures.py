"""The figure commands: ``path``, ``plot``, ``compare`` and ``animate``."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import click

from rollingtop.cli import _output
from rollingtop.cli._errors import BadInput
from rollingtop.cli._options import figure_output, scenario_argument, t_end_option
from rollingtop.cli._simulate import run_scenario

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from rollingtop.scenario import Scenario
    from rollingtop.trajectory import Trajectory

__all__ = ["LOOKS", "MAX_FRAMES", "MAX_PERIODS", "animate", "compare", "path", "plot"]

#: The animation's looks (:data:`rollingtop.plot.looks.LOOKS`, named here so that the command
#: line starts without matplotlib; a test holds them equal).
LOOKS = ("plain", "roller", "shell", "skates")
#: Bounds of the figure and animation commands' own options (samples and frames they imply).
MAX_PERIODS = 1e5
MAX_FRAMES = 100_000


def _figure_scenario(scenario: str, output: str, **overrides: Any) -> Scenario:
    """Check the figure's output path first (nothing runs for an unwritable one), then load."""
    from rollingtop.io import check_output_path
    from rollingtop.plot import FIGURE_SUFFIXES
    from rollingtop.scenario import load_scenario

    check_output_path(output, FIGURE_SUFFIXES)
    return load_scenario(scenario).with_overrides(**overrides)


def _save_figure(fig: Figure, output: str) -> None:
    from rollingtop.plot import save_figure

    save_figure(fig, output)
    click.echo(f"wrote {output}")


@click.command()
@scenario_argument
@figure_output
@click.option(
    "--periods",
    type=float,
    default=30.0,
    show_default=True,
    help="Periods of gamma3 to draw (orbits of a reduction; else the scenario's t_end).",
)
@click.option("--t-end", type=float, default=None, help="End time (overrides --periods).")
def path(scenario: str, output: str, periods: float, t_end: float | None) -> None:
    """Contact-point and CoM paths on the plane, with the once-per-period points and, for an
    orbit of the reduction, the predicted circle (bounded) or drift."""
    from rollingtop.plot.paths import path_figure
    from rollingtop.survey import motion_period_map

    if not 0 < periods <= MAX_PERIODS:
        raise BadInput(f"--periods {periods:g} must lie in (0, {MAX_PERIODS:g}]")
    sc = _figure_scenario(scenario, output)
    pm = motion_period_map(sc)
    if t_end is None and pm is not None:
        t_end = periods * pm.period
    sc = sc.with_overrides(t_end=t_end, samples=max(2001, int(200 * periods)))
    traj = run_scenario(sc, events="w_tau", event_direction=1)
    _save_figure(path_figure(traj, pm), output)


@click.command()
@scenario_argument
@figure_output
@t_end_option
def plot(scenario: str, output: str, t_end: float | None) -> None:
    """Time series: gamma3, the integrals' drift and the contact reactions."""
    from rollingtop.plot.paths import timeseries_figure

    sc = _figure_scenario(scenario, output, t_end=t_end)
    _save_figure(timeseries_figure(run_scenario(sc)), output)


def run_models(sc: Scenario) -> dict[str, Trajectory]:
    """:func:`rollingtop.simulate_models` of ``sc`` under every registered model, with one
    progress bar per model on a terminal and the runs' warnings as lines."""
    from rollingtop.contact import models_for
    from rollingtop.simulate import simulate_models

    models = models_for(sc.body)
    bar = _output.progress_bar("integrating {task.description}")
    if bar is None:
        return _output.with_warnings_reported(lambda: simulate_models(sc, models))
    with bar:
        tasks = {m.name: bar.add_task(m.name, total=sc.integration.t_end) for m in models}

        def progress(name: str, t: float) -> None:
            bar.update(tasks[name], completed=t)

        return _output.with_warnings_reported(
            lambda: simulate_models(sc, models, progress=progress)
        )


@click.command()
@scenario_argument
@figure_output
@t_end_option
def compare(scenario: str, output: str, t_end: float | None) -> None:
    """The scenario's initial state under every contact model: paths and integrals overlaid
    (each model's state is the scenario's, projected on its constraints)."""
    from rollingtop.plot.paths import compare_figure

    sc = _figure_scenario(scenario, output, t_end=t_end)
    _save_figure(compare_figure(run_models(sc)), output)


@click.command()
@scenario_argument
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
@click.option(
    "--look",
    type=click.Choice(LOOKS),
    default="plain",
    show_default=True,
    help="plain wireframe, or the paper's device that realises the meridian constraint: "
    "roller-bearing sphere, shell with a rotor, sphere of skates (meridian model; the "
    "shell-rotor model: the shell, turning with its own spin).",
)
def animate(
    scenario: str, output: str, fps: int, duration: float, speed: float, camera: str, look: str
) -> None:
    """3D animation of the rolling sphere (meridians and axis show the spin, contact trail),
    or of a device that realises the paper's constraint (--look)."""
    from rollingtop.io import check_output_path
    from rollingtop.plot.animation import ANIMATION_SUFFIXES
    from rollingtop.plot.animation import animate as render
    from rollingtop.scenario import load_scenario

    check_output_path(output, ANIMATION_SUFFIXES)
    if not duration * fps <= MAX_FRAMES:
        raise BadInput(
            f"--duration {duration:g} at --fps {fps} makes more than {MAX_FRAMES} frames"
        )
    n_frames = int(round(duration * fps))
    t_end = (n_frames - 1) / fps * speed if n_frames > 1 else speed / fps
    sc = load_scenario(scenario).with_overrides(t_end=t_end, samples=max(2, 4 * n_frames))
    if look != "plain":
        from rollingtop.devices import check_device

        check_device(look, sc.model)  # before anything runs
    traj = run_scenario(sc)
    with _output.counting("rendering", n_frames) as progress:
        render(
            traj,
            output,
            look=look,
            fps=fps,
            duration=duration,
            speed=speed,
            camera=camera,
            progress=progress,
        )
    click.echo(f"wrote {output} ({n_frames} frames)")
