#!/usr/bin/env python3
"""Fit the 1D tier's end junction (reduced1d/outer_flow.hpp kCalibratedJunction,
docs/outer-flow-1d.md §2c) to the steady flows of the axisymmetric tier.

The data are what swim_junction_kernels writes (data/calibration/junction_kernels.txt): for each
tube shape, the towed tube's drag and lumen flux and the swimming velocity that the radial
velocity of each wall ring alone gives. The model is the 1D tier's confined lubrication system
(ConfinedSystem::kinematic, restated here in numpy) with, at each end, the dissipation
D = x^T M x / 2 in x = (lumen flux, annulus flux, tube velocity), M = mu S B B^T S,
S = diag(R^-3/2, R^-3/2, R^1/2), B lower triangular with entries linear in ln(Rc/R - 1), and the
rim's thrust rim mu R <dR/dt>. Fitted by least squares (scipy) to, for every shape, the velocity
of narrow wall bands (0.5 R0 wide, every 0.25 R0 along the tube, each relative to the largest of
that shape) and the towed drag and lumen flux (relative, weight 3). Needs python3-scipy.

    tools/fit_end_junction.py [--no-fit] [--rim-bands] [--rim-weight W] [--rim-length L]
                              [--min-length L/R0] [--expansion FILE] [--expansion-radii R/R0,...]
                              [--start c0,...,c13] [KERNEL_FILE ...]

The shipped coefficients come from

    tools/fit_end_junction.py --rim-bands --min-length 3.2 --expansion-radii 0.55,0.82,1 \
        --expansion data/calibration/junction_expansion.txt data/calibration/junction_kernels.txt \
        data/calibration/junction_kernels_short.txt data/calibration/junction_kernels_protocol.txt

(--min-length 3.2 leaves out the L/R0 = 1.6 shapes and expansions: a short tube's two ends
interact, which a junction at each end cannot hold; docs/outer-flow-1d.md §6c).

With --expansion, the residuals also hold, for each uniform tube there (swim_junction_kernels
--expansion), the relative error of the wall's resistance to a uniform expansion: the lumen's and
annulus's lubrication dissipation plus both ends' x^T M x, x = pi R w L (1, -1, 0), against the
axisymmetric tier's (weight 3, as the towed drag).

Prints each shape's residuals with the plain junction, with the shipped coefficients
(reduced1d/outer_flow.hpp) and after the fit, and the C++ initializer.
"""
import argparse
import os
import re
import sys

import numpy as np
from scipy.optimize import least_squares

R0 = 0.125e-6
RIM_LENGTH = 0.15  # the rim weight's decay length / R (not fitted)


def annulus(Ro, Rc, mu):
    lam = np.log(Rc / Ro)
    D2 = Rc**2 - Ro**2
    G = np.pi / (8 * mu) * (Rc**4 - Ro**4 - D2**2 / lam)
    S = 0.5 * np.pi * D2 / lam
    rho = 1 / G
    return rho, (np.pi * Rc**2 - S) * rho, S, 2 * np.pi * mu / lam


class Tube:
    """The confined lubrication system on N cells (as ConfinedSystem, a_in = a_out = 0)."""

    def __init__(self, L, Rc, P, shape, mu, N=200):
        self.L, self.Rc, self.mu, self.h = L, Rc, mu, L / N
        zp = np.concatenate([[0], (np.arange(N) + 0.5) * self.h, [L]])
        self.zc = zp[1:-1]
        d = np.diff(zp)
        R = shape(zp)
        self.R = R
        rho, kap, S, e = annulus(R, Rc, mu)
        a, b = R[:-1], R[1:]
        self.rl = (8 * mu / np.pi) * d / 3 * (a * a + a * b + b * b) / (a**3 * b**3)
        self.ra = 0.5 * d * (rho[:-1] + rho[1:])
        self.c = 0.5 * d * (kap[:-1] + kap[1:])
        self.S = 0.5 * (S[:-1] + S[1:])
        self.e = 0.5 * d * (e[:-1] + e[1:])
        self.rfree = (P - L) * 8 * mu / (np.pi * Rc**4)
        self.Ac = np.pi * Rc**2
        self.M = [np.zeros((3, 3)), np.zeros((3, 3))]
        self.rim = [0.0, 0.0]

    def solve(self, Rdot, F_ext=0.0):
        s = np.concatenate([[0], np.cumsum(self.h * 2 * np.pi * self.R[1:-1] * Rdot)])
        RL, RLs = self.rl.sum(), (self.rl * s).sum()
        RA, RAs, C = self.ra.sum(), (self.ra * s).sum(), self.c.sum()
        SRA, SRAs = (self.S * self.ra).sum(), (self.S * self.ra * s).sum()
        SC, E = (self.S * self.c).sum(), self.e.sum()
        A = np.array([[RL, 0, 0, 1], [-RA, RA, C, 1], [0, -self.rfree, -self.rfree * self.Ac, 1], [SRA, -SRA, E - SC, 0]])
        b = np.array([RLs, -RAs, 0, F_ext + SRAs])
        T = np.array([[1, 0, 0], [-1, 1, 0], [0, 0, 1.0]])
        rows = [0, 1, 3]
        for k, t in ((0, np.zeros(3)), (1, np.array([-s[-1], s[-1], 0]))):
            A[np.ix_(rows, [0, 1, 2])] += self.M[k] @ T
            b[rows] -= self.M[k] @ t
            Re = self.R[0] if k == 0 else self.R[-1]
            dist = self.zc if k == 0 else self.L - self.zc
            w = np.exp(-dist / (RIM_LENGTH * Re)) / (RIM_LENGTH * Re) * self.h
            b[3] += (1 if k == 0 else -1) * self.rim[k] * self.mu * Re * (w * Rdot).sum()
        return np.linalg.solve(A, b)  # lumen flux at the rear, total flux, U, pressure rise

    def tow(self):
        x = self.solve(np.zeros_like(self.zc), 1.0)
        return 1 / x[2], x[0] / x[2]


