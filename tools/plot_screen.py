"""Plot a design sweep: displacement and mean velocity over the swept keys.

usage: plot_screen.py DESIGNS_CSV OUT_PNG METRIC KEY [KEY ...]
Keys with a single value are ignored; with two or more varying keys the first two are
mapped (others are summarised by the best value over them).
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(csv_path, png, metric, keys):
    with open(csv_path) as f:
        rows = list(csv.DictReader(f))
    si = {}
    for k in keys:
        col = next(c for c in rows[0] if c.startswith(k + "_si"))
        vals = sorted({float(r[col]) for r in rows})
        if len(vals) > 1:
            si[k] = (col, vals)
    varying = list(si)
    panels = [m for m in ("displacement_m", "mean_velocity_m_per_s") if m != metric] + [metric]
    fig, axes = plt.subplots(1, len(panels), figsize=(5.5 * len(panels), 4.5))
    for ax, m in zip(axes, panels):
        if len(varying) >= 2:
            (cx, xs), (cy, ys) = si[varying[0]], si[varying[1]]
            best = {}
            for r in rows:
                if not r[m]:
                    continue
                key = (float(r[cx]), float(r[cy]))
                best[key] = max(best.get(key, -1e300), float(r[m]))
            grid = [[best.get((x, y), float("nan")) for x in xs] for y in ys]
            im = ax.pcolormesh(xs, ys, grid, shading="auto")
            fig.colorbar(im, ax=ax, label=m)
            ax.set(xlabel=cx, ylabel=cy)
        elif len(varying) == 1:
            cx, xs = si[varying[0]]
            pts = sorted((float(r[cx]), float(r[m])) for r in rows if r[m])
            ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-")
            ax.set(xlabel=cx, ylabel=m)
        ax.set_title(m)
    fig.tight_layout()
    fig.savefig(png, dpi=110)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4:])
