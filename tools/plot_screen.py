"""Plot a design sweep: displacement and mean velocity over the swept keys.

usage: plot_screen.py DESIGNS_CSV OUT_PNG METRIC SWEEP_NAME [--goal=max|min] KEY [KEY ...]
The best design by METRIC (largest for --goal=max, the default; smallest for min) is marked
with a red star on every panel and named in the title; ticks sit at the swept values.
`figure(...)` returns (matplotlib figure, choices dict) for tests.
Keys with a single value are ignored; with two or more varying keys the first two are
mapped (others are summarised by the best value over them). Colour scales are logarithmic
when the positive values span more than a decade; axes and colour bars carry SI-prefixed
units.
"""
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.colors import LogNorm  # noqa: E402

PREFIXES = [(1e-21, "z"), (1e-18, "a"), (1e-15, "f"), (1e-12, "p"), (1e-9, "n"), (1e-6, "\u00b5"),
            (1e-3, "m"), (1.0, "")]

# What people call the metrics and the swept keys, with their SI units.
LABELS = {
    "displacement_m": ("displacement", "m"),
    "mean_velocity_m_per_s": ("mean velocity", "m/s"),
    "mean_velocity_per_cycle_m_per_s": ("mean velocity per cycle", "m/s"),
    "displacement_per_cycle_m": ("displacement per cycle", "m"),
    "body_lengths_per_s": ("body lengths per second", "1/s"),
    "pumped_volume_m3": ("pumped volume", "m\u00b3"),
    "max_velocity_m_per_s": ("peak velocity", "m/s"),
    "final_velocity_m_per_s": ("final velocity", "m/s"),
    "mean_cycle_time_s": ("cycle time", "s"),
    "directed_to_diffusive_ratio": ("directed / diffusive displacement", ""),
    "swimmer.length": ("swimmer length $L$", "m"),
    "swimmer.radius": ("swimmer radius $R_0$", "m"),
    "wave.contracted_ratio": ("contracted radius $R_f/R_0$", ""),
    "container.radius": ("container radius", "m"),
    "protocol.load_factor": ("actuation / static load", ""),
}


def si_scale(values, unit):
    """Factor and unit label with an SI prefix for the largest |value| (m^3 not prefixed)."""
    if not unit or unit in ("1/s", "m\u00b3"):
        return 1.0, unit
    big = max((abs(v) for v in values if math.isfinite(v)), default=0.0)
    if big == 0.0:
        return 1.0, unit
    for factor, prefix in reversed(PREFIXES):
        if big >= factor:
            return 1.0 / factor, prefix + unit
    return 1.0 / PREFIXES[0][0], PREFIXES[0][1] + unit


def label(name, unit_label):
    text = LABELS.get(name, (name, ""))[0]
    return f"{text} [{unit_label}]" if unit_label else text


def value(col, row):
    """A design's value on a swept key: its number, or a choice's position."""
    if isinstance(col, tuple):
        return float(col[1].index(row[col[0]]))
    return float(row[col])


def tick_labels(vals, factor):
    return [f"{v * factor:.3g}" for v in vals]


