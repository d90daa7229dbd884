"""Figure 10 done with pressures: uniform inward pressure against the radial displacement
of the middle ring, with the C1 fit through the origin, the secant stiffness against the load,
and the ring's stiffness against its modes cos(n phi) (ring buckling where it turns negative).
A load at which the wall found no static state (the series stops there) is marked on all
three panels, and its reason is printed under them. A failed measurement (status
"failed: ...", e.g. the hydraulic radii) turns the title red and prints the reason.

Scales: pressure and displacement on log axes (the loads span decades); the ring-mode
stiffness on a symmetric-log axis when it spans both signs and more than a decade; the
+-1 % band of the secant stiffness as two dashed lines (the axis follows the data);
legends below the axes.

With a tube law (swim calibrate --tube-law) also DIR/tube_law.png: both branches of the static
law, the loads against the middle radius with the monotone Steffen interpolant through them,
and the law's slope against the radius.

With the axial stiffness (every swim calibrate) also DIR/axial_stiffness.png: C(k) / C1 against
the wavelength with the shell law C1 + D K^4, and the rigidity each wavelength gives.

usage: plot_calibration.py DIR   (reads DIR/calibration.json, writes DIR/calibration.png)
`figure(DIR)` returns (matplotlib figure, choices dict) for tests.
"""
import json
import math
import sys
import textwrap

import matplotlib
import matplotlib.ticker

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def spans_signs_and_decades(values):
    """True when values have both signs and their magnitudes span more than a decade."""
    nz = [abs(v) for v in values if v != 0]
    return any(v > 0 for v in values) and any(v < 0 for v in values) and bool(nz) and max(nz) > 10 * min(nz)


