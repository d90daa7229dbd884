"""Plot one run folder of either tier: swimmer position and velocity, wall energy,
radius extremes over time, and the radius profile R(z, t) as a space-time map.

The title names the scene (its `name`), the tier and model, and a failed run's status.
R_f (the contracted target radius, contracted_ratio * R0) is drawn on the radius panel and
on the map's colour bar; the protocol's events (segment i reaching R_f, cycle starts and
ends, from summary.json) are vertical lines on the time panels and horizontal lines on
the map. Legends sit outside the axes. In 3D the radius extremes are node extremes and
the map is the ring-mean radius; in 1D both are the tube radius.

usage: plot_run.py RUN_DIR   (writes RUN_DIR/run.png)
`figure(RUN_DIR)` returns (matplotlib figure, choices dict) for tests.
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
    big = max((abs(v) for v in values if math.isfinite(v)), default=0.0)
    if big == 0.0:
        return 1.0, unit
    for factor, prefix in reversed(PREFIXES):
        if big >= factor:
            return 1.0 / factor, prefix + unit
    return 1.0 / PREFIXES[0][0], PREFIXES[0][1] + unit


def read_csv(path):
    """Columns by name; a file with its header and no rows gives empty columns."""
    with open(path) as f:
        reader = csv.DictReader(f)
        rows = list(reader)
        names = reader.fieldnames or []
    return {k: [float(r[k]) for r in rows] for k in names}


def read_summary(run_dir):
    try:
        with open(f"{run_dir}/summary.json") as f:
            return json.load(f)
    except (OSError, ValueError):
        return {}


def title_of(summary, run_dir):
    """'Run NAME (tier, model)' and, for a failed run, 'FAILED: reason' on a second line."""
    name = summary.get("scene", {}).get("name") or run_dir
    tier = summary.get("tier", "")
    model = summary.get("model")
    what = ", ".join(v for v in (tier.upper() if tier else "", model.replace("_", " ") if model else "") if v)
    title = f"Run {name}" + (f" ({what})" if what else "")
    status = str(summary.get("status", "ok"))
    failed = status.startswith("failed")
    if failed:
        import textwrap
        reason = status[len("failed"):].lstrip(": ")
        title += "\n" + "\n".join(textwrap.wrap(f"FAILED: {reason}", 110)[:3])
    return title, failed


def contracted_radius(summary):
    """R_f = contracted_ratio * R0 in metres, or None when the summary does not say."""
    d = summary.get("derived", {})
    try:
        return d["contracted_ratio"] * d["aspect_ratio_R0_over_L"] * summary["swimmer_length_m"]
    except (KeyError, TypeError):
        return None


def events(summary):
    """The protocol's events as (time s, kind): a segment reaching R_f, cycle start, cycle end."""
    ev = [(t, "segment at R_f") for t in summary.get("segment_reached_s") or [] if t is not None and t >= 0]
    ev += [(t, "cycle start") for t in summary.get("cycle_start_times_s") or [] if t > 0]
    ev += [(t, "cycle end") for t in summary.get("cycle_end_times_s") or []]
    return sorted(ev)


EVENT_STYLE = {"segment": dict(color="tab:green", ls="--", lw=0.7, alpha=0.7),
               "cycle": dict(color="tab:purple", ls="-.", lw=0.9, alpha=0.8)}


def empty_figure(title, failed):
    """A run that stopped before its first output time (series.csv holds its header only): the
    title and status, and a sentence in place of the panels."""
    fig, a = plt.subplots(figsize=(12.5, 3.2))
    fig.suptitle(title, color="tab:red" if failed else "black")
    a.set_axis_off()
    a.text(0.5, 0.35, "no output time was reached: series.csv and radius.csv hold no rows to plot",
           transform=a.transAxes, ha="center", va="center", color="tab:red" if failed else "black")
    fig.tight_layout(rect=(0, 0, 1, 0.97 if not failed else 0.80))
    return fig, {"title": title, "failed": failed, "R_f_m": None, "events": [], "min_label": None,
                 "map_title": None, "legends": [], "axes": [a], "empty": True}


