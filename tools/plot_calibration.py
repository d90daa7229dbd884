"""Figure 10 done with pressures: uniform inward pressure against the radial displacement
of the middle ring, with the C1 fit through the origin.

usage: plot_calibration.py DIR   (reads DIR/calibration.json, writes DIR/calibration.png)
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(d):
    with open(f"{d}/calibration.json") as f:
        c = json.load(f)
    pts = c["load_points"]
    x = [p["displacement_m"] * 1e9 for p in pts]
    y = [p["pressure_Pa"] * 1e3 for p in pts]
    lin = [p["in_linear_range"] for p in pts]
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.5))
    name = c["scene"].get("name", d)
    fig.suptitle(f"Wall stiffness from uniform loads: {name} ({c['grid']['membrane_nodes']} membrane nodes)")
    ax[0].plot([v for v, l in zip(x, lin) if l], [v for v, l in zip(y, lin) if l], "o", label="linear range (fit)")
    ax[0].plot([v for v, l in zip(x, lin) if not l], [v for v, l in zip(y, lin) if not l], "s", mfc="none",
               label="beyond 1 % of linear")
    xm = max(x)
    ax[0].plot([0, xm], [0, c["C1_Pa_per_m"] * xm * 1e-9 * 1e3], "k-", lw=1,
               label=f"C1 = {c['C1_Pa_per_m'] / 1e6:.4g} MPa/m (fit)")
    ax[0].plot([0, xm], [0, c["C1_spring_network_Pa_per_m"] * xm * 1e-9 * 1e3], "k:", lw=1,
               label=f"2 k_s / (\u221a3 R0\u00b2) = {c['C1_spring_network_Pa_per_m'] / 1e6:.4g} MPa/m")
    ax[0].set(xlabel="radial displacement R0 \u2212 R_mid [nm]", ylabel="pressure [mPa]",
              title="pressure against displacement")
    ax[0].legend(loc="upper left", fontsize="small", frameon=False)
    ax[1].semilogx([p["pressure_Pa"] * 1e3 for p in pts], [p["secant_C1_Pa_per_m"] / 1e6 for p in pts], "o-")
    ax[1].axhline(c["C1_spring_network_Pa_per_m"] / 1e6, color="k", ls=":", lw=1)
    ax[1].set(xlabel="pressure [mPa]", ylabel="secant C1 = P / (R0 \u2212 R_mid) [MPa/m]",
              title="stiffness against load (log scale)")
    fig.tight_layout()
    fig.savefig(f"{d}/calibration.png", dpi=110)


if __name__ == "__main__":
    main(sys.argv[1])
