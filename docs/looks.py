"""Regenerate docs/look_roller.png, docs/look_shell.png and docs/look_skates.png: one frame of
`rollingtop animate examples/paper.toml --look roller|shell|skates`, the three devices of the
paper's Sec. 1 (Figs. 1-3) that realise its constraint, each moving as the paper's motion makes
it (the rollers turning with the slip, the shell against its rotor).
Run: python docs/looks.py"""

from pathlib import Path

from rollingtop import simulate
from rollingtop.plot import save_figure
from rollingtop.plot.animation import frame_figure
from rollingtop.scenario import load_scenario

#: The time of each frame: where the device reads best from the animation's camera.
TIMES = {"roller": 4.0, "shell": 4.0, "skates": 1.0}

if __name__ == "__main__":
    examples = Path(__file__).parents[1] / "examples"
    # dense samples: the rollers' and the shell's turns are integrated over them
    traj = simulate(load_scenario(examples / "paper.toml"), t_end=5.0, samples=501)
    for look, t in TIMES.items():
        fig = frame_figure(traj, t, look=look, size=(5.0, 5.0))
        out = save_figure(fig, Path(__file__).with_name(f"look_{look}.png"), dpi=110)
        print(f"wrote {out}")
