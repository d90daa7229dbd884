"""Plot a 3D confirmation: the metric of each confirmed design in 1D against 3D, with the
diagonal (1D = 3D), and the designs' ranks in both tiers.

usage: plot_confirm.py CONFIRM_JSON OUT_PNG TITLE_NAME
Axes carry SI-prefixed units; each point is labelled with its design number, with its 3D error
bar when the run estimated its own error (confirm.error_estimate). Designs whose 3D run failed
are left out (confirm.md lists them).
"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # plot_screen beside it
from plot_screen import LABELS, label, si_scale  # noqa: E402


def main(path, png, name):
    with open(path) as f:
        rep = json.load(f)
    metric = rep["metric"]
    unit = LABELS.get(metric, (metric, ""))[1]
    pts = [(d["design"], d["figures_1d"][metric], d["figures_3d"][metric], d.get("error_bar_3d") or 0.0,
            d.get("rank_1d"), d.get("rank_3d"), d["selected_as"])
           for d in rep["designs"] if d["status_3d"] == "ok" and d["figures_3d"].get(metric) is not None]
    if not pts:
        fig, ax = plt.subplots(figsize=(7, 3))
        ax.axis("off")
        ax.text(0.5, 0.5, f"3D confirmation of {name}: no 3D run finished\n(see confirm.md for each run's status)",
                ha="center", va="center")
        fig.savefig(png, dpi=110)
        return
    ranked = [p for p in pts if p[4] is not None]
    panels = 2 if len(ranked) >= 2 else 1
    fig, axes = plt.subplots(1, panels, figsize=(5.8 * panels, 5.0), squeeze=False)
    agreement = rep.get("agreement")
    sub = ""
    if agreement:
        tau = agreement.get("kendall_tau")
        tau_text = (f"{tau:.2f} [{agreement['kendall_tau_ci_95'][0]:.2f}, {agreement['kendall_tau_ci_95'][1]:.2f}]"
                    if tau is not None else "undefined (every pair tied within the 3D error bars)")
        sub = (f"\nKendall \u03c4 = {tau_text}, "
               f"Spearman \u03c1 = {agreement['spearman_rho']:.2f} "
               f"[{agreement['spearman_rho_ci_95'][0]:.2f}, {agreement['spearman_rho_ci_95'][1]:.2f}] (95 %)")
    fig.suptitle(f"3D confirmation of {name}: {len(pts)} design(s), {LABELS.get(metric, (metric,))[0]}{sub}")
    ax = axes[0][0]
    vals = [p[1] for p in pts] + [p[2] for p in pts]
    fac, ulab = si_scale(vals, unit)
    for sel, marker in (("best", "o"), ("spread", "s"), ("optimum", "*")):
        sp = [p for p in pts if p[6] == sel]
        if sp:
            ax.errorbar([p[1] * fac for p in sp], [p[2] * fac for p in sp], yerr=[p[3] * fac for p in sp],
                        fmt=marker, ms=8 if sel != "optimum" else 14, label=f"{sel} by 1D", capsize=3)
    for p in pts:
        ax.annotate(str(p[0]), (p[1] * fac, p[2] * fac), textcoords="offset points", xytext=(5, 4), fontsize=8)
    lo, hi = min(vals) * fac, max(vals) * fac
    pad = 0.08 * (hi - lo if hi > lo else abs(hi) or 1.0)
    ax.plot([lo - pad, hi + pad], [lo - pad, hi + pad], "k--", lw=1, label="1D = 3D")
    ax.set(xlabel="1D: " + label(metric, ulab), ylabel="3D: " + label(metric, ulab), title="metric, 1D against 3D")
    ax.legend(fontsize=8)
    if panels == 2:
        ax = axes[0][1]
        n = len(ranked)
        for sel, marker in (("best", "o"), ("spread", "s")):
            sp = [p for p in ranked if p[6] == sel]
            if sp:
                ax.plot([p[4] for p in sp], [p[5] for p in sp], marker, ms=8, label=f"{sel} by 1D")
        for p in ranked:
            ax.annotate(str(p[0]), (p[4], p[5]), textcoords="offset points", xytext=(5, 4), fontsize=8)
        ax.plot([0.5, n + 0.5], [0.5, n + 0.5], "k--", lw=1, label="same rank")
        ax.set(xlim=(n + 0.5, 0.5), ylim=(n + 0.5, 0.5), xlabel="rank in 1D (1 = best)", ylabel="rank in 3D (1 = best)",
               title="ranks among the confirmed designs")
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(png, dpi=110)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], sys.argv[3])
