#!/usr/bin/env python3
"""The force-driven round-wall cases replayed on the 1D tier (docs/outer-flow-1d.md §6b).

For each round-wall case of data/validation/converged.json (by default paper_aspect_L0.2 and L0.4
at 0.5 Pa, paper_amplitude_0.82; --cases L08 A035 the two whose front rim hooks, L = 0.8 um at
0.5 Pa and R_f = 0.35 R0 at 0.8 Pa, their references on triangles): the axisymmetric run (fitted method, --cells cells across, the case's and
its reference's `set` overrides), its first cycle's radius.csv replayed on the 1D tier
(wave.kind = "recorded") with the plain junction and the calibrated one, with and without the
calibrated hydraulic offsets, and the 1D force-driven runs (the suite's default model, calibrated
from docs/validation/converged/report.json, and the sharp wall). Prints the replay table, the
split of the default model's miss into the flow model's share and the wall's, and (--hybrids)
the replays of hybrid records: the axisymmetric R(z, t) with the rear or front fifth, or the
contraction or recovery phase, taken from the 1D force-driven run.

    tools/force_driven_replay.py [--swim build/bin/swim] [--work DIR] [--cells 16] [--hybrids] [--cases ...]

The axisymmetric runs are kept in --work and reused (about 3, 8 and 10 minutes on one core).
"""
import argparse
import json
import os
import subprocess
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
R0 = 0.125e-6
CASES = {  # label: (scene, suite case name, L [m], load override)
    "L02": ("paper_aspect_L0.2", "paper_aspect_L0.2_round_wall", 0.2e-6),
    "L04": ("paper_aspect_L0.4", "paper_aspect_L0.4_round_wall", 0.4e-6),
    "A082": ("paper_amplitude_0.82", "paper_amplitude_0.82_round_wall", 0.4e-6),
    # the two cases whose front rim hooks during the recovery (their references on triangles)
    "L08": ("paper_aspect_L0.8", "paper_aspect_L0.8_round_wall", 0.8e-6),
    "A035": ("paper_amplitude_0.35", "paper_amplitude_0.35_round_wall", 0.4e-6),
}
DEFAULT_CASES = ("L02", "L04", "A082")


def sets(d):
    out = []
    for k, v in d.items():
        if k == "description":
            continue
        out += ["--set", f"{k}={json.dumps(v)}"]
    return out


def run(swim, scene, tier, args, out, may_fail=False):
    """Runs (or reuses) a run folder; True when it completed. A failure ends the script unless
    may_fail (a 1D model that cannot run the case: its row says so)."""
    if os.path.exists(os.path.join(out, "summary.json")) and summary(out)["status"] == "ok":
        return True
    cmd = ["nice", "-n", "19", swim, "run", scene, "--tier", tier, *args, "--out", out, "--overwrite", "--quiet"]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode and not may_fail:
        sys.exit(f"{' '.join(cmd)}: exit {r.returncode}\n{r.stderr}")
    return r.returncode == 0


def summary(d):
    with open(os.path.join(d, "summary.json")) as f:
        return json.load(f)


def series(d):
    return np.genfromtxt(os.path.join(d, "series.csv"), delimiter=",", names=True)


def radius(path):
    a = np.loadtxt(path, delimiter=",", skiprows=1)
    t = np.unique(a[:, 0])
    nz = len(a) // len(t)
    return t, a[:nz, 1], a[:, 2].reshape(len(t), nz)


def first_cycle(d):
    """radius.csv -> radius.cycle.csv: the rows of the first completed cycle"""
    s = summary(d)
    ts, te = s["cycle_start_times_s"][0], s["cycle_end_times_s"][0]
    out = os.path.join(d, "radius.cycle.csv")
    with open(os.path.join(d, "radius.csv")) as f, open(out, "w") as o:
        o.write(f.readline())
        for line in f:
            t = float(line.split(",", 1)[0])
            if ts - 1e-9 * te <= t <= te * (1 + 1e-9):
                o.write(line)
    return out


def per_cycle(d):
    s = summary(d)
    return s["displacement_per_cycle_m"], s["cycle_time_s"]


