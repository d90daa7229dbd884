"""Figures and human-readable reports of a validation suite run.

usage: plot_validation.py DIR   (reads DIR/report.json; writes DIR/report.md, DIR/report.html
                                 and DIR/fig_*.png)
"""
import base64
import html
import json
import math
import os
import re
import struct
import sys
import textwrap
import zlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402
import numpy as np  # noqa: E402  (a dependency of matplotlib)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import plot_calibration  # noqa: E402

MODEL_STYLES = ["C1-", "C2--", "C3-.", "C4:", "C5-", "C6--", "C8-.", "C9:", "C7-"]


SI_PREFIXES = [(1e-15, "f"), (1e-12, "p"), (1e-9, "n"), (1e-6, "µ"), (1e-3, "m"), (1, ""), (1e3, "k"), (1e6, "M")]


def si_prefix(v):
    """The SI prefix si() writes v with: (scale, prefix), e.g. (1e-9, 'n') for 4.2e-8."""
    a = abs(v)
    scale, p = SI_PREFIXES[0]
    for s, q in SI_PREFIXES:
        if a >= s:
            scale, p = s, q
    return scale, p


def si(v, unit, digits=3):
    """Value with an SI prefix: si(4.2e-8, 'm') -> '42 nm'."""
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "—"
    if v == 0:
        return f"0 {unit}"
    scale, p = si_prefix(v)
    return f"{v / scale:.{digits}g} {p}{unit}"


def wrinkle(run):
    """The wall-wrinkle cell of a 3D run: absent for runs written before the measure, and
    "round" below 1e-6 h (a wall held axisymmetric departs from circles by round-off only)."""
    if "max_wrinkle_m" not in run:
        return "—"
    if run.get("max_wrinkle_over_h", 1.0) < 1e-6:
        return "round"
    modes = run.get("wrinkle_modes_over_half_cell") or []
    if len(modes) >= 2:  # the lobes changed during the run
        return si(run["max_wrinkle_m"], "m") + " (m = " + ", then ".join(str(m) for m in modes) + ")"
    mode = run.get("max_wrinkle_mode")
    return si(run["max_wrinkle_m"], "m") + (f" (m = {mode})" if mode else "")


def wrinkle_paragraph(runs):
    """The report's paragraph on the 3D wall's wrinkle over a case's grids (empty when no grid
    wrinkled beyond half a cell): how far, into which lobes, and what chose them (the seeds,
    the secondary instability's seed, or the grid)."""
    wr = [r for r in runs if r.get("max_wrinkle_over_h", 0) > 0.5]
    if not wr:
        return []
    seeds = {r.get("seed_mode", 0) for r in wr}
    seconds = {r.get("secondary_seed_mode", 0) for r in wr}
    # the lobes each run showed: its largest wrinkle's, and those above half a cell
    shown = [{r.get("max_wrinkle_mode")} | set(r.get("wrinkle_modes_over_half_cell") or []) for r in wr]
    seed = next(iter(seeds)) if len(seeds) == 1 else 0
    second = next(iter(seconds)) if len(seconds) == 1 else 0
    seeded = seed > 0 and all(m <= {seed, second} - {0} for m in shown)
    both = seeded and second > 0 and all(second in m for m in shown)
    pattern = (f"the m = {seed} lobes seeded in its stress-free shape and then, by the buckled wall's secondary "
               f"instability, the m = {second} lobes of its secondary seed, on every grid (the seeds choose them: "
               "docs/full3d.md, \"Lobes that change: the secondary instability\")" if both
               else f"the m = {seed} lobes seeded in its stress-free shape, on every grid (the seed chooses "
               "them: docs/full3d.md, \"Ring buckling and the seed imperfection\")" if seeded
               else "lobes whose pattern follows the grid")
    out = ["", "Wall wrinkle: the largest RMS departure of the 3D wall from axisymmetry (m: its lobe number). "
            f"On {len(wr)} of {len(runs)} grids it exceeds h/2 (up to "
            f"{max(r['max_wrinkle_over_h'] for r in wr):.1f} h): the hoop-compressed wall buckled into "
            f"{pattern}, and the 1D tier, which assumes a round tube, "
            "cannot represent them (docs/full3d.md, \"Wall wrinkling\")."]
    changed = [r for r in wr if len(r.get("wrinkle_modes_over_half_cell") or []) >= 2]
    if changed and not both:
        out[-1] += (f" On {len(changed)} of these grids the lobes changed during the run (the cell lists them in "
                    "order): a run whose lobes change follows another buckled branch from there on "
                    "(docs/full3d.md, \"Lobes that change: the secondary instability\").")
    return out


def evidence_value(key, v):
    """One value of a finding's evidence: SI prefixes for lengths and speeds, a dash for a
    value the suite could not compute (a case whose 3D runs all failed)."""
    if v is None:
        return "— (no 3D value)"
    if isinstance(v, (int, float)) and key.endswith("body_lengths_per_s"):
        return f"{v:.3g} body lengths/s"
    if isinstance(v, float):
        for suffix, unit in (("_m_per_s", "m/s"), ("_m", "m"), ("_s", "s")):
            if key.endswith(suffix):
                return si(v, unit)
        return f"{v:.3g}"
    return f"{v}"


def unit_of(quantity):
    """The SI unit of a report key: *_m_per_s, *_m, *_s."""
    for suffix, unit in (("_m_per_s", "m/s"), ("_m", "m"), ("_s", "s")):
        if quantity.endswith(suffix):
            return unit
    return ""


def value_pm(v, e, quantity):
    """'22.3 ± 4.07 nm/s'; a dash for a value the suite could not compute."""
    if v is None:
        return "—"
    if quantity == "body_lengths_per_s":
        return f"{v:.3g} ± {'—' if e is None else f'{e:.2g}'} body lengths/s"
    unit = unit_of(quantity)
    if not unit:
        return f"{v:.3g} ± {'—' if e is None else f'{e:.3g}'}"
    return f"{si(v, unit)} ± {si(e, unit)}"


def finding_values(f):
    """A finding's values with their errors, and the differences it rests on."""
    parts = []
    for e in f["evidence"]:
        if "quantity" in e:
            sweep = [f"{k} = {e[k]}" for k in ("L_um", "R_f_over_R0") if k in e]
            text = f"{e['case']}{' (' + sweep[0] + ')' if sweep else ''}: {value_pm(e['value'], e['error'], e['quantity'])}"
            if e.get("reference") == "axisymmetric reference":
                text += " (axisymmetric reference)"
            if "band" in e:
                text += f" (paper {e['paper']}, band {e['band'][0]:.3g}–{e['band'][1]:.3g})"
        elif "relative_difference" in e:
            rd, er = e["relative_difference"], e["reference_error_relative"]
            text = (f"{e['case']}, {e['model']}{' (default)' if e.get('default_model') else ''}: "
                    f"1D − 3D = {pct(rd)} ± {'—' if er is None else f'{100 * er:.1f} %'} "
                    f"(tolerance ±{100 * e['tolerance']:.0f} %): {e['verdict']}")
        elif "correlation" in e:
            c, ce = e["correlation"], e["correlation_error"]
            against = f" against the {e['reference']}" if e.get("reference") else ""
            text = (f"{e['case']}, {e['model']}{' (default)' if e.get('default_model') else ''}: "
                    f"correlation{against} {'—' if c is None else f'{c:.2f}'} ± {'—' if ce is None else f'{ce:.2f}'} "
                    f"(threshold {e['threshold']}): {e['verdict']}")
        else:
            text = ", ".join(f"{k} = {evidence_value(k, v)}" for k, v in e.items())
        if e.get("note"):
            text += f" ({e['note']})"
        parts.append(text)
    unit = unit_of((f["evidence"][0].get("quantity") or "") if f["evidence"] else "")
    for c in f.get("comparisons", []):
        parts.append(f"{c['expected_larger']} − {c['expected_smaller']} = {si(c['difference'], unit) if unit else c['difference']} "
                     f"against e₁ + e₂ = {si(c['combined_uncertainty'], unit) if unit else c['combined_uncertainty']}: "
                     f"{c['outcome']}")
    return "; ".join(parts) or "the suite has no cases for it"


def cell(text):
    """Text for a Markdown table cell: its pipes escaped (|a − b| stays readable)."""
    return text.replace("|", "\\|")


def legend_right(ax):
    """Legend beside the axes, off the data."""
    ax.legend(loc="center left", bbox_to_anchor=(1.0, 0.5), fontsize="small", frameon=False)


def legend_below(fig, ax, width=9.0, height=4.6, ncol=2, wrap=58, gap=0.15):
    """Legend under the axes (of ax's entries, or of a list of axes' entries with each label
    once, for the whole figure), off the data, its long
    labels wrapped: the axes keep the figure's width (beside them, a legend of long model labels
    squeezed the plot to a strip). Lays the figure out, width x height inches of axes and below
    them room for the legend's rows and a gap."""
    handles, labels, seen = [], [], set()
    for a in (ax if isinstance(ax, (list, tuple)) else [ax]):  # entries of several axes, each label once
        for h, l in zip(*a.get_legend_handles_labels()):
            if l not in seen:
                seen.add(l)
                handles.append(h)
                labels.append(l)
    labels = [textwrap.fill(l, wrap, subsequent_indent="  ") for l in labels]
    fig.legend(handles, labels, loc="lower center", ncol=ncol, fontsize="small", frameon=False)
    # about 0.18 inch per line; the columns are filled one after the other, so row r holds the
    # labels r, r + rows, ...
    rows = math.ceil(len(labels) / ncol)
    lines = sum(max(labels[i].count("\n") + 1 for i in range(r, len(labels), rows)) for r in range(rows))
    below = 0.18 * lines + gap
    fig.set_size_inches(width, height + below)
    fig.tight_layout(rect=(0, below / (height + below), 1, 1))


