"""Plot one run folder of either tier: swimmer position and velocity, wall energy,
radius extremes over time, and the radius profile R(z, t) as a space-time map.

usage: plot_run.py RUN_DIR   (writes RUN_DIR/run.png)
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_csv(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]} if rows else {}


def main(run_dir):
    s = read_csv(f"{run_dir}/series.csv")
    fig, ax = plt.subplots(2, 2, figsize=(11, 7.5))
    t = [v * 1e3 for v in s["t_s"]]
    ax[0, 0].plot(t, [v * 1e6 for v in s["x_center_m"]])
    ax[0, 0].set(xlabel="t [ms]", ylabel="displacement [um]", title="swimmer position")
    ax[0, 1].plot(t, [v * 1e6 for v in s["velocity_m_per_s"]])
    ax[0, 1].set(xlabel="t [ms]", ylabel="W [um/s]", title="swimmer velocity")
    ax[1, 0].plot(t, [v * 1e9 for v in s["min_radius_m"]], label="min R")
    ax[1, 0].plot(t, [v * 1e9 for v in s["max_radius_m"]], label="max R")
    ax2 = ax[1, 0].twinx()
    ax2.plot(t, s["energy_J"], "k:", label="energy")
    ax2.set_ylabel("wall energy [J]")
    ax[1, 0].set(xlabel="t [ms]", ylabel="radius [nm]", title="radius extremes and energy")
    ax[1, 0].legend(loc="lower right")
    try:
        r = read_csv(f"{run_dir}/radius.csv")
        times = sorted(set(r["t_s"]))
        zs = sorted(set(r["z_m"]))
        grid = [[0.0] * len(zs) for _ in times]
        ti = {v: i for i, v in enumerate(times)}
        zi = {v: i for i, v in enumerate(zs)}
        for tt, zz, rr in zip(r["t_s"], r["z_m"], r["radius_m"]):
            grid[ti[tt]][zi[zz]] = rr * 1e9
        im = ax[1, 1].pcolormesh([z * 1e6 for z in zs], [v * 1e3 for v in times], grid, shading="auto")
        fig.colorbar(im, ax=ax[1, 1], label="R [nm]")
        ax[1, 1].set(xlabel="z [um]", ylabel="t [ms]", title="radius R(z, t)")
    except (OSError, KeyError, IndexError):
        ax[1, 1].set_axis_off()
    fig.tight_layout()
    fig.savefig(f"{run_dir}/run.png", dpi=110)


if __name__ == "__main__":
    main(sys.argv[1])
