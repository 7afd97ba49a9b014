"""Figures of rollingtop.plot.section: the section and the indicators' time series."""

from rollingtop.chaos import chaos_indicators, poincare_section
from rollingtop.plot import save_figure
from rollingtop.plot.section import indicators_figure, section_figure

from ..chaos.conftest import chaotic  # noqa: F401 (fixture)


def test_section_and_indicator_figures_are_written(chaotic, tmp_path):  # noqa: F811
    body, model, y0 = chaotic
    ds = poincare_section(body, model, y0, crossings=20, trajectories=2)
    fig = section_figure(ds)
    assert len(fig.axes[0].lines) == 2
    save_figure(fig, tmp_path / "s.png")
    result = chaos_indicators(body, model, y0, t_end=50.0, samples=10)
    save_figure(indicators_figure(result), tmp_path / "c.png")
    assert (tmp_path / "s.png").stat().st_size > 0
    assert (tmp_path / "c.png").stat().st_size > 0