def save(fig, path):
    """Lay out, write and close a figure."""
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def pct(v):
    return "—" if v is None else f"{100 * v:+.1f} %"


# the coarser 3D grids, next-finest first: each its own grey and dash, so they can be told apart
COARSE_STYLES = (dict(color="0.35", ls="--"), dict(color="0.6", ls=":"), dict(color="0.75", ls="-."),
                 dict(color="0.5", ls=(0, (6, 2, 1, 2, 1, 2))))


def declutter(fig, labels, step=9):
    """Moves annotations vertically (in steps of `step` points, away from the point) until
    none overlaps one placed before it; returns how many were moved."""
    fig.canvas.draw()
    placed, moved = [], 0
    for a in labels:
        dx, dy = a.xyann
        sign = -1 if dy < 0 else 1
        for _ in range(12):
            box = a.get_window_extent().expanded(1.02, 1.1)
            if not any(box.overlaps(b) for b in placed):
                break
            dy += sign * step
            a.xyann = (dx, dy)
            moved += 1
            fig.canvas.draw()
        placed.append(a.get_window_extent())
    return moved


def finest_axi_run(case):
    """The finest axisymmetric run of a case's reference that completed a cycle and carries its
    U(t) (the run the 1D models' U(t) verdict is judged against); None without one."""
    runs = [r for r in (case.get("reference") or {}).get("runs", []) if r.get("has_cycle") and r.get("series")]
    return runs[-1] if runs else None


def velocity_figure(case, path):
    """U(t) and U against the cycle phase. With 1D models, two rows: the 3D grids and the
    axisymmetric reference above, the 1D models against the reference (the finest axisymmetric
    run, else the finest 3D run) below, so that neither set hides the other."""
    runs = [r for r in case["runs3d"] if r.get("has_cycle")]
    axi = finest_axi_run(case)
    scale = 0.0
    for r in runs + ([axi] if axi is not None else []):
        u = r["series"]["velocity_m_per_s"]
        scale = max(scale, max(abs(v) for v in u) * 1e9 if u else 0.0)
    models, off = [], []
    for k, m in enumerate(case["models1d"]):
        if "series" not in m or not m.get("has_cycle"):
            continue
        u = [v * 1e9 for v in m["series"]["velocity_m_per_s"]]
        if scale > 0 and max(abs(v) for v in u) > 50 * scale:
            off.append(f"{m['label']} (peak {si(max(abs(v) for v in u) * 1e-9, 'm/s')})")
        else:
            models.append((k, m))
    rows = 2 if models else 1
    fig, axs = plt.subplots(rows, 2, figsize=(12, 4.4 * rows), squeeze=False)

    def draw(ax_pair, s, T, *fmt, **kw):
        u = [v * 1e9 for v in s["velocity_m_per_s"]]
        ax_pair[0].plot(s["t_s"], u, *fmt, **kw)
        ax_pair[1].plot([t / T for t in s["t_s"]], u, *fmt, **kw)

    finest_kw = None
    for k, r in enumerate(runs):
        finest = k == len(runs) - 1
        kw = dict(color="k", lw=2, label=f"3D, h = {r['cell_size_m'] * 1e9:.3g} nm (finest)") if finest else \
            dict(COARSE_STYLES[(len(runs) - 2 - k) % len(COARSE_STYLES)], lw=1.0,
                 label=f"3D, h = {r['cell_size_m'] * 1e9:.3g} nm")
        draw(axs[0], r["series"], r["cycle_time_s"], **kw)
        if finest:
            finest_kw = kw
    # the converged reference of U(t) when the case has one: its finest axisymmetric run
    axi_kw = None
    if axi is not None:
        axi_kw = dict(color="C0", lw=2.4, alpha=0.8,
                      label=f"axisymmetric reference, h = {axi['cell_size_m'] * 1e9:.3g} nm (finest; the U(t) verdict's reference)")
        draw(axs[0], axi["series"], axi["cycle_time_s"], **axi_kw)
    if rows == 2:
        if axi is not None:
            draw(axs[1], axi["series"], axi["cycle_time_s"], **axi_kw)
        elif runs:
            draw(axs[1], runs[-1]["series"], runs[-1]["cycle_time_s"], **finest_kw)
        for k, m in models:
            draw(axs[1], m["series"], m["cycle_time_s"], MODEL_STYLES[k % len(MODEL_STYLES)], lw=1.4,
                 label=f"1D: {m['label']}")
    against = "the axisymmetric reference" if axi is not None else "the finest 3D run"
    for i in range(rows):
        what = "3D grids" + (" and the axisymmetric reference" if axi is not None else "") if i == 0 else \
            f"1D models against {against}"
        axs[i][0].set(xlabel="time t [s]", ylabel="swimmer velocity U [nm/s]", title=f"U(t) over the cycle: {what}")
        axs[i][1].set(xlabel="cycle phase t / T_cycle (each tier on its own cycle time)", ylabel="U [nm/s]",
                      title="U against cycle phase")
        for a in axs[i]:
            a.axhline(0, color="0.6", lw=0.6)
    if rows == 2:  # the same velocity scale in both rows
        for j in range(2):
            lo = min(axs[0][j].get_ylim()[0], axs[1][j].get_ylim()[0])
            hi = max(axs[0][j].get_ylim()[1], axs[1][j].get_ylim()[1])
            for i in range(2):
                axs[i][j].set_ylim(lo, hi)
    title = f"{case['name']}: swimmer velocity, 1D against 3D" + (" and the axisymmetric reference" if axi else "")
    if off:
        title += "\noff scale, not drawn: " + "; ".join(off)
    fig.suptitle(title)
    # long model labels wrapped, so that three columns fit the figure's width
    legend_below(fig, [axs[i][0] for i in range(rows)], width=12, height=4.0 * rows, ncol=3, wrap=62, gap=0.12)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def nonnegative_axis(ax, key):
    """A cycle time is positive: its axis starts at zero where an error bar wider than its value
    would run below it (the bar is cut there)."""
    if key == "cycle_time_s" and ax.get_ylim()[0] < 0:
        ax.set_ylim(bottom=0)


FIGURE_PANELS = (("displacement_per_cycle_m", "displacement per cycle [nm]", 1e9),
                 ("cycle_time_s", "cycle time [s]", 1.0),
                 ("max_displacement_m", "maximum centre displacement [nm]", 1e9))


def order_text(e):
    """'observed order 0.82' / 'not asymptotic' for an extrapolation's legend entry."""
    if e is None:
        return "no extrapolation"
    if e.get("phases"):
        orders = ", ".join(f"{q['observed_order']:.2f}" if q.get("observed_order") is not None else "—"
                           for q in e["phases"])
        return f"sum of {len(e['phases'])} phases extrapolated apart (orders {orders})"
    if e.get("direct") is not None:
        return "displacement over the phases' cycle time"
    obs = e.get("observed_order")
    if e.get("asymptotic") and e.get("order"):
        return f"order {e['order']:.2f}" + ("" if obs is not None else " (assumed)")
    if e.get("method") == "expansion_fit":
        return "not asymptotic: f0 + a h + b h² fitted" + (f" (three finest: order {obs:.2f})" if obs is not None else "")
    if e.get("method") == "lumen_fit":
        return "smeared lumen T0 (1 − a h)⁻⁴ fitted" + (f" (three finest: order {obs:.2f})" if obs is not None else "")
    if e.get("within_time_error"):
        return "within the time integration's error: bounded"
    return "not asymptotic" + (f", observed order {obs:.2f}" if obs is not None else "")


def fitted_curve(e, hmax_nm):
    """The 3D extrapolation's fitted curve over h = 0 to hmax_nm (report.json): (h in nm, values in
    the figure's SI unit, legend label), or None when the extrapolation is not a fit."""
    if not e:
        return None
    hs = np.linspace(0.0, hmax_nm, 60) * 1e-9
    fit = e.get("expansion")
    if e.get("method") == "expansion_fit" and fit and None not in fit.values():
        return hs * 1e9, fit["f0"] + fit["a_per_m"] * hs + fit["b_per_m2"] * hs * hs, "3D: fitted f0 + a h + b h²"
    lum = e.get("lumen_fit")
    if e.get("method") == "lumen_fit" and lum and None not in lum.values():
        return hs * 1e9, lum["T0"] * (1.0 - lum["a_per_m"] * hs) ** -4, "3D: fitted T0 (1 − a h)⁻⁴"
    return None


