"""Plot a design search: the objective of every evaluation (feasible and not) with the best so
far, and each parameter's path across its bounds.

usage: plot_optimize.py TRAJECTORY_CSV OUT_PNG OBJECTIVE SPEC_NAME LO:HI [LO:HI ...]
The LO:HI pairs are the parameters' bounds in SI, in the order of the CSV's parameter columns.
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # plot_screen beside it
from plot_screen import LABELS, label, si_scale  # noqa: E402


def main(path, png, objective, name, bounds):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    params = [c for c in rows[0] if "_si" in c]
    fig, axes = plt.subplots(1, 2, figsize=(11.6, 4.8))
    fig.suptitle(f"Design search {name}: {len(rows)} evaluations (NLopt COBYLA)")
    unit = LABELS.get(objective, (objective, ""))[1]
    vals = [float(r[objective]) for r in rows if r[objective]]
    fac, ulab = si_scale(vals, unit)
    ax = axes[0]
    for feas, style, lab in (("1", "o", "feasible"), ("0", "x", "infeasible")):
        sel = [r for r in rows if r["feasible"] == feas and r[objective]]
        if sel:
            ax.plot([int(r["evaluation"]) for r in sel], [float(r[objective]) * fac for r in sel], style, label=lab)
    best = [(int(r["evaluation"]), float(r["best_so_far_" + objective]) * fac) for r in rows if r["best_so_far_" + objective]]
    if best:
        ax.step([b[0] for b in best], [b[1] for b in best], where="post", color="k", lw=1, label="best so far")
    ax.set(xlabel="evaluation", ylabel=label(objective, ulab), title="objective")
    ax.legend(fontsize=8)
    ax = axes[1]
    for c, b in zip(params, bounds):
        xs = [float(r[c]) for r in rows]
        lo, hi = (float(v) for v in b.split(":"))
        key = c.split("_si")[0]
        f, u = si_scale(xs, c.split("[")[1][:-1] if "[" in c else "")
        ax.plot([int(r["evaluation"]) for r in rows], [(x - lo) / (hi - lo) if hi > lo else 0.5 for x in xs], ".-",
                label=f"{LABELS.get(key, (key,))[0]}: {lo * f:.3g} to {hi * f:.3g} {u}".rstrip())
    ax.set(xlabel="evaluation", ylabel="position within its bounds (0 = min, 1 = max)", title="parameters",
           ylim=(-0.05, 1.05))
    for a in axes:
        a.xaxis.get_major_locator().set_params(integer=True)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(png, dpi=110)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4], sys.argv[5:])