def figure(csv_path, metric, name, keys, goal="max"):
    with open(csv_path) as f:
        rows = list(csv.DictReader(f))
    scored = [r for r in rows if r.get(metric) and r.get("status", "ok").startswith("ok")]
    pick = max if goal == "max" else min
    best = pick(scored, key=lambda r: float(r[metric])) if scored else None
    swept = {}
    for k in keys:
        # a quantity has its SI column next to the values as given (swimmer.length,
        # swimmer.length_m); a number or a choice ("step") has one column
        names = list(rows[0])
        col = names[names.index(k) + 1] if names.index(k) + 1 < len(names) and \
            names[names.index(k) + 1].startswith(k + "_") else k
        try:
            vals = sorted({float(r[col]) for r in rows})
        except ValueError:  # choices: their positions in the order first met
            order = list(dict.fromkeys(r[col] for r in rows))
            col = (col, order)
            vals = list(range(len(order)))
        if len(vals) > 1:
            swept[k] = (col, vals)
    varying = list(swept)
    panels = [m for m in ("displacement_m", "mean_velocity_m_per_s") if m != metric] + [metric]
    fig, axes = plt.subplots(1, len(panels), figsize=(5.8 * len(panels), 4.8), squeeze=False)
    best_text = f"best design {best['design']}" if best and "design" in best else "best design"
    fig.suptitle(f"Design sweep {name}: {len(rows)} designs; \u2605 = {best_text} "
                 f"({'largest' if goal == 'max' else 'smallest'} {LABELS.get(metric, (metric,))[0]})")
    choices = {"best": best, "best_xy": None, "xticks": None, "yticks": None, "axes": axes[0]}
    for ax, m in zip(axes[0], panels):
        unit = LABELS.get(m, (m, ""))[1]
        vals = [float(r[m]) for r in rows if r[m]]
        mf, mu = si_scale(vals, unit)
        if len(varying) >= 2:
            (cx, xs), (cy, ys) = swept[varying[0]], swept[varying[1]]
            xf, xu = si_scale(xs, LABELS.get(varying[0], ("", ""))[1])
            yf, yu = si_scale(ys, LABELS.get(varying[1], ("", ""))[1])
            cell = {}
            for r in rows:
                if not r[m]:
                    continue
                key = (value(cx, r), value(cy, r))
                cell[key] = max(cell.get(key, -1e300), float(r[m]) * mf)
            grid = [[cell.get((x, y), float("nan")) for x in xs] for y in ys]
            pos = [v for row in grid for v in row if math.isfinite(v) and v > 0]
            norm = None
            if pos and len(pos) == sum(1 for row in grid for v in row if math.isfinite(v)) and max(pos) > 10 * min(pos):
                norm = LogNorm(vmin=min(pos), vmax=max(pos))
            im = ax.pcolormesh([x * xf for x in xs], [y * yf for y in ys], grid, shading="auto", norm=norm)
            fig.colorbar(im, ax=ax, label=label(m, mu) + (" (log scale)" if norm else ""))
            ax.set(xlabel=label(varying[0], xu), ylabel=label(varying[1], yu))
            ax.set_xticks([x * xf for x in xs], tick_labels(xs, xf) if not isinstance(cx, tuple) else cx[1])
            ax.set_yticks([y * yf for y in ys], tick_labels(ys, yf) if not isinstance(cy, tuple) else cy[1])
            choices["xticks"], choices["yticks"] = [x * xf for x in xs], [y * yf for y in ys]
            if best:
                bxy = (value(cx, best) * xf, value(cy, best) * yf)
                ax.plot(*bxy, marker="*", ms=16, color="tab:red", mec="white", ls="none")
                choices["best_xy"] = bxy
        elif len(varying) == 1:
            cx, xs = swept[varying[0]]
            xf, xu = si_scale(xs, LABELS.get(varying[0], ("", ""))[1])
            pts = sorted((value(cx, r) * xf, float(r[m]) * mf) for r in rows if r[m])
            ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-")
            ax.set(xlabel=label(varying[0], xu), ylabel=label(m, mu))
            ax.set_xticks([x * xf for x in xs], tick_labels(xs, xf) if not isinstance(cx, tuple) else cx[1])
            choices["xticks"] = [x * xf for x in xs]
            pv = [p[1] for p in pts if p[1] > 0]
            if pv and len(pv) == len(pts) and max(pv) > 10 * min(pv):
                ax.set_yscale("log")
            if best and best.get(m):
                bxy = (value(cx, best) * xf, float(best[m]) * mf)
                ax.plot(*bxy, marker="*", ms=16, color="tab:red", mec="white", ls="none")
                choices["best_xy"] = bxy
        ax.set_title(LABELS.get(m, (m,))[0])
    fig.tight_layout()
    return fig, choices


def main(csv_path, png, metric, name, args):
    goal = "max"
    keys = []
    for a in args:
        if a.startswith("--goal="):
            goal = a.split("=", 1)[1]
        else:
            keys.append(a)
    fig, _ = figure(csv_path, metric, name, keys, goal)
    fig.savefig(png, dpi=110)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4], sys.argv[5:])