def junction(p, R, Rc, mu):
    xg = np.log(Rc / R - 1)
    v = [p[2 * i] + p[2 * i + 1] * xg for i in range(6)]
    B = np.array([[v[0], 0, 0], [v[1], v[2], 0], [v[3], v[4], v[5]]])
    S = np.array([R**-1.5, R**-1.5, R**0.5])
    return mu * (S[:, None] * (B @ B.T) * S[None, :]), p[12] + p[13] * xg


def load(fn):
    cases, cur, tq = [], None, None
    for line in open(fn):
        if line.startswith("# towed"):
            tq = float(line.split()[6])
        elif line.startswith("# L/R0"):
            t = line.split()
            cur = dict(L=float(t[2]) * R0, Rc=float(t[4]) * R0, rt=float(t[6]), cells=int(t[8]), drag=float(t[12]), mu=float(t[14]), zf=float(t[16]),
                       rf=float(t[18]), tq=tq, rings=[])
            cases.append(cur)
        elif cur is not None and line.strip() and not line.startswith("#"):
            cur["rings"].append([float(x) for x in line.split()[:4]])
    return cases


def shape_of(c):
    L, zf, rf, rt = c["L"], c["zf"], c["rf"], c["rt"]
    if zf < 0:
        return lambda z: rt * R0 + 0 * z
    w = L / 8

    def f(z):
        x = (z - zf * L) / w
        return np.where(x <= -0.5, rf * R0,
                        np.where(x >= 0.5, rt * R0, rf * R0 + (rt - rf) * R0 * 0.5 * (1 + np.sin(np.pi * x))))
    return f


def load_expansion(fn):
    """swim_junction_kernels --expansion lines: (L, Rc, R, mu, Z)"""
    out = []
    for line in open(fn):
        t = line.split()
        if line.startswith("# expansion"):
            out.append((float(t[3]) * R0, float(t[5]) * R0, float(t[7]) * R0, float(t[11]), float(t[13])))
    return out


def expansion_z(p, L, Rc, R, mu):
    """The 1D tier's resistance to a uniform expansion: lubrication lumen and annulus, both ends' junction"""
    d = Rc * Rc - R * R
    G = Rc**4 - R**4 - d * d / np.log(Rc / R)
    z = (8 * np.pi / 3) * mu * R * R * L**3 * (1 / R**4 + 1 / G)
    M, _ = junction(p, R, Rc, mu)
    x = np.array([np.pi * R * L, -np.pi * R * L, 0.0])
    return z + 2 * x @ M @ x


def shipped():
    """kCalibratedJunction's 14 coefficients as reduced1d/outer_flow.hpp holds them"""
    src = open(os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "reduced1d", "outer_flow.hpp")).read()
    body = src[src.index("kCalibratedJunction{"):]
    return np.array([float(v) for v in re.findall(r"-?\d+\.\d+(?:e-?\d+)?", body)[:14]])