def reference_convergence_figure(case, path):
    """Both grid series of a case with an axisymmetric reference against h: each figure on its
    own panel, the 3D runs and the axi runs, both extrapolations at h = 0 with their error bars
    (fitted orders in the legend), the paper's value where the case has one."""
    ref = case["reference"]
    r3 = [r for r in case["runs3d"] if r.get("has_cycle")]
    ra = [r for r in ref.get("runs", []) if r.get("has_cycle")]
    if not r3 and not ra:
        return False
    paper = (case.get("paper") or {}).get("max_displacement_m")
    panels = [p for p in FIGURE_PANELS if p[0] != "max_displacement_m" or paper]
    fig, axes = plt.subplots(1, len(panels), figsize=(5.4 * len(panels), 6.0))
    # the grids whose run completed no cycle (a failure, a time limit): marked, not left out silently
    def without_cycle(runs):
        bad = [r for r in runs if not r.get("has_cycle") and r.get("cell_size_m")]
        why = " (time limit)" if bad and all("time_limit" in r.get("status", "") for r in bad) else ""
        return [r["cell_size_m"] * 1e9 for r in bad], why

    (no3, why3), (noa, whya) = without_cycle(case["runs3d"]), without_cycle(ref.get("runs", []))
    hmax = max([r["cell_size_m"] * 1e9 for r in r3 + ra] + no3 + noa or [1.0])
    for ax, (key, ylabel, scale) in zip(axes, panels):
        for hs, why, colour, tier in ((no3, why3, "k", "3D"), (noa, whya, "tab:blue", "axisymmetric")):
            for j, h in enumerate(hs):
                ax.axvline(h, color=colour, ls=":", lw=1.0, alpha=0.6,
                           label=None if j else f"{tier} runs without a cycle{why}: h = "
                           + ", ".join(f"{v:.3g}" for v in sorted(hs)) + " nm")
        p3 = [(r["cell_size_m"] * 1e9, r[key] * scale) for r in r3 if r.get(key) is not None]
        pa = [(r["cell_size_m"] * 1e9, r[key] * scale) for r in ra if r.get(key) is not None]
        e3 = case["reference3d"].get(key)
        ea = ref.get(key)
        if p3:
            ax.plot(*zip(*p3), "ko-", ms=5, label=f"3D runs: {order_text(e3)}")
            curve = fitted_curve(e3, max(h for h, _ in p3))  # the suite's fit, h = 0 to the coarsest grid
            if curve:
                ax.plot(curve[0], curve[1] * scale, "k--", lw=0.8, label=curve[2])
        if pa:
            ax.plot(*zip(*pa), "s-", color="tab:blue", ms=5,
                    label=f"axisymmetric runs ({ref.get('method', 'axi')}): {order_text(ea)}")
        if e3 and e3.get("value") is not None:
            ax.errorbar([-0.015 * hmax], [e3["value"] * scale], yerr=[(e3["error"] or 0) * scale], fmt="o", mfc="white",
                        color="k", capsize=4, label="3D extrapolation h → 0 ± error")
        if ea and ea.get("value") is not None:
            conv = "converged" if ea.get("converged") else "not converged"
            ax.errorbar([0.015 * hmax], [ea["value"] * scale], yerr=[(ea["error"] or 0) * scale], fmt="s",
                        color="tab:blue", capsize=4, label=f"axisymmetric reference h → 0 ± error ({conv})")
        if key == "max_displacement_m" and paper:
            ax.axhline(paper * 1e9, color="tab:red", ls=":", lw=1.4, label="paper: maximum displacement over the cycle")
        ax.set_xlim(-0.06 * hmax, 1.06 * hmax)
        ax.set(xlabel="cell size h [nm]", ylabel=ylabel)
        nonnegative_axis(ax, key)
        ax.grid(alpha=0.3)
        # each panel's legend below it, off the data: the orders differ from figure to figure; the
        # labels wrapped to the panel's width (about 10 characters per inch), so that neighbouring
        # legends neither overlap nor run off the figure
        handles, labels = ax.get_legend_handles_labels()
        ax.legend(handles, [textwrap.fill(t, 52) for t in labels], loc="upper center", bbox_to_anchor=(0.5, -0.16),
                  fontsize="small", frameon=False)
    # the statement wrapped to the figure's width (about 9 characters per inch at this size)
    statement = "\n".join(textwrap.wrap(ref.get("statement", ""), int(9 * 5.4 * len(panels))))
    fig.suptitle(f"{case['name']}: grid convergence of the 3D tier and the axisymmetric reference\n{statement}",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


GRID_MARKERS = ("o", "s", "^", "D", "v", "P")


def convergence_figure(case, path):
    """The 3D grid series against h with its extrapolation h -> 0, one panel per figure:
    displacement per cycle and, when the runs have it, the cycle time."""
    if case.get("reference"):
        return reference_convergence_figure(case, path)
    runs = [r for r in case["runs3d"] if r.get("has_cycle")]
    if not runs:
        return False
    panels = [("displacement_per_cycle_m", "displacement per cycle [nm]", 1e9, "nm")]
    if all(r.get("cycle_time_s") is not None for r in runs):
        panels.append(("cycle_time_s", "cycle time [s]", 1.0, "s"))
    fig, axes = plt.subplots(1, len(panels), figsize=(8.0 * len(panels), 6.2), squeeze=False)
    h = [r["cell_size_m"] * 1e9 for r in runs]
    rng = case["reference3d"].get("order_range")
    rng_text = f"[{rng[0]:g}, {rng[1]:g}]" if rng else "the scheme's range"
    for ax, (key, ylabel, scale, unit) in zip(axes[0], panels):
        v = [r[key] * scale for r in runs]
        ax.plot(h, v, "k-", lw=1, label="3D runs")
        for k, (hk, vk) in enumerate(zip(h, v)):  # each grid its own marker, its cell size beside it
            ax.plot([hk], [vk], GRID_MARKERS[k % len(GRID_MARKERS)], color="k", ms=6)
            ax.annotate(f"h = {hk:.3g} nm", (hk, vk), xytext=(6, 4), textcoords="offset points", fontsize=7)
        ref = case["reference3d"].get(key)
        if ref:
            obs = ref.get("observed_order")
            if ref["asymptotic"]:
                what = f" (order {ref['order']:.2f}, accepted in {rng_text})" if ref["order"] else ""
            elif ref.get("method") == "expansion_fit":
                what = " (not asymptotic: f0 + a h + b h² fitted to the grids, error = leave-one-out change)"
            elif ref.get("method") == "lumen_fit":
                what = (" (the smeared lumen: T0 (1 − a h)⁻⁴ fitted to the grids, error = leave-one-out change, "
                        "the finest pair's line or a quarter of the correction)")
            else:
                what = (" (not asymptotic: finest ± spread" +
                        (f"; observed order {obs:.2f} outside {rng_text}" if obs is not None and
                         not (rng and rng[0] <= obs <= rng[1]) else "") + ")")
            curve = fitted_curve(ref, max(h))
            if curve:
                ax.plot(curve[0], curve[1] * scale, "k--", lw=0.8, label=curve[2])
            ax.errorbar([0], [ref["value"] * scale], yerr=[ref["error"] * scale], fmt="rs", capsize=4,
                        label="3D reference h → 0 ± error" + what)
        for k, m in enumerate(case["models1d"]):
            if m.get("has_cycle") and m.get(key) is not None and ref and abs(m[key]) < 20 * abs(ref["value"]):
                ax.axhline(m[key] * scale, color=f"C{k + 1}", ls="--", lw=1, label=f"1D: {m['label']}")
        paper = (case.get("paper") or {}).get("max_displacement_m")
        if paper and key == "displacement_per_cycle_m":
            ax.axhline(paper * 1e9, color="0.4", ls=":", lw=1.2, label="paper: maximum displacement over the cycle")
        ax.set(xlabel="cell size h [nm]", ylabel=ylabel)
        ax.set_xlim(left=-0.05 * max(h), right=1.2 * max(h))
        nonnegative_axis(ax, key)
        ax.grid(alpha=0.3)
        handles, labels = ax.get_legend_handles_labels()
        ax.legend(handles, [textwrap.fill(t, 60) for t in labels], loc="upper center", bbox_to_anchor=(0.5, -0.13),
                  fontsize="small", frameon=False, ncol=1)
    fig.suptitle(f"{case['name']}: 3D grid convergence")
    save(fig, path)
    return True


def pareto_figure(report, path):
    """Error against wall time of every run of the speed/accuracy study. With a few cases each
    (case, tier, axis) is its own line with its resolutions written beside the points; with
    many, the colour and marker say the tier and the axis (one legend entry each) and each
    case is a thin line, without point labels."""
    cases = [c for c in report["cases"]
             if any(q.get("displacement_per_cycle_error", 0) > 0 for q in c.get("speed_accuracy", []))]
    if not cases:
        return False
    many = len(cases) > 3
    fig, ax = plt.subplots(figsize=(9, 5.2))
    markers = {"cells": "o-", "rtol": "^--", "h": "s-", "time step": "D--"}
    texts = []
    colours = {("1d", "cells"): "tab:blue", ("1d", "rtol"): "tab:orange", ("3d", "h"): "black",
               ("3d", "time step"): "tab:red"}
    named = set()
    for c in cases:
        pts = [q for q in c.get("speed_accuracy", []) if q.get("displacement_per_cycle_error", 0) > 0]
        axes = []
        for q in pts:
            if (q["tier"], q.get("axis", "")) not in axes:
                axes.append((q["tier"], q.get("axis", "")))
        for tier, axis in axes:
            p = [q for q in pts if q["tier"] == tier and q.get("axis", "") == axis]
            p.sort(key=lambda q: q["wall_time_s"])
            xs = [q["wall_time_s"] for q in p]
            ys = [100 * q["displacement_per_cycle_error"] for q in p]
            if many:
                key = (tier, axis)
                label = None if key in named else f"{tier.upper()}, varying {axis}"
                named.add(key)
                ax.loglog(xs, ys, markers.get(axis, "x-"), color=colours.get(key, "tab:gray"), lw=0.8, ms=4,
                          alpha=0.8, label=label)
                continue
            ax.loglog(xs, ys, markers.get(axis, "x-"), label=f"{c['name']}, {tier.upper()}, varying {axis}")
            # labels above left for the resolution axes, below right for the tolerance and step
            # axes, fanned out so that points that coincide stay readable
            below = axis in ("rtol", "time step")
            for j, q in enumerate(p):
                texts.append(ax.annotate(q["resolution"], (q["wall_time_s"], 100 * q["displacement_per_cycle_error"]),
                                         fontsize=7, xytext=(4, -10) if below else (-4, 4),
                                         textcoords="offset points", ha="left" if below else "right"))
    ax.set(xlabel="wall time [s] (log scale)", ylabel="error in displacement per cycle [%] (log scale)")
    # plain numbers on the error axis (1, 2, 5, 10, 20, ...), not 4×10¹
    fmt = matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}")
    ax.yaxis.set_major_formatter(fmt)
    ax.yaxis.set_minor_formatter(matplotlib.ticker.FuncFormatter(
        lambda v, _: f"{v:g}" if f"{v:.1e}"[0] in "25" else ""))
    # each case's error is taken against its judged reference: the axisymmetric one where the
    # case has it, else the 3D extrapolation
    axi = [bool(c.get("reference")) for c in cases]
    against = ("error against the converged axisymmetric reference" if all(axi)
               else "error against the extrapolated 3D reference" if not any(axi)
               else "error against the axisymmetric reference where a case has one, else the 3D extrapolation")
    sub = f"{len(cases)} cases, one line per case and axis\n{against}" if many else against
    fig.suptitle(f"Speed against accuracy: {report['suite']} suite\n{sub}")
    legend_right(ax)
    fig.tight_layout()  # the final axes size, so that the labels are placed where they are drawn
    declutter(fig, texts)
    save(fig, path)
    return True


