"""Run one drop from Python and draw its orbit: the rotor centre relative to the race inside
the clearance circle (the paper's Fig. 3 view), with the contact force beneath.

    pip install ./crates/python matplotlib
    python examples/python/orbit.py [--speed-rpm 8000] [--mu 0.4] [--out orbit.png]
"""

from __future__ import annotations

import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import whirlmap  # noqa: E402


def main() -> None:
    """Parse the options, run the drop and write the chart."""
    ap = argparse.ArgumentParser(description=" ".join(__doc__.split("\n\n")[0].split()))
    ap.add_argument("--speed-rpm", type=float, default=8000.0, help="release speed (r/min)")
    ap.add_argument("--mu", type=float, default=0.4, help="dynamic friction coefficient")
    ap.add_argument("--duration-s", type=float, default=0.5, help="simulated time (s)")
    ap.add_argument("--out", default="orbit.png", help="the chart's file (PNG)")
    a = ap.parse_args()

    d = whirlmap.drop(a.speed_rpm, a.mu, duration_s=a.duration_s)
    s = d.series
    assert s is not None
    um = 1e6
    c = d.clearance_m * um

    fig, (ax, axf) = plt.subplots(
        2, 1, figsize=(6, 8), gridspec_kw={"height_ratios": [3, 1]}, constrained_layout=True
    )
    phi = np.linspace(0, 2 * np.pi, 400)
    ax.plot(c * np.cos(phi), c * np.sin(phi), color="0.3", lw=1.2, label="clearance circle")
    ax.plot(s["x_rel_m"] * um, s["y_rel_m"] * um, lw=0.6, color="tab:red", label="rotor centre")
    ax.plot([0], [0], "+", color="0.3")
    ax.set_aspect("equal")
    ax.set_xlim(-1.15 * c, 1.15 * c)
    ax.set_ylim(-1.15 * c, 1.15 * c)
    ax.set_xlabel("x relative to the race (µm)")
    ax.set_ylabel("y relative to the race (µm)")
    rec = d.record
    ax.set_title(
        f"{a.speed_rpm:.0f} r/min, μ = {a.mu:.2f}: {rec['class'].replace('_', ' ')}\n"
        f"max force {rec['max_contact_force_n']:.0f} N, "
        f"peak heat power {rec['peak_heat_power_w']:.0f} W"
    )
    ax.legend(loc="upper right", fontsize=8)

    axf.plot(s["t_s"] * 1e3, s["contact_force_n"], lw=0.6, color="tab:blue")
    axf.set_xlabel("time since release (ms)")
    axf.set_ylabel("contact force (N)")
    fig.savefig(a.out, dpi=120)
    print(f"{rec['class']}: {len(s['t_s'])} samples, chart {a.out}")


if __name__ == "__main__":
    main()
