"""The shell-rotor pair (rollingtop.contact.shell_rotor) against the paper's meridian model.

1. Convergence: the paper's body as the rotor in a shell of mass = inertia = eps, from the
   rotor state of examples/shell_rotor.toml; the distance from the meridian model's motion at
   t = 10 (axis direction in space, contact point, angular velocity) for eps = 1e-1 .. 1e-14,
   both at rtol 1e-13; the exponent fitted over 1e-3 .. 1e-10. -> docs/shell_convergence.png
2. A real shell (thin, inertia 2/3 mass R^2, mass 10 % and 30 % of the rotor's): Poincare
   the rotor's reduced motion (gamma3, w_tau) and the sections w_tau = 0 of motions started on
   the paper's Fig. 5 level (M3 = 1, C1 = 0.5, C2 = -2; the rotor's state) next to the
   meridian model's, the largest distance of a trajectory's crossings from its first (the
   "section spread": 0 for a periodic nutation), and MEGNO at t = 2000.
   -> docs/shell_sections.png
With --readme, also rewrites the block between the readme-shell markers in README.md.
Run: python docs/shell_rotor.py [--readme]   (about a minute)"""

import sys
import warnings
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from rollingtop import ContactLostWarning, SphericalTop, initial_state, simulate
from rollingtop.chaos import chaos_indicators, poincare_section
from rollingtop.dynamics.state import project_state
from rollingtop.io import write_bytes_atomic
from rollingtop.plot import save_figure
from rollingtop.reduction import LevelSet
from rollingtop.reduction.start import start_on_level

ROOT = Path(__file__).resolve().parents[1]
PAPER = {"R": 1.0, "m": 1.0, "g": 1.0, "a3": 0.1, "I1": 0.3, "I3": 0.5}
STATE = {"gamma": [0.0, 0.19**0.5, 0.9], "omega": [2.0, -0.2, 3.0], "free": {"v_tau": 0.3}}
T_CONV = 10.0
EPS = 10.0 ** -np.arange(1, 15)
FIT = (1e-3, 1e-10)
SHELLS = (0.1, 0.3)
H = (3.6, 4.2, 4.8, 5.4, 5.9, 6.4, 7.0)
CROSSINGS = 300
T_MEGNO = 2000.0
START = "<!-- readme-shell:start (written by docs/shell_rotor.py --readme) -->"
END = "<!-- readme-shell:end -->"


def _run(body, model, t_end):
    y0 = initial_state(body, model, **STATE)
    return simulate(body, model, y0, t_end=t_end, rtol=1e-13, atol=1e-15, samples=2).y[-1]


def _contact(body, y):
    """Contact point in the plane: the CoM's position minus the horizontal part of the arm."""
    alpha, beta, gamma = y[6:9], y[9:12], y[12:15]
    r = -body.R * gamma - np.array([0.0, 0.0, body.a3])
    return y[15:17] + np.array([r @ alpha, r @ beta])


def convergence():
    plain = SphericalTop(**PAPER)
    ref = _run(plain, "meridian", T_CONV)
    rows = []
    for eps in EPS:
        body = SphericalTop(**PAPER, shell_mass=eps, shell_inertia=eps)
        y = _run(body, "shell-rotor", T_CONV)
        rows.append((eps, np.linalg.norm(y[[8, 11, 14]] - ref[[8, 11, 14]]),
                     np.linalg.norm(_contact(body, y) - _contact(plain, ref)),
                     np.linalg.norm(y[3:6] - ref[3:6])))  # fmt: skip
    rows = np.array(rows)
    window = (rows[:, 0] <= FIT[0]) & (rows[:, 0] >= FIT[1])
    slopes = [np.polyfit(np.log10(rows[window, 0]), np.log10(rows[window, k]), 1)[0]
              for k in (1, 2, 3)]  # fmt: skip
    return rows, slopes


def _fig5_states(body):
    level = LevelSet(SphericalTop(**PAPER), 1.0, 0.5, -2.0)
    states = [start_on_level(level, h) for h in H]
    if body.has_shell:
        states = [project_state(body, "shell-rotor", y) for y in states]
    return np.array(states)


def sections():
    out = {}
    for ms in (0.0, *SHELLS):
        if ms == 0.0:
            body, model = SphericalTop(**PAPER), "meridian"
        else:
            body = SphericalTop(**PAPER, shell_mass=ms, shell_inertia=2 * ms / 3)
            model = "shell-rotor"
        states = _fig5_states(body)
        ds = poincare_section(body, model, states, crossings=CROSSINGS, seed=0)
        megno = [
            float(chaos_indicators(body, model, y, t_end=T_MEGNO).megno_mean[-1]) for y in states
        ]
        # how far the crossings of each trajectory stray from its first (0: periodic nutation)
        g3, wn = ds["gamma3"].values, ds["w_n"].values
        spread = float(np.nanmax(np.hypot(g3 - g3[:, :1], wn - wn[:, :1])))
        with warnings.catch_warnings():  # lost contacts are drawn faded
            warnings.simplefilter("ignore", ContactLostWarning)
            runs = [simulate(body, model, y, t_end=50.0, rtol=1e-11, samples=5001)
                    for y in states]  # fmt: skip
        out[ms] = (ds, megno, spread, [(r.y, r.contact_lost_at is not None) for r in runs])
    return out