def correlation(a_dir, b_dir, phase=False):
    """U(t) of two runs on one time base (phase: each over its own cycle, t/T)"""
    a, b = series(a_dir), series(b_dir)
    Ta, Tb = per_cycle(a_dir)[1], per_cycle(b_dir)[1]
    x = np.linspace(0, 1, 1000)
    ua = np.interp(x * Ta, a["t_s"], a["velocity_m_per_s"])
    ub = np.interp(x * (Tb if phase else Ta), b["t_s"], b["velocity_m_per_s"])
    rms = np.sqrt(np.mean((ua - ub) ** 2) / np.mean(ua ** 2))
    ua, ub = ua - ua.mean(), ub - ub.mean()
    return float(np.dot(ua, ub) / np.sqrt(np.dot(ua, ua) * np.dot(ub, ub))), float(rms)


def phase_grid(t, z, R, tc, T, s, zq):
    """R on phase-aligned time s (0..1 the contraction up to tc, 1..2 the recovery) and zq"""
    tt = np.where(s <= 1, s * tc, tc + (s - 1) * (T - tc))
    G = np.empty((len(s), len(zq)))
    for i, x in enumerate(tt):
        k = min(max(np.searchsorted(t, x, side="right") - 1, 0), len(t) - 2)
        th = (x - t[k]) / (t[k + 1] - t[k])
        row = (1 - th) * R[k] + th * R[k + 1]
        G[i] = np.interp(zq, z, row)
        for lo, j0, j1 in ((True, 0, 1), (False, -2, -1)):  # linear continuation past the end rings
            m = zq < z[0] if lo else zq > z[-1]
            if m.any():
                w = (zq[m] - z[j0]) / (z[j1] - z[j0])
                G[i, m] = (1 - w) * row[j0] + w * row[j1]
    return G