def sweep_figure(report, group, xlabel, key, ylabel, scale, path, title, logx=False):
    cases = sorted([c for c in report["cases"] if c.get("group") == group and c.get("sweep_value") is not None],
                   key=lambda c: c["sweep_value"])
    if len(cases) < 2:
        return False
    fig, ax = plt.subplots(figsize=(9, 4.6))
    x = [c["sweep_value"] for c in cases]
    y, e = [], []
    axi = [bool(c.get("reference")) for c in cases]
    for c in cases:
        ref = (c.get("reference") or c["reference3d"]).get(key)
        y.append(ref["value"] * scale if ref and ref.get("value") is not None else float("nan"))
        e.append(ref["error"] * scale if ref and ref.get("error") is not None else 0)
    label = ("axisymmetric reference (h → 0)" if all(axi) else "3D reference (h → 0, or finest grid)" if not any(axi)
             else "reference (axisymmetric where the case has one, else 3D)")
    ax.errorbar(x, y, yerr=e, fmt="ks-", capsize=4, label=label)
    if any(axi):
        y3, e3 = [], []
        for c in cases:
            ref = c["reference3d"].get(key)
            y3.append(ref["value"] * scale if ref and ref.get("value") is not None else float("nan"))
            e3.append(ref["error"] * scale if ref and ref.get("error") is not None else 0)
        ax.errorbar(x, y3, yerr=e3, fmt="o--", color="0.5", mfc="white", capsize=3, label="3D extrapolation (h → 0)")
    labels = [m["label"] for m in cases[0]["models1d"]]
    ref_max = max((abs(b) for b in y if math.isfinite(b)), default=0.0)
    unit = "m/s" if key.endswith("_per_s") else "m"
    off = []
    for k, lab in enumerate(labels):
        v = []
        for c in cases:
            m = next((m for m in c["models1d"] if m["label"] == lab), None)
            v.append(m[key] * scale if m and key in m else float("nan"))
        if all(not math.isfinite(a) for a in v):
            continue
        # a model more than 50 times the references anywhere (the paper's reproduction mode)
        # would flatten every other line: named in the title instead
        big = [a for a in v if math.isfinite(a) and abs(a) > 50 * ref_max]
        if big:
            off.append(f"1D: {lab} (up to {si(max(abs(a) for a in big) / scale, unit)})")
            continue
        ax.plot(x, v, MODEL_STYLES[k % len(MODEL_STYLES)] + "o", label=f"1D: {lab}")
    ax.set(xlabel=xlabel, ylabel=ylabel)
    sup = f"{report['suite']} suite: {title}"
    if off:
        sup += "\n" + textwrap.fill("off scale, not drawn: " + "; ".join(off), 110)
    fig.suptitle(sup)
    if logx:
        ax.set_xscale("log")
        ax.set_xticks(x)
        ax.set_xticklabels([f"{v:g}" for v in x])
        ax.minorticks_off()
    legend_below(fig, ax)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def multicycle_figure(report, path):
    cases = [c for c in report["cases"] if c.get("group") == "optimal"]
    if not cases:
        return False
    fig, ax = plt.subplots(figsize=(9, 4.6))
    off = []
    for c in cases:
        for r in c["runs3d"]:
            fin = r is c["runs3d"][-1]
            ax.plot(r["series"]["t_s"], [v * 1e9 for v in r["series"]["x_m"]], "-",
                    color="black" if fin else "0.6", lw=2 if fin else 1,
                    label=f"3D, h = {si(r['cell_size_m'], 'm')} ({r.get('cycles_completed', 0)} cycles, {r['status'][:6]})")
        x3 = max((abs(v) for r in c["runs3d"] for v in r["series"]["x_m"]), default=0.0)
        for k, m in enumerate(c["models1d"]):
            if "series" not in m:
                continue
            if x3 > 0 and max(abs(v) for v in m["series"]["x_m"]) > 50 * x3:
                off.append(m["label"])
                continue
            ax.plot(m["series"]["t_s"], [v * 1e9 for v in m["series"]["x_m"]], MODEL_STYLES[k % 6],
                    label=f"1D: {m['label']}")
    title = f"{cases[0]['name']}: centre displacement over the run (Figure 14)"
    if off:
        title += "\noff scale, not drawn: " + ", ".join(off)
    ax.set(xlabel="time t [s]", ylabel="centre displacement [nm]")
    fig.suptitle(title)
    legend_right(ax)
    save(fig, path)
    return True


