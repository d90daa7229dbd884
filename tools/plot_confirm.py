"""Plot a confirmation: the metric of each confirmed design in 1D against the confirming tier
(3D, or the axisymmetric tier with confirm.tier = "axi": the report's "tier"), with the
diagonal, and the designs' ranks in both tiers.

usage: plot_confirm.py CONFIRM_JSON OUT_PNG TITLE_NAME
Axes carry SI-prefixed units; each point is labelled with its design number, with its error
bar when the run estimated its own error (confirm.error_estimate). Designs whose confirming run
failed are left out (confirm.md lists them).
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
    tier = rep.get("tier", "3d")
    t = "_" + tier                                   # the keys of the confirming tier
    tl = "Axisymmetric" if tier == "axi" else "3D"   # its name in titles
    ts = "axi" if tier == "axi" else "3D"            # its short name on axes
    pts = [(d["design"], d["figures_1d"][metric], d["figures" + t][metric], d.get("error_bar" + t) or 0.0,
            d.get("rank_1d"), d.get("rank" + t), d["selected_as"])
           for d in rep["designs"] if d["status" + t] == "ok" and d["figures" + t].get(metric) is not None]
    if not pts:
        fig, ax = plt.subplots(figsize=(7, 3))
        ax.axis("off")
        ax.text(0.5, 0.5, f"{tl} confirmation of {name}: no {tl.lower() if tier == 'axi' else tl} run finished\n(see confirm.md for each run's status)",
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
                    if tau is not None else f"undefined (every pair tied within the {ts} error bars)")
        sub = (f"\nKendall \u03c4 = {tau_text}, "
               f"Spearman \u03c1 = {agreement['spearman_rho']:.2f} "
               f"[{agreement['spearman_rho_ci_95'][0]:.2f}, {agreement['spearman_rho_ci_95'][1]:.2f}] (95 %)")
    fig.suptitle(f"{tl} confirmation of {name}: {len(pts)} design(s), {LABELS.get(metric, (metric,))[0]}{sub}")
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
    ax.plot([lo - pad, hi + pad], [lo - pad, hi + pad], "k--", lw=1, label=f"1D = {ts}")
    ax.set(xlabel="1D: " + label(metric, ulab), ylabel=f"{ts}: " + label(metric, ulab), title=f"metric, 1D against {ts}")
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
        ax.set(xlim=(n + 0.5, 0.5), ylim=(n + 0.5, 0.5), xlabel="rank in 1D (1 = best)", ylabel=f"rank in {ts} (1 = best)",
               title="ranks among the confirmed designs")
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(png, dpi=110)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], sys.argv[3])