def write_record(path, s, zq, G, T):
    with open(path, "w") as o:
        o.write("t_s,z_m,radius_m\n")
        for i in range(len(s)):
            for j in range(len(zq)):
                o.write(f"{s[i] * T / 2:.10g},{zq[j]:.10g},{G[i, j]:.10g}\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--swim", default=os.path.join(ROOT, "build/bin/swim"))
    ap.add_argument("--work", default=os.path.join(ROOT, "out/force_driven_replay"))
    ap.add_argument("--cells", type=int, default=16)
    ap.add_argument("--hybrids", action="store_true")
    ap.add_argument("--cases", nargs="+", choices=sorted(CASES), default=list(DEFAULT_CASES),
                    help="which cases (default: the three whose rims do not hook)")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    with open(os.path.join(ROOT, "data/validation/converged.json")) as f:
        suite = {c["set"]["name"]: c for c in json.load(f)["cases"]}
    with open(os.path.join(ROOT, "docs/validation/converged/report.json")) as f:
        report = {c["name"]: c for c in json.load(f)["cases"]}
    rows, split = [], []
    for label in a.cases:
        scene_name, case, L = CASES[label]
        W = lambda k: os.path.join(a.work, f"{k}_{label}")
        scene = os.path.join(ROOT, "data/scenes", scene_name + ".json")
        c = suite[case]
        # the calibration of the suite's default 1D model, from the shipped report
        cal = {k: report[case]["calibration"][k] for k in
               ("C1_Pa_per_m", "hydraulic_offset_inner_m", "hydraulic_offset_outer_m", "axial_bending_rigidity_J")}
        cal["status"] = "ok"
        cal_file = os.path.join(a.work, f"calibration_{label}.json")
        with open(cal_file, "w") as f:
            json.dump(cal, f)
        case_set = {k: v for k, v in c["set"].items() if not k.startswith("full3d.")}
        run(a.swim, scene, "axi", sets({**c["set"], **c["reference"]["set"], "axi.grid.cells_across": a.cells}), W("axi"))
        calibrated = {"wall.spring_constant": None, "wall.calibration": cal_file,
                      "model1d.hydraulic_offsets.source": "calibration"}
        forced = {**case_set, "model1d.short_wave_traction": True}
        run(a.swim, scene, "1d", sets({**forced, **calibrated, "model1d.axial_bending.source": "calibration"}), W("fd"))
        sharp_ok = run(a.swim, scene, "1d", sets(forced), W("fdsharp"), may_fail=True)
        record = first_cycle(W("axi"))
        replay = {"name": case, "wave.kind": "recorded", "wave.radius_file": record, "wave.contracted_ratio": None,
                  "protocol": None}
        for ends in ("none", "junction"):
            run(a.swim, scene, "1d", sets({**replay, "model1d.end_effects": ends}), W(f"rep_{ends}"))
            run(a.swim, scene, "1d", sets({**replay, **calibrated, "model1d.end_effects": ends}), W(f"repcal_{ends}"))
        Xa, Ta = per_cycle(W("axi"))
        r = [f"{scene_name}", f"{Xa * 1e9:.2f} nm, {Ta:.3f} s"]
        for k in ("rep_none", "rep_junction", "repcal_none", "repcal_junction"):
            X, _ = per_cycle(W(k))
            cr, rms = correlation(W("axi"), W(k))
            r.append(f"{X * 1e9:.2f} nm ({X / Xa - 1:+.0%}; U(t) corr {cr:.2f}, rms {rms:.2f})")
        for k in ("fd", "fdsharp"):
            if k == "fdsharp" and not sharp_ok:
                r.append("stops: " + summary(W(k))["status"].split(":", 2)[-1].strip()[:60])
                continue
            X, T = per_cycle(W(k))
            cr, rms = correlation(W("axi"), W(k), phase=True)
            r.append(f"{X * 1e9:.2f} nm ({X / Xa - 1:+.0%}), {T:.3f} s ({T / Ta - 1:+.0%}; U(t/T) corr {cr:.2f})")
        rows.append(r)
        Xf, Tf = per_cycle(W("fd"))
        Xr, _ = per_cycle(W("repcal_none"))
        tca, tcf = max(summary(W("axi"))["segment_reached_s"]), max(summary(W("fd"))["segment_reached_s"])
        split.append([scene_name, f"{(Xf - Xa) * 1e9:+.2f} nm ({Xf / Xa - 1:+.0%})",
                      f"{(Xr - Xa) * 1e9:+.2f} nm ({(Xr - Xa) / Xa:+.0%})", f"{(Xf - Xr) * 1e9:+.2f} nm ({(Xf - Xr) / Xa:+.0%})",
                      f"{Tf / Ta - 1:+.0%}", f"{tca:.3f} / {Ta - tca:.3f} s -> {tcf:.3f} / {Tf - tcf:.3f} s"])
        if a.hybrids:
            ta, za, Ra = radius(record)
            tb, zb, Rb = radius(first_cycle(W("fd")))
            s = np.linspace(0, 2, 801)
            zq = np.linspace(0, L, 101)
            A = phase_grid(ta, za, Ra, tca, Ta, s, zq)
            B = phase_grid(tb, zb, Rb, tcf, Tf, s, zq)
            zn = zq / L
            ws = np.clip((s - 0.9) / 0.2, 0, 1)[:, None]
            hyb = {"axi": A, "1d": B, "rear fifth 1d": A + np.clip(1 - zn / 0.2, 0, 1) * (B - A),
                   "front fifth 1d": A + np.clip(1 - (1 - zn) / 0.2, 0, 1) * (B - A),
                   "contraction 1d": A + (1 - ws) * (B - A), "recovery 1d": A + ws * (B - A)}
            got = {}
            for k, G in hyb.items():
                f = os.path.join(a.work, f"hybrid_{label}_{k.replace(' ', '_')}.csv")
                write_record(f, s, zq, G, Ta)
                d = W("hybrid_" + k.replace(" ", "_"))
                run(a.swim, scene, "1d", sets({**replay, **calibrated, "wave.radius_file": f, "model1d.end_effects": "none"}), d)
                got[k] = per_cycle(d)[0]
            print(f"{scene_name}: hybrid records (calibrated offsets, plain junction), change against the axi record:")
            for k, v in got.items():
                print(f"  {k:16s} {v * 1e9:8.3f} nm ({(v - got['axi']) * 1e9:+.2f} nm)")
    print("| case | axi | 1D replay, plain | 1D replay, junction | replay, calibrated offsets, plain | replay, "
          "calibrated offsets, junction | 1D force-driven (suite default) | 1D force-driven, sharp wall |")
    print("|---" * 8 + "|")
    for r in rows:
        print("| " + " | ".join(r) + " |")
    print()
    print("| case | force-driven miss | flow model | wall | cycle time | contraction / recovery, axi -> 1D |")
    print("|---" * 6 + "|")
    for r in split:
        print("| " + " | ".join(r) + " |")


if __name__ == "__main__":
    main()