def figures(rows, slopes, secs):
    fig = Figure(figsize=(7.0, 4.8), layout="constrained")
    ax = fig.add_subplot()
    for k, name in ((1, "axis direction"), (2, "contact point"), (3, "angular velocity")):
        ax.loglog(rows[:, 0], rows[:, k], "o-", ms=4, label=f"{name} (slope {slopes[k - 1]:.3f})")
    ax.loglog(EPS, EPS * rows[2, 1] / EPS[2], "k:", lw=1, label="slope 1")
    ax.axvspan(FIT[1], FIT[0], color="0.93", zorder=0, label="fitted range")
    ax.set(xlabel="shell mass = shell inertia  (rotor: m = 1, I1 = 0.3, I3 = 0.5)",
           ylabel=f"distance from the meridian model at t = {T_CONV:g}",
           title="The weightless-shell limit of the shell-rotor pair")  # fmt: skip
    ax.legend(fontsize=8)
    save_figure(fig, ROOT / "docs" / "shell_convergence.png")

    fig = Figure(figsize=(13.5, 4.6), layout="constrained")
    axes = fig.subplots(1, len(secs), sharex=True, sharey=True)
    for ax, (ms, (ds, megno, spread, runs)) in zip(axes, secs.items(), strict=True):
        for k, (y, lost) in enumerate(runs):
            # a motion that loses its contact is faded (a dash pattern fills in as it retraces)
            ax.plot(y[:, 14], _w_tau(y), lw=0.8, color=f"C{k}", alpha=0.3 if lost else 1.0,
                    label=f"h = {H[k]:g}" + (" (loses contact)" if lost else ""))  # fmt: skip
            n = int(ds["n_crossings"][k])
            ax.plot(ds["gamma3"][k, :n], ds["w_tau"][k, :n], "o", ms=4, color=f"C{k}")
        what = "meridian model (no shell)" if ms == 0 else f"shell-rotor, thin shell of {ms:g} m"
        ax.set(title=f"{what}\nMEGNO(t = {T_MEGNO:g}) {min(megno):.2f} .. {max(megno):.2f}; "
                     f"section spread {spread:.0e}", xlabel=r"$\gamma_3$")  # fmt: skip
    axes[0].set_ylabel(r"$\omega_\tau$")
    axes[0].legend(fontsize=7, loc="lower left")
    fig.suptitle("The rotor's (gamma3, w_tau), t <= 50, from the paper's Fig. 5 level "
                 "(M3 = 1, C1 = 0.5, C2 = -2).\nDots: the section w_tau = 0 upward, "
                 f"{CROSSINGS} crossings each, on one point.\nFaded: the normal force turns "
                 "negative (the body would leave the plane; the model keeps the contact)"
                 )  # fmt: skip
    save_figure(fig, ROOT / "docs" / "shell_sections.png")


def _w_tau(y):
    g = y[:, 12:15]
    s = np.hypot(g[:, 0], g[:, 1])
    return (g[:, 0] * y[:, 4] - g[:, 1] * y[:, 3]) / s


def readme_block(rows, slopes, secs):
    lines = [
        f"Distance from the meridian model at t = {T_CONV:g} (shell mass = inertia = eps; "
        f"fitted exponents over {FIT[0]:g} .. {FIT[1]:g}: axis {slopes[0]:.3f}, contact point "
        f"{slopes[1]:.3f}, angular velocity {slopes[2]:.3f}):",
        "",
        "| eps | axis direction | contact point | angular velocity |",
        "|---|---|---|---|",
    ]
    for eps, a, c, w in rows:
        lines.append(f"| {eps:.0e} | {a:.2e} | {c:.2e} | {w:.2e} |")
    lines += ["", "A thin shell of 10 % and 30 % of the rotor's mass, motions from the Fig. 5 "
              f"level, MEGNO at t = {T_MEGNO:g} (2: regular):", "",
              "| shell mass | " + " | ".join(f"h = {h:g}" for h in H) + " | section spread |",
              "|---|" + "---|" * (len(H) + 1)]  # fmt: skip
    for ms, (_, megno, spread, _) in secs.items():
        label = "0 (meridian)" if ms == 0 else f"{ms:g} m"
        lines.append(f"| {label} | " + " | ".join(f"{x:.2f}" for x in megno) + f" | {spread:.0e} |")
    return "\n".join(lines)


def write_readme(block, path=ROOT / "README.md"):
    text = path.read_text()
    head, rest = text.split(START)
    _, tail = rest.split(END)
    write_bytes_atomic(path, f"{head}{START}\n{block}\n{END}{tail}".encode())


def main(argv):
    rows, slopes = convergence()
    secs = sections()
    figures(rows, slopes, secs)
    block = readme_block(rows, slopes, secs)
    print(block)
    if "--readme" in argv:
        write_readme(block)


if __name__ == "__main__":
    main(sys.argv[1:])