def main():
    global RIM_LENGTH
    ap = argparse.ArgumentParser()
    ap.add_argument("kernels", nargs="*", default=["data/calibration/junction_kernels.txt"])
    ap.add_argument("--expansion", default=None)
    ap.add_argument("--no-fit", action="store_true", help="only the plain and the shipped junction's residuals")
    ap.add_argument("--rim-bands", action="store_true",
                    help="two more bands per shape, centred on the rims (the half of a band inside the tube)")
    ap.add_argument("--rim-weight", type=float, default=1.0, help="weight of the rim bands' residuals (default 1)")
    ap.add_argument("--rim-length", type=float, default=RIM_LENGTH, help="the rim weight's decay length / R (default 0.15)")
    ap.add_argument("--min-length", type=float, default=0.0,
                    help="leave out the shapes and expansions of tubes shorter than this L/R0 (their ends interact)")
    ap.add_argument("--expansion-radii", default=None,
                    help="comma-separated R/R0 of the expansions to use (default all)")
    ap.add_argument("--start", default=None, help="start the fit from these 14 comma-separated coefficients")
    a = ap.parse_args()
    RIM_LENGTH = a.rim_length
    data = []
    expansions = load_expansion(a.expansion) if a.expansion else []
    expansions = [e for e in expansions if e[0] / R0 >= a.min_length - 1e-9]
    if a.expansion_radii:
        radii = [float(v) for v in a.expansion_radii.split(",")]
        expansions = [e for e in expansions if min(abs(e[2] / R0 - r) for r in radii) < 1e-6]
    for c in [c for fn in a.kernels for c in load(fn) if c["L"] / R0 >= a.min_length - 1e-9]:
        h = c["Rc"] / c["cells"]
        P = round(5 * c["L"] / h) * h
        r = np.array(c["rings"])
        z, U_ring = r[:, 1] * R0, r[:, 3] / 1e-6
        tube = Tube(c["L"], c["Rc"], P, shape_of(c), c["mu"])
        bands, weights = [], []
        centres = np.arange(0.25 * R0, c["L"] - 0.25 * R0 + 1e-12, 0.25 * R0)
        if a.rim_bands:
            centres = np.concatenate([[0.0], centres, [c["L"]]])
        for zc in centres:
            def band(zz, zc=zc):
                x = (zz - zc) / (0.5 * R0)
                return np.where(abs(x) < 0.5, np.cos(np.pi * x) ** 2, 0.0)
            bands.append(band(tube.zc))
            weights.append(a.rim_weight if a.rim_bands and zc in (centres[0], centres[-1]) else 1.0)
            c.setdefault("U", []).append(np.sum(U_ring * band(z)))
        c["U"] = np.array(c["U"])
        c["w"] = np.array(weights)
        data.append((c, tube, bands))

    def residuals(p, report=False):
        out = []
        for c, tube, bands in data:
            for k in (0, 1):
                tube.M[k], tube.rim[k] = junction(p, tube.R[0] if k == 0 else tube.R[-1], c["Rc"], c["mu"])
            U = np.array([tube.solve(b)[2] for b in bands])
            scale = np.abs(c["U"]).max()
            out.extend(c["w"] * (U - c["U"]) / scale)
            drag, flux = tube.tow()
            out += [3 * (drag / c["drag"] - 1), 3 * (flux / c["tq"] - 1)]
            if report:
                e = (U - c["U"]) / scale
                print(f"  L/R0 {c['L'] / R0:5.2f} Rc/R0 {c['Rc'] / R0:4.2f} zf {c['zf']:5.2f} rf {c['rf']:.2f} rt {c['rt']:.2f}: bands rms "
                      f"{np.sqrt(np.mean(e**2)):.3f} max {np.abs(e).max():.3f}; drag {drag / c['drag'] - 1:+.3f}, "
                      f"lumen flux {flux / c['tq'] - 1:+.3f}")
        for L, Rc, R, mu, Z in expansions:
            r = expansion_z(p, L, Rc, R, mu) / Z - 1
            out.append(3 * r)
            if report:
                print(f"  uniform expansion L/R0 {L / R0:5.2f} Rc/R0 {Rc / R0:4.2f} R/R0 {R / R0:.2f}: resistance {r:+.3f}")
        return np.array(out)

    print("plain junction:")
    residuals(np.zeros(14), True)
    print("shipped junction:")
    r = residuals(shipped(), True)
    print(f"  cost {0.5 * np.sum(r**2):.4f}")
    if a.no_fit:
        return
    start = np.array([1, 0, 0.1, 0, 0.1, 0, 0.5, 0, -0.3, 0, 0.5, 0, 0, 0.0])
    if a.start:
        start = np.array([float(v) for v in a.start.split(",")])
    fit = least_squares(residuals, start)
    print(f"fitted ({len(fit.fun)} residuals, cost {fit.cost:.4f}):")
    residuals(fit.x, True)
    p = fit.x
    xg = [np.log(c["Rc"] / r - 1) for c, tube, _ in data for r in (tube.R[0], tube.R[-1])]
    entries = ",\n    ".join(f"{{{p[2 * i]:.7f}, {p[2 * i + 1]:.7f}}}" for i in range(6))
    print("\ninline constexpr EndJunction kCalibratedJunction{{" + entries + "},\n    " +
          f"{{{p[12]:.7f}, {p[13]:.7f}}}, {RIM_LENGTH}, {min(xg):.7f}, {max(xg):.7f}}};")

if __name__ == "__main__":
    main()
