#!/usr/bin/env python3
"""The 1D tier's lubrication flow model against the axisymmetric reference on identical
prescribed kinematics (docs/outer-flow-1d.md, "Where lubrication holds").

A grid of prescribed waves -- a step with a sharp front (w = L/8), a step with a smooth front
(w = L/4, the widest the 1D tier allows) and a sine (lambda = L) -- on tubes of R0 = 0.125 um
with L/R0 = 3.2, 6.4, 12.8 in cylinders of Rc/R0 = 1.5, 2, 4 (period about 5 L, a whole number of
cells; R_f/R0 = 0.55, 10 um/s), each over one transit, run with `swim run --tier axi` (fitted
method) and `--tier 1d`. Prints one table row per case: displacement per transit on both tiers
and axi/1D. The axi results are kept in a cache file, by default the shipped
data/calibration/flow_model_table_axi.json (they do not depend on the 1D model), so the 1D columns
are redone in seconds. With --set1d the table has a second 1D column, the 1D tier
with those settings (e.g. --set1d 'model1d.end_effects="open_ends"'), beside the plain one:

    tools/flow_model_table.py [--swim build/bin/swim] [--cells 16] [--cache FILE]
                              [--set1d key=value ...] [--only step_sharp,sine] [--L 3.2,6.4]
                              [--Rc 1.5,2,4] [--markdown] [--cached]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

R0_UM = 0.125
WAVES = {"step_sharp": ("step", 1 / 8), "step_smooth": ("step", 1 / 4), "sine": ("sine", 1.0)}


def scene(wave, L_over_R0, Rc_over_R0, cells):
    kind, frac = WAVES[wave]
    L = L_over_R0 * R0_UM
    Rc = Rc_over_R0 * R0_UM
    transit = L / 10.0  # s at 10 um/s (the sine's lambda = L)
    h = Rc / cells
    period = round(5 * L / h) * h  # the axi tier needs a whole number of cells
    sc = {"name": f"flowtable_{wave}_L{L_over_R0:g}_Rc{Rc_over_R0:g}",
          "swimmer": {"radius": f"{R0_UM} um", "length": f"{L:.6g} um"},
          "container": {"kind": "cylinder", "radius": f"{Rc:.6g} um", "period": f"{period:.12g} um"},
          "wave": {"kind": kind, "contracted_ratio": 0.55, "speed": "10 um/s"},
          "time": {"output_interval": f"{transit / 20:.9g} s"},
          "full3d": {"membrane": {"axisymmetric": True}},
          "axi": {"method": "fitted", "grid": {"cells_across": cells}}}
    if kind == "step":
        sc["wave"]["width"] = f"{frac * L:.6g} um"
    else:
        sc["wave"]["wavelength"] = f"{L:.6g} um"
    return sc


def run(swim, sc, tier, extra):
    with tempfile.TemporaryDirectory(prefix="swim-flowtable-") as d:
        path = os.path.join(d, "scene.json")
        with open(path, "w") as f:
            json.dump(sc, f)
        out = os.path.join(d, "out")
        cmd = [swim, "run", path, "--tier", tier, "--out", out, "--quiet"]
        for s in extra:
            cmd += ["--set", s]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"{' '.join(cmd)} exited {r.returncode}: {r.stderr.strip()}")
        with open(os.path.join(out, "summary.json")) as f:
            s = json.load(f)
        wall = s.get("wall_time_s", float("nan"))
        return s["displacement_m"], wall


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--swim", default=os.path.join(os.path.dirname(__file__), "..", "build", "bin", "swim"))
    ap.add_argument("--cells", type=int, default=16, help="axi.grid.cells_across (default 16: h = Rc/8)")
    ap.add_argument("--cache", default=os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "data",
                                                    "calibration", "flow_model_table_axi.json"),
                    help="axi results cache (JSON; the shipped data/calibration/flow_model_table_axi.json holds the "
                         "grid's axi runs at 16 cells across)")
    ap.add_argument("--set1d", action="append", default=[],
                    help="a --set for a second 1D column (repeatable)")
    ap.add_argument("--only", default=",".join(WAVES), help="waves: " + ",".join(WAVES))
    ap.add_argument("--L", default="3.2,6.4,12.8", help="L/R0 values")
    ap.add_argument("--Rc", default="1.5,2,4", help="Rc/R0 values")
    ap.add_argument("--markdown", action="store_true", help="print a markdown table")
    ap.add_argument("--cached", action="store_true", help="only the cases whose axi result is cached")
    a = ap.parse_args()
    cache = {}
    if os.path.exists(a.cache):
        with open(a.cache) as f:
            cache = json.load(f)
    rows = []
    for wave in a.only.split(","):
        for Rc in [float(x) for x in a.Rc.split(",")]:
            for L in [float(x) for x in a.L.split(",")]:
                sc = scene(wave, L, Rc, a.cells)
                key = f"{sc['name']}_n{a.cells}"
                if key not in cache and a.cached:
                    continue
                if key not in cache:
                    cache[key] = run(a.swim, sc, "axi", [])
                    with open(a.cache, "w") as f:
                        json.dump(cache, f, indent=1)
                x_axi, wall = cache[key]
                x_1d, _ = run(a.swim, sc, "1d", [])
                x_set = run(a.swim, sc, "1d", a.set1d)[0] if a.set1d else None
                rows.append((wave, L, Rc, x_axi, x_1d, x_set, wall))
                if not a.markdown:
                    line = (f"{wave:12s} L/R0 {L:5.1f} Rc/R0 {Rc:4.1f}  axi {x_axi * 1e9:9.3f} nm ({wall:5.1f} s)"
                            f"  1D {x_1d * 1e9:9.3f} nm  axi/1D {x_axi / x_1d:6.3f}")
                    if x_set is not None:
                        line += f"  1D (set) {x_set * 1e9:9.3f} nm  axi/1D {x_axi / x_set:6.3f}"
                    print(line, flush=True)
    if a.markdown:
        extra = " 1D with --set1d (nm) | axi/1D with --set1d |" if a.set1d else ""
        print("| wave | L/R0 | Rc/R0 | axi (nm) | 1D (nm) | axi/1D |" + extra)
        print("|---|---|---|---|---|---|" + ("---|---|" if a.set1d else ""))
        for wave, L, Rc, xa, x1, xs, _ in rows:
            line = f"| {wave} | {L:g} | {Rc:g} | {xa * 1e9:.2f} | {x1 * 1e9:.2f} | {xa / x1:.3f} |"
            if xs is not None:
                line += f" {xs * 1e9:.2f} | {xa / xs:.3f} |"
            print(line)


if __name__ == "__main__":
    main()