def figure(d):
    with open(f"{d}/calibration.json") as f:
        c = json.load(f)
    pts = c["load_points"]
    x = [p["displacement_m"] * 1e9 for p in pts]
    y = [p["pressure_Pa"] * 1e3 for p in pts]
    fitted = [p["in_linear_range"] and p["stable_to_ring_buckling"] for p in pts]
    unstable = [not p["stable_to_ring_buckling"] for p in pts]
    nonlin = [not f and not u for f, u in zip(fitted, unstable)]
    fig, ax = plt.subplots(1, 3, figsize=(15, 5.6))
    name = c["scene"].get("name", d)
    status = str(c.get("status", "ok"))
    failed = status.startswith("failed")
    title = f"Wall stiffness from uniform loads: {name} ({c['grid']['membrane_nodes']} membrane nodes)"
    if failed:
        title += "\nC1 measured; " + status.split(":", 2)[1].strip() + " FAILED (no offsets written)" \
            if status.count(":") >= 2 else "\nFAILED"
    fig.suptitle(title, color="tab:red" if failed else "black")
    notes = []
    if failed:
        notes.append(("tab:red", status))

    def sel(v, m):
        return [a for a, b in zip(v, m) if b]

    positive = all(v > 0 for v in x + y)
    ax[0].plot(sel(x, fitted), sel(y, fitted), "o", label="fitted (linear, stable)")
    if any(nonlin):
        ax[0].plot(sel(x, nonlin), sel(y, nonlin), "s", mfc="none", label="beyond 1 % of linear")
    if any(unstable):
        ax[0].plot(sel(x, unstable), sel(y, unstable), "x", ms=8, label="unstable to ring buckling")
    xs = [min(x) if positive else 0, max(x)]
    ax[0].plot(xs, [c["C1_Pa_per_m"] * v * 1e-9 * 1e3 for v in xs], "k-", lw=1,
               label=f"C1 = {c['C1_Pa_per_m'] / 1e6:.4g} MPa/m (fit)")
    ax[0].plot(xs, [c["C1_spring_network_Pa_per_m"] * v * 1e-9 * 1e3 for v in xs], "k:", lw=1,
               label=f"2 k\u209b / (\u221a3 R\u2080\u00b2) = {c['C1_spring_network_Pa_per_m'] / 1e6:.4g} MPa/m")
    if positive:
        ax[0].set_xscale("log")
        ax[0].set_yscale("log")
    lost = c.get("loads_without_static_state")
    if lost:
        p_lost = lost["from_Pa"] * 1e3
        ax[0].axhline(p_lost, color="tab:red", ls="--", lw=1, label=f"no static state at {p_lost:.3g} mPa")
        for a in ax[1:]:
            a.axvline(p_lost, color="tab:red", ls="--", lw=1, label=f"no static state at {p_lost:.3g} mPa")
        notes.append(("tab:red", f"No static state from {p_lost:.3g} mPa: {lost['reason']}"))
    log = " (log scale)" if positive else ""
    ax[0].set(xlabel=f"radial displacement R\u2080 \u2212 R_mid [nm]{log}", ylabel=f"pressure [mPa]{log}",
              title="pressure against displacement")

    P = [p["pressure_Pa"] * 1e3 for p in pts]
    sec = [p["secant_C1_Pa_per_m"] / 1e6 for p in pts]
    spring = c["C1_spring_network_Pa_per_m"] / 1e6
    ax[1].semilogx(P, sec, "o-", label="secant P / (R\u2080 \u2212 R_mid)")
    ax[1].axhline(spring, color="k", ls=":", lw=1, label="spring-network value")
    shown = sec + [spring]
    pad = 0.15 * (max(shown) - min(shown)) or 0.01 * abs(sec[0])
    ylim = (min(shown) - pad, max(shown) + pad)
    band = (sec[0] * 0.99, sec[0] * 1.01)
    for i, b in enumerate(band):
        ax[1].axhline(b, color="0.5", ls="--", lw=0.8, label="\u00b11 % of the smallest load's" if i == 0 else None)
    ax[1].set_ylim(*ylim)
    if not (ylim[0] <= band[0] and band[1] <= ylim[1]):  # say where the band lies when off the axis
        off = [f"{b:.4g}" for b in band if not ylim[0] <= b <= ylim[1]]
        ax[1].text(0.02, 0.02, f"\u00b11 % lines off the axis at {', '.join(off)} MPa/m", transform=ax[1].transAxes,
                   fontsize="x-small", color="0.35")
    ax[1].set(xlabel="pressure [mPa] (log scale)", ylabel="secant C1 [MPa/m]", title="stiffness against load")

    k = {n: [p["ring_mode_stiffness_N_per_m"][n - 2] * 1e12 for p in pts] for n in (2, 3)}
    soft = [p["softest_ring_mode_stiffness_N_per_m"] * 1e12 for p in pts]
    for n in (2, 3):
        ax[2].plot(P, k[n], "o-", label=f"mode n = {n}")
    ax[2].plot(P, soft, "ks--", label="softest mode (n labelled)")
    ax[2].set_xscale("log")
    everything = k[2] + k[3] + soft
    symlog = spans_signs_and_decades(everything)
    if symlog:
        # the linear range one decade wide, ending on a power of ten (ticks at 0 and +-linthresh apart)
        lin = 10.0 ** math.floor(math.log10(min(abs(v) for v in everything if v != 0)))
        ax[2].set_yscale("symlog", linthresh=lin)
    prev = None
    for i, p in enumerate(pts):  # the softest mode's n, where it changes, away from the curves
        if p["softest_ring_mode"] != prev:
            above = soft[i] >= 0
            ax[2].annotate(f"n={p['softest_ring_mode']}", (P[i], soft[i]), fontsize=7,
                           xytext=(0, 9 if above else -11), textcoords="offset points", ha="center",
                           va="bottom" if above else "top")
        prev = p["softest_ring_mode"]
    ax[2].axhline(0, color="k", lw=1)
    ax[2].margins(y=0.14)  # room for the n labels inside the axes, clear of the title and ticks
    ax[2].set(xlabel="pressure [mPa] (log scale)",
              ylabel="ring-mode stiffness [pN/m]" + (" (symlog)" if symlog else ""),
              title="ring buckling: unstable below zero")
    legends = [a.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), fontsize="small", frameon=False, ncol=2)
               for a in ax]
    text = "\n".join(line for _, n in notes for line in textwrap.wrap(n, 190))
    if text:
        fig.text(0.01, 0.01, text, fontsize=8, color="tab:red", va="bottom")
    bottom = 0.03 + 0.02 * text.count("\n") if text else 0
    fig.tight_layout(rect=(0, bottom, 1, 0.95 if failed else 1))
    return fig, {"failed": failed, "title": title, "symlog": symlog, "secant_ylim": ylim, "band": band,
                 "loglog": positive, "legends": legends, "axes": ax}


def main(d):
    fig, _ = figure(d)
    fig.savefig(f"{d}/calibration.png", dpi=110)
    plt.close(fig)  # plot_validation draws one per case in one process
    with open(f"{d}/calibration.json") as f:
        c = json.load(f)
    if "tube_law" in c:
        plot_tube_law(d, c)
    if "C_Pa_per_m" in c.get("axial_stiffness", {}):  # (a failed measurement holds only its status)
        plot_axial_stiffness(d, c)


