"""Regenerate docs/pole_limits.png: T, delta_psi and the friction needed across the pole level
of examples/pole.toml (paper body, M3 = 1, C2 = -0.3, h = 1.1). Run: python docs/pole_limits.py"""

from pathlib import Path

from rollingtop import SphericalTop
from rollingtop.plot import save_figure
from rollingtop.plot.pole_limits import pole_limits_figure

if __name__ == "__main__":
    body = SphericalTop(R=1.0, m=1.0, g=1.0, a3=0.1, I1=0.3, I3=0.5)
    fig = pole_limits_figure(body, M3=1.0, C2=-0.3, h=1.1)
    out = save_figure(fig, Path(__file__).with_name("pole_limits.png"), dpi=150)
    print(f"wrote {out}")
