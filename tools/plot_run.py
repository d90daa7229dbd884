"""Plot one run folder of either tier: swimmer position and velocity, wall energy,
radius extremes over time, and the radius profile R(z, t) as a space-time map.

usage: plot_run.py RUN_DIR   (writes RUN_DIR/run.png)
"""
import csv
import json
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

PREFIXES = [(1e-21, "z"), (1e-18, "a"), (1e-15, "f"), (1e-12, "p"), (1e-9, "n"), (1e-6, "\u00b5"), (1e-3, "m"), (1.0, "")]


def si_scale(values, unit):
    """Factor and label that put the largest |value| in [1, 1000) with an SI prefix."""
    big = max((abs(v) for v in values), default=0.0)
    if big == 0.0 or not math.isfinite(big):
        return 1.0, unit
    for factor, prefix in reversed(PREFIXES):
        if big >= factor:
            return 1.0 / factor, prefix + unit
    return 1.0 / PREFIXES[0][0], PREFIXES[0][1] + unit


def read_csv(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]} if rows else {}


def main(run_dir):
    s = read_csv(f"{run_dir}/series.csv")
    try:
        with open(f"{run_dir}/summary.json") as f:
            summary = json.load(f)
        name = summary.get("scene", {}).get("name", run_dir)
        label = f"{name} ({summary.get('tier', '')}{', ' + summary['model'] if 'model' in summary else ''})"
    except (OSError, ValueError):
        label = run_dir
    fig, ax = plt.subplots(2, 2, figsize=(11, 7.5))
    fig.suptitle(f"Run {label}")
    tf, tu = si_scale(s["t_s"], "s")
    t = [v * tf for v in s["t_s"]]
    xf, xu = si_scale(s["x_center_m"], "m")
    ax[0, 0].plot(t, [v * xf for v in s["x_center_m"]])
    ax[0, 0].set(xlabel=f"t [{tu}]", ylabel=f"displacement [{xu}]", title="swimmer position")
    vf, vu = si_scale(s["velocity_m_per_s"], "m/s")
    ax[0, 1].plot(t, [v * vf for v in s["velocity_m_per_s"]])
    ax[0, 1].axhline(0.0, color="0.6", lw=0.8)
    ax[0, 1].set(xlabel=f"t [{tu}]", ylabel=f"velocity U [{vu}]", title="swimmer velocity")
    rf, ru = si_scale(s["max_radius_m"], "m")
    ax[1, 0].plot(t, [v * rf for v in s["min_radius_m"]], label="min R")
    ax[1, 0].plot(t, [v * rf for v in s["max_radius_m"]], label="max R")
    ax2 = ax[1, 0].twinx()
    ef, eu = si_scale(s["energy_J"], "J")
    ax2.plot(t, [v * ef for v in s["energy_J"]], "k:", label="wall energy")
    ax2.set_ylabel(f"wall energy [{eu}]")
    ax[1, 0].set(xlabel=f"t [{tu}]", ylabel=f"radius [{ru}]", title="radius extremes and energy")
    lines = ax[1, 0].get_lines() + ax2.get_lines()
    ax[1, 0].legend(lines, [ln.get_label() for ln in lines], loc="upper left", bbox_to_anchor=(1.12, 1.0),
                    fontsize="small", frameon=False)
    try:
        r = read_csv(f"{run_dir}/radius.csv")
        times = sorted(set(r["t_s"]))
        zs = sorted(set(r["z_m"]))
        grid = [[0.0] * len(zs) for _ in times]
        ti = {v: i for i, v in enumerate(times)}
        zi = {v: i for i, v in enumerate(zs)}
        gf, gu = si_scale(r["radius_m"], "m")
        for tt, zz, rr in zip(r["t_s"], r["z_m"], r["radius_m"]):
            grid[ti[tt]][zi[zz]] = rr * gf
        zf, zu = si_scale(zs, "m")
        mf, mu = si_scale(times, "s")
        im = ax[1, 1].pcolormesh([z * zf for z in zs], [v * mf for v in times], grid, shading="auto")
        fig.colorbar(im, ax=ax[1, 1], label=f"R [{gu}]")
        ax[1, 1].set(xlabel=f"z [{zu}]", ylabel=f"t [{mu}]", title="radius R(z, t)")
    except (OSError, KeyError, IndexError, ValueError):
        ax[1, 1].set_axis_off()
    fig.tight_layout()
    fig.savefig(f"{run_dir}/run.png", dpi=110)


if __name__ == "__main__":
    main(sys.argv[1])
