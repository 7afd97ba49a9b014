"""``rollingtop explore``: the reduced system in the browser (:mod:`rollingtop.explore`)."""

from __future__ import annotations

import click

from rollingtop.cli._errors import BadInput

__all__ = ["explore"]

_LOOKS = ("plain", "roller", "shell", "skates")


@click.command()
@click.argument("scenario", required=False, type=click.Path(dir_okay=False))
@click.option(
    "--port",
    default=5006,
    show_default=True,
    type=click.IntRange(1, 65535),
    help="Port to listen on.",
)
@click.option(
    "--host",
    default="127.0.0.1",
    show_default=True,
    help="Address to listen on (another than this machine's loopback serves the page, "
    "which has no authentication, to the network).",
)
@click.option("--no-browser", is_flag=True, help="Do not open a browser.")
@click.option(
    "--look",
    type=click.Choice(_LOOKS),
    default="plain",
    show_default=True,
    help="Device drawn beside a trajectory's path (the page can change it).",
)
def explore(scenario: str | None, port: int, host: str, no_browser: bool, look: str) -> None:
    """Explore a scenario's level in the browser: sliders for the body and the level, U, the
    phase portrait, the bifurcation diagram; a click on the portrait starts a trajectory.

    Without SCENARIO, the paper's Fig. 5 level. Prints one line, `serving at URL`, once the
    page is ready; Ctrl-C stops the server. Needs the explore extra
    (pip install 'rollingtop[explore]').
    """
    try:
        import panel  # noqa: F401
    except ImportError:
        raise BadInput("explore needs Panel: pip install 'rollingtop[explore]'") from None
    from rollingtop.explore.server import LOOPBACK, serve
    from rollingtop.explore.view import default_scenario, state_from_scenario
    from rollingtop.scenario import load_scenario

    sc = load_scenario(scenario) if scenario is not None else default_scenario()
    base = state_from_scenario(sc)
    if look != "plain":
        from rollingtop.devices import check_device

        check_device(look, sc.model)
    if host not in LOOPBACK:
        click.echo(
            f"rollingtop: warning: serving on {host}: the page has no authentication; "
            "anyone who reaches this address can use it",
            err=True,
        )
    serve(base, port=port, host=host, open_browser=not no_browser, look=look, echo=click.echo)