def steffen(xk, yk, x):
    """Steffen's monotone cubic (GSL gsl_interp_steffen) and its derivative; linear beyond the knots."""
    n = len(xk)
    h = [xk[i + 1] - xk[i] for i in range(n - 1)]
    s = [(yk[i + 1] - yk[i]) / h[i] for i in range(n - 1)]
    d = [0.0] * n
    for i in range(1, n - 1):
        p = (s[i - 1] * h[i] + s[i] * h[i - 1]) / (h[i - 1] + h[i])
        sg = (1 if s[i - 1] > 0 else -1 if s[i - 1] < 0 else 0) + (1 if s[i] > 0 else -1 if s[i] < 0 else 0)
        d[i] = sg * min(abs(s[i - 1]), abs(s[i]), 0.5 * abs(p))
    d[0], d[-1] = s[0], s[-1]  # GSL's end slopes: the end secants (Steffen's simplest choice)
    lo = d[0] if d[0] > 0 else s[0]
    hi = d[-1] if d[-1] > 0 else s[-1]
    y, dy = [], []
    for v in x:
        if v <= xk[0]:
            y.append(yk[0] + lo * (v - xk[0])), dy.append(lo)
            continue
        if v >= xk[-1]:
            y.append(yk[-1] + hi * (v - xk[-1])), dy.append(hi)
            continue
        i = max(k for k in range(n - 1) if xk[k] <= v)
        t = v - xk[i]
        a = (d[i] + d[i + 1] - 2 * s[i]) / h[i] ** 2
        b = (3 * s[i] - 2 * d[i] - d[i + 1]) / h[i]
        y.append(yk[i] + t * (d[i] + t * (b + t * a)))
        dy.append(d[i] + t * (2 * b + 3 * a * t))
    return y, dy


def plot_tube_law(d, c):
    t = c["tube_law"]
    R0 = t["round"]["knots_radius_m"][-1]
    name = c["scene"].get("name", d)
    fig, ax = plt.subplots(1, 2, figsize=(13, 4.8))
    fig.suptitle(f"Static tube law from uniform loads: {name} (R\u2080 = {R0 * 1e6:.4g} \u00b5m, "
                 f"{c['grid']['membrane_nodes']} membrane nodes)")
    lo = min(t["round"]["knots_radius_m"][0], t.get("buckled", t["round"])["knots_radius_m"][0])
    branches = [("round", "round (axisymmetric) wall", "tab:blue", "o")]
    if "buckled" in t:
        branches.append(("buckled", "paper's wall, free to buckle", "tab:red", "s"))
    for key, label, col, mk in branches:
        b = t[key]
        pts = b["load_points"]
        ax[0].plot([p["mid_radius_m"] * 1e6 for p in pts], [p["pressure_Pa"] for p in pts], mk, color=col,
                   mfc="none", label=f"{label}: loads")
        xk, yk = b["knots_radius_m"], b["knots_wall_pressure_Pa"]
        xs = [lo + (R0 - lo) * i / 400 for i in range(401)]
        y, dy = steffen(xk, yk, xs)
        ax[0].plot([v * 1e6 for v in xs], [-v for v in y], "-", color=col, lw=1, label=f"{label}: monotone law")
        ax[1].plot([v * 1e6 for v in xs], [v / 1e6 for v in dy], "-", color=col, lw=1, label=label)
    c1 = t["C1_small_load_fit_Pa_per_m"]
    ax[0].plot([lo * 1e6, R0 * 1e6], [c1 * (R0 - lo), 0], "k:", lw=1, label=f"linear law, C1 = {c1 / 1e6:.4g} MPa/m")
    if t.get("buckling_load_Pa"):
        ax[0].axhline(t["buckling_load_Pa"], color="0.5", ls="--", lw=1,
                      label=f"round branch's ring-mode buckling load {t['buckling_load_Pa'] * 1e3:.3g} mPa (n = {t['buckling_ring_mode']})")
    if t.get("collapse_load_Pa"):
        ax[0].axhline(t["collapse_load_Pa"], color="tab:red", ls=":", lw=1,
                      label=f"free wall collapses between {t['round_up_to_Pa'] * 1e3:.3g} and "
                            f"{t['collapse_load_Pa'] * 1e3:.3g} mPa")
    ax[0].set(xlabel="middle radius R_mid [\u00b5m]", ylabel="uniform inward load P [Pa]",
              title="load against radius (static equilibria)")
    ax[0].legend(fontsize="small", frameon=False)
    ax[1].axhline(c1 / 1e6, color="k", ls=":", lw=1, label="C1 (small-load fit)")
    ax[1].set(xlabel="middle radius R_mid [\u00b5m]", ylabel="law slope dP/dR [MPa/m]", yscale="log",
              title="stiffness of the law")
    ax[1].legend(fontsize="small", frameon=False)
    fig.tight_layout()
    fig.savefig(f"{d}/tube_law.png", dpi=110)
    plt.close(fig)