def figure(run_dir):
    s = read_csv(f"{run_dir}/series.csv")
    summary = read_summary(run_dir)
    title, failed = title_of(summary, run_dir)
    is3d = summary.get("tier") == "3d"
    if not s.get("t_s"):
        return empty_figure(title, failed)
    fig, ax = plt.subplots(2, 2, figsize=(12.5, 7.8))
    fig.suptitle(title, color="tab:red" if failed else "black")
    tf, tu = si_scale(s["t_s"], "s")
    t = [v * tf for v in s["t_s"]]
    ev = events(summary)
    xf, xu = si_scale(s["x_center_m"], "m")
    ax[0, 0].plot(t, [v * xf for v in s["x_center_m"]], label="centre position")
    ax[0, 0].set(xlabel=f"t [{tu}]", ylabel=f"displacement [{xu}]", title="swimmer position")
    vf, vu = si_scale(s["velocity_m_per_s"], "m/s")
    ax[0, 1].plot(t, [v * vf for v in s["velocity_m_per_s"]], label="velocity U")
    ax[0, 1].axhline(0.0, color="0.6", lw=0.8)
    ax[0, 1].set(xlabel=f"t [{tu}]", ylabel=f"velocity U [{vu}]", title="swimmer velocity")
    rf_m = contracted_radius(summary)
    rf, ru = si_scale(s["max_radius_m"] + ([rf_m] if rf_m else []), "m")
    lo = "min R (node minimum)" if is3d else "min R"
    hi = "max R (node maximum)" if is3d else "max R"
    ax[1, 0].plot(t, [v * rf for v in s["min_radius_m"]], label=lo)
    ax[1, 0].plot(t, [v * rf for v in s["max_radius_m"]], label=hi)
    if rf_m:
        ax[1, 0].axhline(rf_m * rf, color="tab:red", ls=":", lw=1.2,
                         label=f"R_f = {rf_m * rf:.3g} {ru} (target)")
    ax2 = ax[1, 0].twinx()
    ef, eu = si_scale(s["energy_J"], "J")
    ax2.plot(t, [v * ef for v in s["energy_J"]], "k:", label="wall energy")
    ax2.set_ylabel(f"wall energy [{eu}]")
    ax[1, 0].set(xlabel=f"t [{tu}]", ylabel=f"radius [{ru}]",
                 title="radius extremes (nodes) and energy" if is3d else "radius extremes and energy")
    # the protocol's events on the three time panels, one legend entry per kind
    seen = set()
    for tt, kind in ev:
        style = EVENT_STYLE["segment" if kind.startswith("segment") else "cycle"]
        lab = "segment reaches R_f" if kind.startswith("segment") else kind
        for a in (ax[0, 0], ax[0, 1], ax[1, 0]):
            a.axvline(tt * tf, label=None if lab in seen else lab, **style)
            seen.add(lab) if a is ax[1, 0] else None
    legends = []
    for a, extra in ((ax[0, 0], []), (ax[0, 1], []), (ax[1, 0], ax2.get_lines())):
        handles = [h for h in a.get_lines() + list(extra) if not h.get_label().startswith("_")]
        if handles:
            legends.append(a.legend(handles, [h.get_label() for h in handles], loc="upper left",
                                    bbox_to_anchor=(1.16 if a is ax[1, 0] else 1.02, 1.0),
                                    fontsize="x-small", frameon=False))
    map_title = "ring-mean radius R(z, t)" if is3d else "radius R(z, t)"
    has_map = False
    try:
        r = read_csv(f"{run_dir}/radius.csv")
        if not r.get("t_s"):
            raise ValueError("no radius profile was written")
        times = sorted(set(r["t_s"]))
        zs = sorted(set(r["z_m"]))
        grid = [[float("nan")] * len(zs) for _ in times]
        ti = {v: i for i, v in enumerate(times)}
        zi = {v: i for i, v in enumerate(zs)}
        gf, gu = si_scale(r["radius_m"], "m")
        for tt, zz, rr in zip(r["t_s"], r["z_m"], r["radius_m"]):
            grid[ti[tt]][zi[zz]] = rr * gf
        zf, zu = si_scale(zs, "m")
        im = ax[1, 1].pcolormesh([z * zf for z in zs], [v * tf for v in times], grid, shading="auto")
        cb = fig.colorbar(im, ax=ax[1, 1], label=f"{'ring-mean R' if is3d else 'R'} [{gu}]")
        lo_c, hi_c = im.get_clim()
        if rf_m and lo_c <= rf_m * gf <= hi_c:  # R_f on the colour scale, labelled left of it
            cb.ax.axhline(rf_m * gf, color="tab:red", lw=1.5)
            cb.ax.text(-0.1, rf_m * gf, "R_f", transform=cb.ax.get_yaxis_transform(), color="tab:red",
                       fontsize="x-small", va="center", ha="right")
        for tt, kind in ev:
            ax[1, 1].axhline(tt * tf, **dict(EVENT_STYLE["segment" if kind.startswith("segment") else "cycle"],
                                             color="white"))
        ax[1, 1].set(xlabel=f"z [{zu}]", ylabel=f"t [{tu}]", title=map_title)
        has_map = True
    except (OSError, KeyError, IndexError, ValueError):
        ax[1, 1].set_axis_off()
    fig.tight_layout(rect=(0, 0, 1, 0.97 if not failed else 0.92))
    choices = {"title": title, "failed": failed, "R_f_m": rf_m, "events": ev,
               "min_label": lo, "map_title": map_title if has_map else None,
               "legends": legends, "axes": ax, "empty": False}
    return fig, choices


def main(run_dir):
    fig, _ = figure(run_dir)
    fig.savefig(f"{run_dir}/run.png", dpi=110)


if __name__ == "__main__":
    main(sys.argv[1])
