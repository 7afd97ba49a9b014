"""Figures (matplotlib). Imported only by the command line and by users, never by the numerics."""

from rollingtop.plot._save import FIGURE_SUFFIXES, save_figure
from rollingtop.plot.portrait import default_h_levels, phase_portrait

__all__ = ["FIGURE_SUFFIXES", "default_h_levels", "phase_portrait", "save_figure"]