def plot_axial_stiffness(d, c):
    """DIR/axial_stiffness.png: the wall's stiffness along the axis, C(k) = C1 + D k^4, measured
    under loads p0 cos(kx) on a long tube (calibration.json "axial_stiffness"), against the shell
    law with the wall's D; and the rigidity each wavelength gives, (C - C1) / K^4."""
    a = c["axial_stiffness"]
    name = c["scene"].get("name", d)
    c1, dw, dx = a["C1_Pa_per_m"], a["bending_rigidity_wall_J"], a["ring_spacing_m"]
    lam = a["wavelengths_m"]
    fig, ax = plt.subplots(1, 2, figsize=(13, 4.8))
    fig.suptitle(f"Wall stiffness along the axis: {name} ({a['membrane_nodes']} membrane nodes, "
                 f"{a['tube_length_m'] * 1e6:.3g} \u00b5m tube, bending length {a['bending_length_m'] * 1e9:.3g} nm)")
    lo, hi = 0.8 * min(lam), 1.25 * max(lam)
    xs = [lo * (hi / lo) ** (i / 200) for i in range(201)]

    def lattice(l):
        k = 2 * math.pi / l
        return 2 / dx * math.sin(0.5 * k * dx)

    ax[0].loglog([v * 1e9 for v in lam], a["C_over_C1"], "o", label="measured C(k) / C1")
    ax[0].loglog([v * 1e9 for v in xs], [1 + dw * lattice(v) ** 4 / c1 for v in xs], "k-", lw=1,
                 label=f"1 + D K\u2074 / C1, wall's D = {dw:.4g} J")
    ax[0].loglog([v * 1e9 for v in xs], [1 + dw * (2 * math.pi / v) ** 4 / c1 for v in xs], "k:", lw=1,
                 label="1 + D k\u2074 / C1 (continuum k)")
    ax[0].set(xlabel="wavelength \u03bb [nm] (log scale)", ylabel="C / C1 [dimensionless] (log scale)",
              title=f"stiffness against wavelength (C1 = {c1 / 1e6:.5g} MPa/m)")
    ax[0].legend(fontsize="small", frameon=False)
    dk = [(cc - c1) / kk ** 4 / dw for cc, kk in zip(a["C_Pa_per_m"], a["lattice_wavenumbers_per_m"])]
    ax[1].semilogx([v * 1e9 for v in lam], dk, "o", label="(C \u2212 C1) / (D K\u2074) per wavelength")
    ax[1].axhline(1.0, color="k", lw=1, label=f"wall's D = {dw:.4g} J")
    ax[1].axhline(a["bending_rigidity_fit_J"] / dw, color="tab:blue", ls="--", lw=1,
                  label=f"fit C \u2212 C1 = D K\u2074: {a['bending_rigidity_fit_J']:.4g} J")
    f2 = a["fit_with_k2"]
    ax[1].semilogx([v * 1e9 for v in xs],
                   [(f2["k2_coefficient_N_per_m"] * (2 * math.pi / v) ** 2 + f2["bending_rigidity_J"] * lattice(v) ** 4)
                    / (lattice(v) ** 4 * dw) for v in xs], "-", color="tab:orange", lw=1,
                   label=f"fit A k\u00b2 + D K\u2074: D = {f2['bending_rigidity_J']:.4g} J, "
                         f"A = {f2['k2_coefficient_N_per_m']:.3g} N/m")
    ax[1].set(xlabel="wavelength \u03bb [nm] (log scale)", ylabel="rigidity / wall's D [dimensionless]",
              title="rigidity along the axis (K = (2/dx) sin(k dx/2))")
    ax[1].legend(fontsize="small", frameon=False)
    for a_ in ax:  # ticks at the measured wavelengths
        a_.set_xticks([v * 1e9 for v in lam])
        a_.set_xticklabels([f"{v * 1e9:.3g}" for v in lam])
        a_.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    fig.tight_layout()
    fig.savefig(f"{d}/axial_stiffness.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main(sys.argv[1])