def decode_vtk_binary(body, compressed):
    """Bytes of one inline binary DataArray (header_type UInt32): a byte count and the
    values, or with vtkZLibDataCompressor a block header (base64 on its own) and the
    zlib-compressed blocks."""
    if not compressed:
        raw = base64.b64decode(body)
        n = struct.unpack("<I", raw[:4])[0]
        return raw[4:4 + n]
    blocks = struct.unpack("<I", base64.b64decode(body[:8])[:4])[0]
    header_bytes = 4 * (3 + blocks)
    header_chars = 4 * ((header_bytes + 2) // 3)
    h = struct.unpack(f"<{3 + blocks}I", base64.b64decode(body[:header_chars])[:header_bytes])
    packed = base64.b64decode(body[header_chars:])
    out, at = b"", 0
    for b in range(blocks):
        out += zlib.decompress(packed[at:at + h[3 + b]])
        at += h[3 + b]
    return out


def read_vtp_points(path):
    """Node coordinates of a membrane frame written by swim (VTK XML PolyData, binary
    inline Float32 or Float64, plain or zlib-compressed)."""
    with open(path) as f:
        text = f.read()
    m = re.search(r'<Points>\s*<DataArray[^>]*type="(Float32|Float64)"[^>]*>\s*([A-Za-z0-9+/=\s]+?)\s*</DataArray>', text)
    if not m:
        return None
    raw = decode_vtk_binary(re.sub(r"\s", "", m.group(2)), 'compressor="vtkZLibDataCompressor"' in text)
    size = 4 if m.group(1) == "Float32" else 8
    n = len(raw) // size
    v = struct.unpack(f"<{n}{'f' if size == 4 else 'd'}", raw[:n * size])
    return [v[i:i + 3] for i in range(0, n, 3)]


def membrane_figure(case, path):
    """Side views of the membrane over one cycle from the finest 3D run's frames (Figure 5)."""
    runs = [r for r in case["runs3d"] if r.get("membrane_frames")]
    if not runs or not runs[-1].get("has_cycle"):
        return False
    run = runs[-1]
    folder = run["folder"]
    try:
        with open(f"{folder}/membrane.pvd") as f:
            pvd = f.read()
        with open(f"{folder}/summary.json") as f:
            summ = json.load(f)
    except OSError:
        return False
    frames = [(float(t), fn) for t, fn in re.findall(r'timestep="([^"]+)"[^>]*file="([^"]+)"', pvd)]
    T = run["cycle_time_s"]
    frames = [fr for fr in frames if fr[0] <= T * (1 + 1e-9)]
    if len(frames) < 2:
        return False
    pick = [frames[round(k * (len(frames) - 1) / min(7, len(frames) - 1))] for k in range(min(7, len(frames) - 1) + 1)]
    n_theta = summ["derived"]["n_theta"]
    R0 = summ["derived"]["aspect_ratio_R0_over_L"] * case["length_m"]
    fig, ax = plt.subplots(figsize=(8, 1.1 * len(pick) + 1.2))
    x0 = None
    offsets = []
    for k, (t, fn) in enumerate(pick):
        pts = read_vtp_points(f"{folder}/{fn}")
        if not pts:
            continue
        yc = sum(p[1] for p in pts) / len(pts)
        zc = sum(p[2] for p in pts) / len(pts)
        if x0 is None:
            x0 = min(p[0] for p in pts)
        rings = len(pts) // n_theta
        top, bot = [], []
        for r in range(rings):
            ring = pts[r * n_theta:(r + 1) * n_theta]
            hi = max(ring, key=lambda p: p[1] - yc)  # the node facing +y: the upper outline
            lo = min(ring, key=lambda p: p[1] - yc)
            top.append(((hi[0] - x0) * 1e6, (hi[1] - yc) * 1e9))
            bot.append(((lo[0] - x0) * 1e6, (lo[1] - yc) * 1e9))
        off = -k * 3.0 * R0 * 1e9
        offsets.append(off)
        for line in (top, bot):
            ax.plot([q[0] for q in line], [q[1] + off for q in line], "k-", lw=1.2)
        ax.plot([0, 0], [off - R0 * 1e9, off + R0 * 1e9], color="0.8", lw=0.6)
        ax.annotate(f"t = {si(t, 's')}", (0, off), xytext=(-8, 0), textcoords="offset points", ha="right",
                    va="center", fontsize=8)
    ax.set_xlabel("axial position from the tube's initial rear end [µm]")
    ax.set_ylabel("transverse position about each snapshot's axis [nm]\n(snapshots offset by 3 R₀)")
    # y ticks: -R0, 0 and +R0 about each snapshot's axis
    ticks = [(off + d, f"{d:.0f}") for off in offsets for d in (-R0 * 1e9, 0.0, R0 * 1e9)]
    ax.set_yticks([t for t, _ in ticks], [lab for _, lab in ticks], fontsize=7)
    ax.set_aspect("auto")
    ax.set_title(f"Membrane side view over one cycle: {case['name']}\n(3D, h = {si(run['cell_size_m'], 'm')}; "
                 f"the grey bar marks the initial rear end)")
    xmin, xmax = ax.get_xlim()
    ax.set_xlim(xmin - 0.25 * (xmax - xmin), xmax)
    save(fig, path)
    return True


def suite_wall_time(report):
    """The suite's wall time, and when 3D grid runs came from the cache, what they took when they ran."""
    runs = {}
    for case in report["cases"]:
        for run in case.get("runs3d", []):
            runs[run.get("folder", id(run))] = run
    cached = [r for r in runs.values() if r.get("cached")]
    text = si(report["wall_time_s"], "s")
    if cached:
        made = sum(r.get("wall_time_s") or 0.0 for r in cached)
        text += (f" ({len(cached)} of the {len(runs)} distinct 3D grid runs came from the cache; "
                 f"they took {si(made, 's')} when they ran)")
    return text


def ref_words(report):
    """Which reference the cases are judged against."""
    axi = [c["name"] for c in report["cases"] if c.get("reference")]
    if not axi:
        return "the extrapolated 3D reference"
    if len(axi) == len(report["cases"]):
        return "the extrapolated axisymmetric reference (`--tier axi`)"
    return ("the extrapolated axisymmetric reference for " + ", ".join(axi) +
            ", the extrapolated 3D reference for the others")


TARGET_WORDS = {"displacement_per_cycle": "displacement", "cycle_time": "cycle time",
                "mean_velocity_per_cycle": "velocity", "velocity_phase_correlation": "U(t)"}


def targets_words(tg):
    """A case's 1D design targets in words: '10 / 15 / 15 %, U(t) ≥ 0.8'"""
    return (f"{100 * tg['displacement_per_cycle_relative']:g} / {100 * tg['cycle_time_relative']:g} / "
            f"{100 * tg['mean_velocity_per_cycle_relative']:g} %, U(t) ≥ {tg['velocity_phase_correlation']:g}")


def target_text(m):
    """A 1D model's verdicts against its case's design targets: 'met 2 of 4 (fail: cycle time; inconclusive: U(t))'"""
    tv = m.get("target_verdicts") or {}
    if not tv:
        return "—"
    met = sum(1 for v in tv.values() if v == "pass")
    rest = []
    for status in ("fail", "inconclusive", "not assessed"):
        names = [TARGET_WORDS.get(k, k) for k, v in tv.items() if v == status]
        if names:
            rest.append(f"{status}: {', '.join(names)}")
    return f"met {met} of {len(tv)}" + (f" ({'; '.join(rest)})" if rest else "")


def targets_markdown(report):
    """The 1D models against the 1D tier's design targets, case by case (cases with targets1d)"""
    cases = [c for c in report["cases"] if c.get("targets1d")]
    if not cases:
        return []
    labels = []
    for c in cases:
        for m in c.get("models1d", []):
            if m["label"] not in labels:
                labels.append(m["label"])
    kinds = {}
    for c in cases:
        kinds.setdefault(targets_words(c["targets1d"]), []).append(c["name"])
    out = ["", "## The 1D models against the 1D tier's design targets", "",
           "Each 1D model judged by the verdicts' rules (against the case's reference and its error bar) "
           "with the 1D tier's design targets instead of the suite's thresholds: "
           + "; ".join(f"{w} for {', '.join(names)}" for w, names in kinds.items())
           + " (displacement per cycle / cycle time / mean velocity per cycle, and the U(t) phase correlation).",
           "", "| model | " + " | ".join(c["name"] for c in cases) + " |", "|---" * (len(cases) + 1) + "|"]
    for label in labels:
        row = []
        for c in cases:
            m = next((m for m in c.get("models1d", []) if m["label"] == label), None)
            row.append("—" if m is None else (target_text(m) if m.get("has_cycle") else "no cycle"))
        out.append(f"| {label} | " + " | ".join(row) + " |")
    return out



def markdown(report, figs):
    th = report["thresholds"]
    sel = report.get("cases_selected") or []
    out = [f"# Validation report: {report['suite']} suite", "", report.get("description", ""), "",
           *( [f"**Subset**: only the case(s) {', '.join(sel)} of the suite were run (`--case`); the paper's "
               "conclusions that need the other cases are not assessed.", ""] if sel else []),
           f"Wall time of the suite: {suite_wall_time(report)}. Thresholds: displacement per cycle "
           f"±{100 * th['displacement_per_cycle_relative']:.0f} %, cycle time ±{100 * th['cycle_time_relative']:.0f} %, "
           f"mean velocity per cycle ±{100 * th['mean_velocity_per_cycle_relative']:.0f} % (1D against the "
           f"case's reference: {ref_words(report)}); U(t) phase correlation ≥ {th['velocity_phase_correlation']} "
           "(against the finest axisymmetric run where the case has an axisymmetric reference, else the finest 3D "
           "run); each verdict against the reference's error bar.", "",
           "## The paper's conclusions", "",
           "Every value carries the error of its 3D reference (the extrapolation's, or the spread of the grids "
           "when they are not in the asymptotic range). Two values differ when |a − b| exceeds e_a + e_b (their "
           "error bars do not overlap); a status is *inconclusive* when the error bars cannot decide it, with what "
           "would settle it.", "",
           "| claim | status | values (± error) | rule |", "|---|---|---|---|"]
    for f in report["findings"]:
        status = f"**{f['status']}**"
        if f.get("to_settle"):
            status += f": {f['to_settle']}"
        elif f.get("reason"):
            status += f": {f['reason']}"
        out.append(f"| {cell(f['claim'])} | {cell(status)} | {cell(finding_values(f))} | {cell(f.get('rule', ''))} |")
    out += targets_markdown(report)
    ex = report.get("extremes3d") or []
    if ex:
        n_ok = sum(1 for e in ex if e["as_expected"])
        out += ["", "## 3D at the extremes", "",
                f"{n_ok} of {len(ex)} cases ended as the suite states they should. Each states its expected outcome: "
                "a valid result (ok), a numerical failure naming its cause and the key to change (failed, exit 3), "
                "or a rejection as input (rejected, exit 2).", "",
                "| case | expected | outcome | as expected | displacement / cycle | message |", "|---|---|---|---|---|---|"]
        for e in ex:
            msg = e["message"].replace("|", "/")
            msg = msg[:160] + ("…" if len(msg) > 160 else "")
            out.append(f"| {e['label']} | {e['expected']}{' (' + e['expected_cause'] + ')' if e['expected_cause'] else ''} "
                       f"| {e['outcome']} | {'yes' if e['as_expected'] else '**no**'} | "
                       f"{si(e.get('displacement_per_cycle_m'), 'm')} | {msg} |")
    for c in report["cases"]:
        out += ["", f"## {c['name']}", "", c.get("description", ""), "", "### 3D runs", "",
                "| grid | h | status | displacement / cycle | cycle time | mean velocity / cycle | wall wrinkle | steps | wall time |",
                "|---|---|---|---|---|---|---|---|---|"]
        for r in c["runs3d"]:
            out.append(f"| {json.dumps(r['grid_value'])} | {si(r['cell_size_m'], 'm')} | {r['status'][:60]} | "
                       f"{si(r.get('displacement_per_cycle_m'), 'm')} | {si(r.get('cycle_time_s'), 's')} | "
                       f"{si(r.get('mean_velocity_per_cycle_m_per_s'), 'm/s')} | "
                       f"{wrinkle(r)} | {r['steps']} | "
                       f"{si(r['wall_time_s'], 's')}{' (cached)' if r['cached'] else ''} |")
        out += wrinkle_paragraph(c["runs3d"])
        ref = c["reference3d"]
        rng = ref.get("order_range")
        out += ["", "Extrapolated 3D reference (h → 0"
                + (f"; observed orders accepted in [{rng[0]:g}, {rng[1]:g}]" if rng else "") + "):", ""]
        for key, unit in (("displacement_per_cycle_m", "m"), ("cycle_time_s", "s"),
                          ("mean_velocity_per_cycle_m_per_s", "m/s")):
            if key in ref:
                e = ref[key]
                out.append(f"- {key.rsplit('_', 1)[0] if unit != 'm/s' else 'mean velocity per cycle'}: "
                           f"{si(e['value'], unit)} ± {si(e['error'], unit)}; {e['note']}"
                           + (f", order {e['order']:.2f}" if e["asymptotic"] and e["order"] else ""))
        if "note" in ref:
            out.append(f"- {ref['note']}")
        if c.get("reference"):
            out += reference_markdown(c)
        if c.get("paper"):
            p = c["paper"]
            out += ["", f"Paper: maximum displacement {si(p.get('max_displacement_m'), 'm')} ({p.get('source', '')}); "
                    f"here, finest 3D run's displacement per cycle "
                    f"{si(c['runs3d'][-1].get('displacement_per_cycle_m'), 'm')}."]
        cal = c["calibration"]
        out += ["", "### Calibration (at grid " + json.dumps(cal["grid_value"]) + ")", ""]
        if "C1_Pa_per_m" in cal:
            out.append(f"C1 = {si(cal['C1_Pa_per_m'], 'Pa/m', 5)} ± {si(cal['C1_stderr_Pa_per_m'], 'Pa/m')} "
                       f"(spring-network value {si(cal['C1_spring_network_Pa_per_m'], 'Pa/m', 5)}); hydraulic offsets "
                       f"a_in = {si(cal.get('hydraulic_offset_inner_m'), 'm')} ± "
                       f"{si(cal.get('hydraulic_offset_inner_uncertainty_m'), 'm')}, a_out = "
                       f"{si(cal.get('hydraulic_offset_outer_m'), 'm')} ± "
                       f"{si(cal.get('hydraulic_offset_outer_uncertainty_m'), 'm')} (profile fits).")
            if "towed_drag_coefficient_N_s_per_m" in cal:
                out.append(f"Towed tube: drag coefficient {si(cal['towed_drag_coefficient_N_s_per_m'], 'N s/m', 4)}, "
                           f"a_out from the drag = {si(cal.get('hydraulic_offset_outer_from_drag_m'), 'm')} ± "
                           f"{si(cal.get('hydraulic_offset_outer_from_drag_uncertainty_m'), 'm')}"
                           + (" (no root in the physical range: see calibration.json)."
                              if cal.get("hydraulic_offset_outer_from_drag_m") is None else "."))
        else:
            out.append(f"Not available: {cal.get('status', 'unknown')}")
        out += ["", "### 1D models", "",
                f"vs ref: the relative difference from the {'axisymmetric' if c.get('reference') else '3D'} reference "
                "± the reference's relative error; U(t) phase correlation ± its spread over the three finest grids, "
                + ("against the finest axisymmetric run (the verdict's), then against the finest 3D run (informative)"
                   if c.get("reference") else "against the finest 3D run")
                + ". A verdict passes when the whole interval lies inside the "
                "tolerance, fails when it lies wholly outside, and is inconclusive otherwise.", "",
                *([f"Targets: the 1D tier's design targets for this case ({targets_words(c['targets1d'])}), "
                   "judged by the same rule.", ""] if c.get("targets1d") else []),
                "| model | displacement / cycle | vs ref | cycle time | vs ref | mean velocity / cycle | vs ref | "
                f"U(t) phase corr. {'vs axi; vs 3D' if c.get('reference') else 'vs 3D'} | verdicts | "
                + ("targets | " if c.get("targets1d") else "") + "wall time |",
                "|---|---|---|---|---|---|---|---|---|" + ("---|" if c.get("targets1d") else "") + "---|"]
        for m in c["models1d"]:
            if not m.get("has_cycle"):
                out.append(f"| {m['label']} | {m.get('status', '')[:200]} {m.get('no_cycle_reason', '')} "
                           "| | | | | | | | |" + (" |" if c.get("targets1d") else ""))
                continue
            e = m.get("relative_error_vs_reference", {})
            re_ = m.get("reference_error_relative", {})
            verd = ", ".join(f"{k}: {w}" for k, w in m.get("verdicts", {}).items())

            def corr_text(v):
                corr = v.get("phase_correlation")
                spread = v.get("phase_correlation_grid_spread")
                if corr is None:
                    return "—" + (f" ({v['note']})" if v.get("note") else "")
                return f"{corr:.2f}" + ("" if spread is None else f" ± {spread:.2f}")
            u_corr = corr_text(m.get("velocity_vs_finest3d", {}))
            if c.get("reference"):
                u_corr = f"axi: {corr_text(m.get('velocity_vs_reference', {}))}; 3D: {u_corr}"

            def vs(k):
                err = re_.get(k)
                return pct(e.get(k)) + ("" if err is None or e.get(k) is None else f" ± {100 * err:.2g} %")
            # a result no Stokes swimmer can give (faster than its wave: more than its length per
            # cycle) is marked, not only failed
            length = c.get("length_m")
            faster = length is not None and abs(m["displacement_per_cycle_m"]) > length
            label = m['label'] + (" (**implausible**: more than its length per cycle, which no Stokes swimmer does)"
                                  if faster or not m.get("plausible", True) else "")
            out.append(f"| {label} | {si(m['displacement_per_cycle_m'], 'm')} | {vs('displacement_per_cycle')} | "
                       f"{si(m['cycle_time_s'], 's')} | {vs('cycle_time')} | "
                       f"{si(m['mean_velocity_per_cycle_m_per_s'], 'm/s')} | {vs('mean_velocity_per_cycle')} | "
                       f"{u_corr} | {verd} | " + (f"{target_text(m)} | " if c.get("targets1d") else "")
                       + f"{si(m['wall_time_s'], 's')} |")
        out += phases_markdown(c)
        if "wall_time_ratio_3d_over_1d" in c:
            out += ["", f"Wall time, 3D run at the calibration grid against the first 1D model: "
                        f"{c['wall_time_ratio_3d_over_1d']:.3g} ×."]
        for f in figs.get(c["name"], []):
            out += ["", f"![{f}]({f})"]
    for f in figs.get("", []):
        out += ["", f"![{f}]({f})"]
    return "\n".join(out) + "\n"



FIGURE_WORDS = (("displacement_per_cycle_m", "displacement per cycle", "m"), ("cycle_time_s", "cycle time", "s"),
                ("mean_velocity_per_cycle_m_per_s", "mean velocity per cycle", "m/s"),
                ("max_displacement_m", "maximum displacement", "m"))


def pm_in_unit_of(v, e, unit):
    """'80 ms ± 0.1 ms': v with its SI prefix and e (two digits) in the same prefix; e with a
    prefix of its own when it is below 10^-4 of that prefix's unit."""
    text = si(v, unit)
    if e is None:
        return text
    scale, p = si_prefix(v) if v else (1.0, "")
    prefix_unit = p + unit
    x = abs(e) / scale
    es = f"{x:.2g}"
    if "e" in es:
        es = f"{x:.0f}" if x >= 1 else None
    return f"{text} ± " + (f"{es} {prefix_unit}" if es else si(e, unit, 2))


def phase_groups(n):
    """The protocol's n phases (n - 1 segment contractions, front segment first, then the
    recovery) in the groups the phase table shows: (label, phase indices)."""
    k = n - 1
    groups = [("first contraction (front segment)", [0])]
    if k > 2:
        groups.append((f"contractions 2–{k - 1}", list(range(1, k - 1))))
    if k > 1:
        groups.append((f"last contraction (rear segment, {k})", [k - 1]))
    groups.append(("recovery", [n - 1]))
    return groups


def phases_of(run, n):
    """A run's or model's protocol phases, (durations, displacements), when it completed a cycle
    with n of them; None otherwise."""
    t, d = run.get("cycle_phase_times_s") or [], run.get("cycle_phase_displacements_m") or []
    return (t, d) if run.get("has_cycle") and len(t) == n and len(d) == n else None


def group_sum(vals, idx):
    """The sum of a phase group's values."""
    return sum(vals[i] for i in idx)


def phase_reference(c):
    """The reference's phases: (source words, durations, their errors or None, the centre's
    displacement over each) from the axisymmetric reference (its extrapolated phase durations,
    the displacements of its finest run), else the finest 3D run; None without them."""
    run = finest_axi_run(c)
    if run is not None:
        disp = run.get("cycle_phase_displacements_m")
        ext = ((c.get("reference") or {}).get("cycle_time_s") or {}).get("phases")
        if not disp:
            return None
        if ext and len(ext) == len(disp) and all(p.get("value") is not None for p in ext):
            return ("axisymmetric reference: durations extrapolated, ± their error bars; displacements of its "
                    f"finest grid, h = {si(run['cell_size_m'], 'm')}",
                    [p["value"] for p in ext], [p.get("error") for p in ext], disp)
        times = run.get("cycle_phase_times_s")
        if times and len(times) == len(disp):
            return (f"finest axisymmetric run, h = {si(run['cell_size_m'], 'm')}", times, None, disp)
        return None
    runs = [r for r in c.get("runs3d", []) if r.get("has_cycle") and r.get("cycle_phase_displacements_m")]
    if not runs:
        return None
    r = runs[-1]
    return (f"finest 3D run, h = {si(r['cell_size_m'], 'm')}", r["cycle_phase_times_s"], None,
            r["cycle_phase_displacements_m"])


def phase_3d(c, n):
    """Beside an axisymmetric reference, the finest 3D run with the reference's n phases (the
    tier the reference judges, phase by phase); None otherwise."""
    if finest_axi_run(c) is None:
        return None
    runs = [r for r in c.get("runs3d", []) if phases_of(r, n)]
    return runs[-1] if runs else None


def phase_models(c, disp):
    """The 1D models of a case whose phases match the reference's (disp: the reference's
    displacement over each): (index, model), and the labels of those whose distance in a phase
    group exceeds 50 times the reference's largest (drawn off scale: named, not drawn)."""
    groups = phase_groups(len(disp))
    scale = max(abs(group_sum(disp, idx)) for _, idx in groups)
    keep, off = [], []
    for k, m in enumerate(c.get("models1d", [])):
        ph = phases_of(m, len(disp))
        if ph is None:
            continue
        big = max(abs(group_sum(ph[1], idx)) for _, idx in groups)
        if scale > 0 and big > 50 * scale:
            off.append(m["label"])
        else:
            keep.append((k, m))
    return keep, off


def phases_figure(case, path):
    """The cycle phase by phase: per phase group (first contraction, the middle ones, the last,
    the recovery) the time it took (log scale) and the distance the centre moved over it, the
    reference's bar with its error bar beside each 1D model's. False when the case has no
    reference phases or no 1D model with them."""
    ref = phase_reference(case)
    if ref is None:
        return False
    words, times, errs, disp = ref
    n = len(times)
    groups = phase_groups(n)
    models, off = phase_models(case, disp)
    if not models:
        return False
    r3 = phase_3d(case, n)
    fig, axs = plt.subplots(1, 2, figsize=(13, 4.6))
    width = 0.84 / (len(models) + 1 + (r3 is not None))
    xs = range(len(groups))

    def group_sums(vals):
        return [group_sum(vals, idx) for _, idx in groups]
    bars = [("reference", group_sums(times), None if errs is None or any(e is None for e in errs)
             else group_sums(errs), group_sums(disp), dict(color="k"))]
    if r3 is not None:
        bars.append((f"3D, finest grid (h = {si(r3['cell_size_m'], 'm')})", group_sums(r3["cycle_phase_times_s"]), None,
                     group_sums(r3["cycle_phase_displacements_m"]), dict(color="0.6", hatch="//", edgecolor="0.3")))
    for k, m in models:
        style = MODEL_STYLES[k % len(MODEL_STYLES)]
        bars.append((f"1D: {m['label']}", group_sums(m["cycle_phase_times_s"]), None,
                     group_sums(m["cycle_phase_displacements_m"]), dict(color=style[:2])))
    for j, (label, t, e, d, kw) in enumerate(bars):
        at = [x - 0.42 + (j + 0.5) * width for x in xs]
        axs[0].bar(at, [v * 1e3 for v in t], width, label=label,
                   yerr=None if e is None else [v * 1e3 for v in e], capsize=2, **kw)
        axs[1].bar(at, [v * 1e9 for v in d], width, label=label, **kw)
    names = [textwrap.fill(g[0], 18) for g in groups]
    axs[0].set_yscale("log")
    # labelled ticks at 1, 2 and 5 of each decade: the groups' times span one to three decades
    axs[0].yaxis.set_major_locator(matplotlib.ticker.LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    axs[0].yaxis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}"))
    axs[0].yaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    axs[0].set(ylabel="time the phases took [ms] (log scale)", title="Time of each phase group")
    axs[1].set(ylabel="distance the centre moved [nm]", title="Distance over each phase group")
    axs[1].axhline(0, color="0.5", lw=0.7)
    for a in axs:
        a.set_xticks(list(xs))
        a.set_xticklabels(names, fontsize="small")
    title = (f"{case['name']}: the cycle phase by phase, " + ("3D and " if r3 is not None else "")
             + f"1D models against the reference\n({words})")
    if off:
        title += "\noff scale, not drawn: " + "; ".join(off)
    fig.suptitle("\n".join(textwrap.fill(line, 120) for line in title.split("\n")))
    legend_below(fig, list(axs), width=13, height=4.6, ncol=3, wrap=62, gap=0.12)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def phases_markdown(c):
    """Where each 1D model's cycle parts from the reference's: the protocol's phases grouped
    (first contraction, the middle ones, the last, the recovery), each with what it took and
    what the centre moved over it, against the reference's."""
    ref = phase_reference(c)
    if ref is None:
        return []
    words, times, errs, disp = ref
    n = len(times)
    groups = phase_groups(n)
    if not any(phases_of(m, n) for m in c.get("models1d", [])):
        return []  # no 1D model to set against the reference (a multi-cycle 1D run keeps its last cycle's events)
    r3 = phase_3d(c, n)
    head = "| | " + " | ".join(g[0] for g in groups) + " |"
    out = ["", "#### The cycle phase by phase", "",
           f"The protocol's phases grouped (each segment's contraction until it reaches R_f, front segment first; "
           f"the recovery until the cycle ends): the time each group took and the distance the centre moved over "
           f"it. Reference: the {words}"
           + ("; beside it the finest 3D run, the tier it judges" if r3 is not None else "")
           + ". A model's time is given with its difference from the reference's, "
           "its distance with the difference in distance (a phase's distance can be near zero or negative, where a "
           "percentage says nothing).", "", head, "|---|" + "---|" * len(groups)]
    cells = []
    for _, idx in groups:
        e = None if errs is None or any(errs[i] is None for i in idx) else group_sum(errs, idx)
        cells.append(f"{pm_in_unit_of(group_sum(times, idx), e, 's')}; {si(group_sum(disp, idx), 'm')}")
    out.append("| reference | " + " | ".join(cells) + " |")

    def against(label, mt, md):
        cells = []
        for _, idx in groups:
            t, tr = group_sum(mt, idx), group_sum(times, idx)
            d, dr = group_sum(md, idx), group_sum(disp, idx)
            dd = si(d - dr, "m")
            cells.append(f"{si(t, 's')} ({pct((t - tr) / tr if tr > 0 else None)}); {si(d, 'm')} "
                         f"({'' if dd.startswith('-') or dd == '—' else '+'}{dd})")
        return f"| {label} | " + " | ".join(cells) + " |"
    if r3 is not None:
        out.append(against(f"3D, finest grid (h = {si(r3['cell_size_m'], 'm')})", r3["cycle_phase_times_s"],
                           r3["cycle_phase_displacements_m"]))
    for m in c.get("models1d", []):
        if not m.get("has_cycle"):
            continue
        ph = phases_of(m, n)
        out.append(against(m["label"], *ph) if ph else f"| {m['label']} | " + " | ".join(["—"] * len(groups)) + " |")
    return out


def reference_markdown(c):
    """The axisymmetric reference of a case: its runs, its extrapolated figures with the
    convergence statement, and the 3D extrapolation against it."""
    ref = c["reference"]
    rng = ref.get("order_range")
    out = ["", "### Axisymmetric reference (the reference of this case's 1D verdicts and findings)", "",
           f"**{ref.get('statement', '')}** "
           f"(target ±{100 * ref.get('target_relative', 0.01):g} %; {ref.get('method', '')} method, "
           f"`{ref.get('grid_key', '')}` = {json.dumps(ref.get('grids'))}"
           + (f", observed orders accepted in [{rng[0]:g}, {rng[1]:g}]" if rng else "") + ").", "",
           "| grid | h | status | displacement / cycle | cycle time | mean velocity / cycle | max displacement | steps | wall time |",
           "|---|---|---|---|---|---|---|---|---|"]
    for r in ref.get("runs", []):
        out.append(f"| {json.dumps(r.get('grid_value'))} | {si(r['cell_size_m'], 'm')} | {r['status'][:60]} | "
                   f"{si(r.get('displacement_per_cycle_m'), 'm')} | {si(r.get('cycle_time_s'), 's')} | "
                   f"{si(r.get('mean_velocity_per_cycle_m_per_s'), 'm/s')} | {si(r.get('max_displacement_m'), 'm')} | "
                   f"{r.get('steps', '')} | {si(r.get('wall_time_s'), 's')}{' (cached)' if r.get('cached') else ''} |")
    tc = ref.get("time_check")
    wc = ref.get("wall_check")
    for chk, what in ((tc, "axi.tolerance × {:g} (time check)"), (wc, "axi.spacing_factor × {:g} (wall check)")):
        if chk and chk.get("run"):
            r = chk["run"]
            out.append(f"| {json.dumps(r.get('grid_value'))}, {what.format(chk.get('factor', 0))} | "
                       f"{si(r['cell_size_m'], 'm')} | {r['status'][:60]} | "
                       f"{si(r.get('displacement_per_cycle_m'), 'm')} | {si(r.get('cycle_time_s'), 's')} | "
                       f"{si(r.get('mean_velocity_per_cycle_m_per_s'), 'm/s')} | {si(r.get('max_displacement_m'), 'm')} | "
                       f"{r.get('steps', '')} | {si(r.get('wall_time_s'), 's')}{' (cached)' if r.get('cached') else ''} |")
    out.append("")
    if tc:
        out.append(f"- time integration's error, inside each error bar below: {tc.get('note', '')}")
    if wc:
        out.append(f"- the wall's resolution error, inside each error bar below: {wc.get('note', '')}")
    for key, words, unit in FIGURE_WORDS:
        e = ref.get(key)
        if not e:
            continue
        rel = e.get("relative_error")
        te = e.get("time_error")
        we = e.get("wall_error")
        wall_text = "" if we is None else ", the wall's resolution ± " + si(we, unit)
        out.append(f"- {words}: {si(e['value'], unit)} ± {si(e['error'], unit)}"
                   f"{'' if rel is None else f' (± {100 * rel:.2g} %)'}"
                   f"{'' if te is None else f', of which the time integration ± {si(te, unit)}'}"
                   f"{wall_text}; {order_text(e)}; "
                   f"{'converged' if e.get('converged') else 'not converged'}; {e.get('note', '')}")
        for q in e.get("phases", []):
            out.append(f"  - {q['phase']}: {si(q['value'], unit)} ± {si(q['error'], unit)}; {order_text(q)}")
        for alt, words_alt in (("whole_cycle", "the whole cycle's series"), ("direct", "extrapolated directly")):
            w = e.get(alt)
            if w:
                out.append(f"  - {words_alt}: {si(w['value'], unit)} ± {si(w['error'], unit)}; {order_text(w)}")
    cmp = c.get("comparison_3d_vs_reference") or {}
    if cmp:
        out += ["", "3D extrapolation against the axisymmetric reference (disagree when |Δ| > e_3d + e_ref; otherwise "
                "agree, or inconclusive when e_3d + e_ref exceeds a quarter of the reference):", "",
                "| figure | 3D (h → 0) | 3D order | axisymmetric reference | Δ = 3D − ref | e_3d + e_ref | verdict | finest 3D grid vs ref |",
                "|---|---|---|---|---|---|---|---|"]
        for key, words, unit in FIGURE_WORDS:
            e = cmp.get(key)
            if not e:
                continue
            obs = e.get("observed_order_3d")
            fr = e.get("finest_3d_relative_error")
            out.append(f"| {words} | {si(e['value_3d'], unit)} ± {si(e['error_3d'], unit)} | "
                       f"{'—' if obs is None else f'{obs:.2f}'}{'' if e.get('asymptotic_3d') else ' (not asymptotic)'}"
                       f"{'; fit f0 + a h + b h²' if e.get('method_3d') == 'expansion_fit' else ''}"
                       f"{'; fit T0 (1 − a h)⁻⁴' if e.get('method_3d') == 'lumen_fit' else ''} | "
                       f"{si(e['value_reference'], unit)} ± {si(e['error_reference'], unit)} | "
                       f"{si(e['difference'], unit)} | {si(e['combined_uncertainty'], unit)} | **{e['verdict']}** | "
                       f"{pct(fr)} (h = {si(e.get('finest_3d_cell_size_m'), 'm')}) |")
    u = c.get("velocity_3d_vs_reference")
    if u and u.get("phase_correlation") is not None:
        spread = u.get("phase_correlation_grid_spread")
        out += ["", f"U(t) of the finest 3D run (h = {si(u.get('cell_size_m'), 'm')}) against the finest axisymmetric "
                f"run (h = {si(u.get('reference_cell_size_m'), 'm')}), against the cycle phase: correlation "
                f"{u['phase_correlation']:.2f}" + ("" if spread is None else
                                                   f" ± {spread:.2f} (its spread over the three finest axisymmetric grids)")
                + f", relative L2 difference {u['phase_l2_relative']:.2f}; against time: correlation "
                f"{u['time_correlation']:.2f}, relative L2 difference {u['time_l2_relative']:.2f}."]
    return out


def to_html(md, d):
    """A small Markdown subset (headings, tables, lists, images, bold) to one self-contained page."""
    body, table = [], False
    for line in md.splitlines():
        if line.startswith("|"):
            # cells split on the unescaped pipes; an escaped one (\|) is text
            cells = [c.strip().replace("\\|", "|") for c in re.split(r"(?<!\\)\|", line.strip()[1:-1])]
            if all(set(c) <= set("-") for c in cells):
                continue
            if not table:
                body.append("<table>")
                table = True
                body.append("<tr>" + "".join(f"<th>{html.escape(c)}</th>" for c in cells) + "</tr>")
                continue
            body.append("<tr>" + "".join(f"<td>{html.escape(c).replace('**', '')}</td>" for c in cells) + "</tr>")
            continue
        if table:
            body.append("</table>")
            table = False
        if line.startswith("!["):
            f = line[line.index("(") + 1:-1]
            with open(os.path.join(d, f), "rb") as fh:
                b = base64.b64encode(fh.read()).decode()
            body.append(f'<p><img alt="{html.escape(f)}" src="data:image/png;base64,{b}" style="max-width:100%"></p>')
        elif line.startswith("### "):
            body.append(f"<h3>{html.escape(line[4:])}</h3>")
        elif line.startswith("## "):
            body.append(f"<h2>{html.escape(line[3:])}</h2>")
        elif line.startswith("# "):
            body.append(f"<h1>{html.escape(line[2:])}</h1>")
        elif line.startswith("- "):
            body.append(f"<li>{html.escape(line[2:])}</li>")
        elif line.strip():
            body.append(f"<p>{html.escape(line)}</p>")
    if table:
        body.append("</table>")
    style = ("body{font-family:sans-serif;max-width:1200px;margin:auto}table{border-collapse:collapse}"
             "td,th{border:1px solid #bbb;padding:3px 6px;font-size:90%}")
    return f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>Validation report</title><style>{style}</style>" \
           f"</head><body>{''.join(body)}</body></html>\n"


def main(d):
    with open(f"{d}/report.json") as f:
        report = json.load(f)
    figs = {}
    for c in report["cases"]:
        name = c["name"]
        lst = figs.setdefault(name, [])
        if any(r.get("has_cycle") for r in c["runs3d"]):
            velocity_figure(c, f"{d}/fig_velocity_{name}.png")
            lst.append(f"fig_velocity_{name}.png")
        if convergence_figure(c, f"{d}/fig_convergence_{name}.png"):
            lst.append(f"fig_convergence_{name}.png")
        if phases_figure(c, f"{d}/fig_phases_{name}.png"):
            lst.append(f"fig_phases_{name}.png")
        if membrane_figure(c, f"{d}/fig_membrane_{name}.png"):
            lst.append(f"fig_membrane_{name}.png")
        cal = c["calibration"].get("file")
        if cal and os.path.exists(cal):
            cd = os.path.dirname(cal)
            plot_calibration.main(cd)
            dst = f"fig_calibration_{name}.png"
            os.replace(f"{cd}/calibration.png", f"{d}/{dst}")
            lst.append(dst)
    glob = figs.setdefault("", [])
    if sweep_figure(report, "aspect", "swimmer length L [µm]", "displacement_per_cycle_m", "displacement per cycle [nm]",
                    1e9, f"{d}/fig_distance_vs_length.png", "Distance per cycle against swimmer length (Figure 12)"):
        glob.append("fig_distance_vs_length.png")
    if sweep_figure(report, "amplitude", "contracted radius R_f / R₀", "displacement_per_cycle_m",
                    "displacement per cycle [nm]", 1e9, f"{d}/fig_distance_vs_amplitude.png",
                    "Distance per cycle against contraction (Figure 12)"):
        glob.append("fig_distance_vs_amplitude.png")
    if sweep_figure(report, "aspect", "swimmer length L [µm]", "mean_velocity_per_cycle_m_per_s",
                    "mean velocity per cycle [nm/s]", 1e9, f"{d}/fig_velocity_vs_length.png",
                    "Mean velocity per cycle against swimmer length (Figure 13)"):
        glob.append("fig_velocity_vs_length.png")
    if sweep_figure(report, "amplitude", "contracted radius R_f / R₀", "mean_velocity_per_cycle_m_per_s",
                    "mean velocity per cycle [nm/s]", 1e9, f"{d}/fig_velocity_vs_amplitude.png",
                    "Mean velocity per cycle against contraction (Figure 13)"):
        glob.append("fig_velocity_vs_amplitude.png")
    if sweep_figure(report, "container", "container radius Rc / R₀", "displacement_per_cycle_m",
                    "displacement per cycle [nm]", 1e9, f"{d}/fig_distance_vs_container.png",
                    "Distance per cycle against the container radius, L = 0.2 µm", logx=True):
        glob.append("fig_distance_vs_container.png")
    if multicycle_figure(report, f"{d}/fig_multicycle.png"):
        glob.append("fig_multicycle.png")
    if pareto_figure(report, f"{d}/fig_pareto.png"):
        glob.append("fig_pareto.png")
    md = markdown(report, figs)
    with open(f"{d}/report.md", "w") as f:
        f.write(md)
    with open(f"{d}/report.html", "w") as f:
        f.write(to_html(md, d))


if __name__ == "__main__":
    main(sys.argv[1])
