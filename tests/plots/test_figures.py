"""The figures' choices, checked on small synthetic inputs: each plotting script exposes
`figure(...)` returning the matplotlib figure and a dict of what it chose.

Run by CTest (label unit) with /usr/bin/python3; exits 77 (skipped) without matplotlib.
"""
import csv
import importlib.util
import json
import math
import os
import sys
import tempfile
import unittest

try:
    import matplotlib  # noqa: F401
except ImportError:
    print("matplotlib not importable by", sys.executable)
    sys.exit(77)

TOOLS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools")


def load(name):
    spec = importlib.util.spec_from_file_location(name, os.path.join(TOOLS, name + ".py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def write_csv(path, header, rows):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(rows)


def legend_outside(fig, ax, legend):
    """True when the legend's box does not overlap the axes' box (display coordinates)."""
    fig.canvas.draw()
    lb = legend.get_window_extent()
    ab = ax.get_window_extent()
    return lb.x0 >= ab.x1 or lb.x1 <= ab.x0 or lb.y0 >= ab.y1 or lb.y1 <= ab.y0


def run_folder(d, tier="1d", status="ok"):
    R0, L = 125e-9, 400e-9
    ts = [i * 0.01 for i in range(20)]
    write_csv(f"{d}/series.csv", ["t_s", "x_center_m", "velocity_m_per_s", "energy_J", "min_radius_m", "max_radius_m"],
              [[t, t * 1e-7, 1e-7, 1e-21 * t, R0 * (1 - 0.4 * t), R0 * 1.05] for t in ts])
    write_csv(f"{d}/radius.csv", ["t_s", "z_m", "radius_m"],
              [[t, z * 1e-7, R0 * (1 - 0.4 * t * z / 4)] for t in ts for z in range(5)])
    with open(f"{d}/summary.json", "w") as f:
        json.dump({"tier": tier, "model": "force_free_confined" if tier == "1d" else "immersed_boundary",
                   "status": status, "scene": {"name": "my_scene"}, "swimmer_length_m": L,
                   "derived": {"contracted_ratio": 0.55, "aspect_ratio_R0_over_L": R0 / L},
                   "segment_reached_s": [0.12, 0.05, -1], "cycle_start_times_s": [0.0, 0.15],
                   "cycle_end_times_s": [0.15]}, f)


class RunFigure(unittest.TestCase):
    def setUp(self):
        self.mod = load("plot_run")
        self.tmp = tempfile.TemporaryDirectory()
        self.d = self.tmp.name

    def tearDown(self):
        self.tmp.cleanup()

    def test_title_names_the_scene_and_rf_and_events_are_marked(self):
        run_folder(self.d)
        fig, c = self.mod.figure(self.d)
        self.assertIn("my_scene", c["title"])
        self.assertNotIn("FAILED", c["title"])
        self.assertAlmostEqual(c["R_f_m"], 0.55 * 125e-9)
        ax = c["axes"][1, 0]
        rf = [ln for ln in ax.get_lines() if ln.get_label().startswith("R_f")]
        self.assertEqual(len(rf), 1)
        self.assertAlmostEqual(rf[0].get_ydata()[0], 0.55 * 125)  # nm
        # segment 1 at 50 ms, segment 0 at 120 ms, a cycle end and start at 150 ms; -1: not reached
        self.assertEqual([round(t, 3) for t, _ in c["events"]], [0.05, 0.12, 0.15, 0.15])
        self.assertIn("segment reaches R_f", [ln.get_label() for ln in ax.get_lines()])
        for leg, a in zip(c["legends"], (c["axes"][0, 0], c["axes"][0, 1], c["axes"][1, 0])):
            self.assertTrue(legend_outside(fig, a, leg))

    def test_failed_run_is_marked_failed(self):
        run_folder(self.d, status="failed: numerical failure: CFL 0.9 exceeds 0.5")
        fig, c = self.mod.figure(self.d)
        self.assertTrue(c["failed"])
        self.assertIn("FAILED: numerical failure", c["title"])
        self.assertEqual(fig._suptitle.get_color(), "tab:red")

    def test_run_failed_before_its_first_output_is_drawn_failed_without_data(self):
        # the run stopped at t = 0 (series.csv and radius.csv hold their headers only)
        run_folder(self.d, status="failed: numerical failure: tube radius collapsed to zero")
        write_csv(f"{self.d}/series.csv", ["t_s", "x_center_m", "velocity_m_per_s", "energy_J", "min_radius_m",
                                           "max_radius_m"], [])
        write_csv(f"{self.d}/radius.csv", ["t_s", "z_m", "radius_m"], [])
        fig, c = self.mod.figure(self.d)
        self.assertTrue(c["failed"])
        self.assertTrue(c["empty"])
        self.assertIn("FAILED: numerical failure: tube radius collapsed", c["title"])
        self.assertEqual(fig._suptitle.get_color(), "tab:red")
        texts = [t.get_text() for a in fig.axes for t in a.texts]
        self.assertTrue(any("no output time was reached" in t for t in texts), texts)
        self.mod.main(self.d)  # the script itself writes run.png for such a folder
        self.assertTrue(os.path.getsize(f"{self.d}/run.png") > 0)

    def test_3d_node_minimum_is_told_apart_from_the_ring_mean_map(self):
        run_folder(self.d, tier="3d")
        _, c = self.mod.figure(self.d)
        self.assertIn("node minimum", c["min_label"])
        self.assertIn("ring-mean", c["map_title"])


class ScreenFigure(unittest.TestCase):
    def setUp(self):
        self.mod = load("plot_screen")
        self.tmp = tempfile.TemporaryDirectory()
        self.csv = os.path.join(self.tmp.name, "designs.csv")
        rows, i = [], 0
        for L in (2e-7, 4e-7, 8e-7):
            for e in (0.35, 0.6, 0.85):
                v = 1e-8 * (1 + 10 * (L == 4e-7) * (e == 0.6)) + 1e-9 * i
                rows.append([i, f"{L * 1e6:g} um", L, e, "ok", v * 2, v])
                i += 1
        write_csv(self.csv, ["design", "swimmer.length", "swimmer.length_m", "wave.contracted_ratio", "status",
                             "displacement_m", "mean_velocity_m_per_s"], rows)

    def tearDown(self):
        self.tmp.cleanup()

    def test_best_design_marked_and_ticks_at_swept_values(self):
        fig, c = self.mod.figure(self.csv, "mean_velocity_m_per_s", "s", ["swimmer.length", "wave.contracted_ratio"])
        self.assertEqual(c["best"]["design"], "4")
        self.assertAlmostEqual(c["best_xy"][0], 400.0)  # nm
        self.assertAlmostEqual(c["best_xy"][1], 0.6)
        self.assertEqual([round(v) for v in c["xticks"]], [200, 400, 800])
        self.assertEqual(c["yticks"], [0.35, 0.6, 0.85])
        self.assertEqual(list(c["axes"][0].get_xticks()), c["xticks"])
        stars = [ln for ln in c["axes"][-1].get_lines() if ln.get_marker() == "*"]
        self.assertEqual(len(stars), 1)
        self.assertIn("best design 4", fig._suptitle.get_text())

    def test_goal_min_marks_the_smallest(self):
        _, c = self.mod.figure(self.csv, "mean_velocity_m_per_s", "s", ["swimmer.length", "wave.contracted_ratio"],
                               goal="min")
        self.assertEqual(c["best"]["design"], "0")


class CalibrationFigure(unittest.TestCase):
    def setUp(self):
        self.mod = load("plot_calibration")
        self.tmp = tempfile.TemporaryDirectory()
        self.d = self.tmp.name

    def tearDown(self):
        self.tmp.cleanup()

    def write(self, status="ok"):
        pts = []
        for i, P in enumerate((0.002, 0.02, 0.2)):
            k = (5e-10, -1e-8, -3e-8)[i]
            pts.append({"pressure_Pa": P, "displacement_m": P / 4e6 * (1 + 0.001 * i), "secant_C1_Pa_per_m": 4e6 * (1 - 0.001 * i),
                        "in_linear_range": i < 2, "stable_to_ring_buckling": k > 0,
                        "ring_mode_stiffness_N_per_m": [k, k * 1.1], "softest_ring_mode": 2 + i,
                        "softest_ring_mode_stiffness_N_per_m": k})
        with open(f"{self.d}/calibration.json", "w") as f:
            json.dump({"load_points": pts, "C1_Pa_per_m": 4e6, "C1_spring_network_Pa_per_m": 3.98e6,
                       "scene": {"name": "cal_scene"}, "grid": {"membrane_nodes": 100}, "status": status}, f)

    def test_scales_band_and_legends(self):
        self.write()
        fig, c = self.mod.figure(self.d)
        self.assertIn("cal_scene", c["title"])
        self.assertTrue(c["symlog"])
        self.assertEqual(c["axes"][2].get_yscale(), "symlog")
        # room for the n labels: the axis reaches well past the softest mode's extremes
        ax2 = c["axes"][2]
        lo2, hi2 = ax2.get_ylim()
        t = ax2.transScale
        ys = [t.transform((1, v))[1] for v in (lo2, hi2, -3e4, 5e2)]  # pN/m, in the symlog's space
        self.assertGreater(ys[2] - ys[0], 0.1 * (ys[1] - ys[0]))
        self.assertGreater(ys[1] - ys[3], 0.1 * (ys[1] - ys[0]))
        self.assertTrue(c["loglog"])
        self.assertEqual(len(c["axes"][1].patches), 0)  # no filled band
        lo, hi = c["secant_ylim"]
        self.assertFalse(lo <= c["band"][0] and c["band"][1] <= hi)  # the axis follows the data
        for a, leg in zip(c["axes"], c["legends"]):
            self.assertTrue(legend_outside(fig, a, leg))
        self.assertFalse(c["failed"])

    def test_main_writes_the_png(self):
        self.write()
        self.mod.main(self.d)
        self.assertTrue(os.path.exists(f"{self.d}/calibration.png"))
        self.assertFalse(os.path.exists(f"{self.d}/axial_stiffness.png"))

    def test_axial_stiffness_figure(self):
        self.write()
        with open(f"{self.d}/calibration.json") as f:
            c = json.load(f)
        lam = [40e-9, 80e-9, 160e-9, 320e-9]
        dx, D, c1 = 4e-9, 2e-24, 4e6
        ks = [2 * math.pi / v for v in lam]
        K = [2 / dx * math.sin(0.5 * k * dx) for k in ks]
        C = [c1 + D * q ** 4 for q in K]
        c["axial_stiffness"] = {
            "wavelengths_m": lam, "wavenumbers_per_m": ks, "lattice_wavenumbers_per_m": K, "C_Pa_per_m": C,
            "C_over_C1": [v / c1 for v in C], "C1_Pa_per_m": c1, "bending_rigidity_wall_J": D,
            "bending_rigidity_fit_J": 0.99 * D, "bending_length_m": 26.6e-9, "ring_spacing_m": dx,
            "membrane_nodes": 50000, "tube_length_m": 1.2e-6,
            "fit_with_k2": {"k2_coefficient_N_per_m": -1e-10, "bending_rigidity_J": D}}
        with open(f"{self.d}/calibration.json", "w") as f:
            json.dump(c, f)
        self.mod.main(self.d)
        self.assertTrue(os.path.exists(f"{self.d}/axial_stiffness.png"))

    def test_failed_hydraulic_measurement_looks_failed(self):
        self.write("failed: hydraulic radii: numerical failure: slipping")
        fig, c = self.mod.figure(self.d)
        self.assertTrue(c["failed"])
        self.assertIn("hydraulic radii FAILED", c["title"])
        self.assertEqual(fig._suptitle.get_color(), "tab:red")

    def test_symlog_only_for_both_signs_over_decades(self):
        self.assertTrue(self.mod.spans_signs_and_decades([1.0, -100.0]))
        self.assertFalse(self.mod.spans_signs_and_decades([1.0, 100.0]))
        self.assertFalse(self.mod.spans_signs_and_decades([-2.0, 3.0]))


def vtp_compressed(path, pts):
    """A membrane frame as swim writes it: Float32 points, zlib-compressed inline binary."""
    import base64
    import struct
    import zlib
    raw = struct.pack(f"<{3 * len(pts)}f", *[c for p in pts for c in p])
    packed = zlib.compress(raw)
    header = struct.pack("<4I", 1, len(raw), len(raw), len(packed))
    body = base64.b64encode(header).decode() + base64.b64encode(packed).decode()
    with open(path, "w") as f:
        f.write('<?xml version="1.0"?>\n<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian" '
                'header_type="UInt32" compressor="vtkZLibDataCompressor">\n<PolyData>\n<Piece>\n<Points>\n'
                f'<DataArray type="Float32" NumberOfComponents="3" format="binary">\n{body}\n</DataArray>\n'
                '</Points>\n</Piece>\n</PolyData>\n</VTKFile>\n')


class ValidationFigures(unittest.TestCase):
    def setUp(self):
        sys.path.insert(0, TOOLS)  # plot_validation imports plot_calibration
        self.mod = load("plot_validation")
        self.tmp = tempfile.TemporaryDirectory()
        self.d = self.tmp.name
        self.closed = []
        self.mod.plt.close = self.closed.append  # keep the figure for inspection

    def tearDown(self):
        self.tmp.cleanup()

    def membrane_case(self):
        import math
        R0, n_theta, rings = 125e-9, 4, 3
        pts = [(i * 1e-7, R0 * math.cos(2 * math.pi * k / n_theta), R0 * math.sin(2 * math.pi * k / n_theta))
               for i in range(rings) for k in range(n_theta)]
        os.makedirs(f"{self.d}/vtk")
        for n in range(2):
            vtp_compressed(f"{self.d}/vtk/m{n}.vtp", pts)
        with open(f"{self.d}/membrane.pvd", "w") as f:
            f.write('<Collection><DataSet timestep="0" file="vtk/m0.vtp"/><DataSet timestep="0.1" file="vtk/m1.vtp"/>'
                    '</Collection>')
        with open(f"{self.d}/summary.json", "w") as f:
            json.dump({"derived": {"n_theta": n_theta, "aspect_ratio_R0_over_L": R0 / 4e-7}}, f)
        return pts, {"name": "c", "length_m": 4e-7, "runs3d": [
            {"membrane_frames": 2, "has_cycle": True, "folder": self.d, "cycle_time_s": 0.1, "cell_size_m": 3e-8}]}

    def test_compressed_membrane_frames_are_read(self):
        pts, _ = self.membrane_case()
        got = self.mod.read_vtp_points(f"{self.d}/vtk/m0.vtp")
        self.assertEqual(len(got), len(pts))
        self.assertAlmostEqual(got[5][1], pts[5][1], delta=1e-12)

    def test_membrane_plot_draws_outlines_with_y_ticks(self):
        _, case = self.membrane_case()
        self.assertTrue(self.mod.membrane_figure(case, f"{self.d}/m.png"))
        ax = self.closed[-1].axes[0]
        outlines = [ln for ln in ax.get_lines() if len(ln.get_xdata()) == 3]
        self.assertEqual(len(outlines), 4)  # top and bottom of two snapshots
        self.assertEqual(len(ax.get_yticks()), 6)  # -R0, 0, +R0 about each snapshot
        self.assertIn("125", [t.get_text() for t in ax.get_yticklabels()])

    def test_targets_section_counts_what_each_model_met(self):
        round_wall = {"displacement_per_cycle_relative": 0.1, "cycle_time_relative": 0.15,
                      "mean_velocity_per_cycle_relative": 0.15, "velocity_phase_correlation": 0.8}
        m = {"label": "junction", "has_cycle": True,
             "target_verdicts": {"displacement_per_cycle": "pass", "cycle_time": "fail",
                                 "mean_velocity_per_cycle": "pass", "velocity_phase_correlation": "inconclusive"}}
        report = {"cases": [{"name": "round", "targets1d": round_wall, "models1d": [m, {"label": "stalls"}]},
                            {"name": "other", "models1d": [dict(m, target_verdicts={})]}]}
        md = "\n".join(self.mod.targets_markdown(report))
        self.assertIn("10 / 15 / 15 %, U(t) ≥ 0.8 for round", md)
        self.assertIn("| junction | met 2 of 4 (fail: cycle time; inconclusive: U(t)) |", md)
        self.assertIn("| stalls | no cycle |", md)
        self.assertNotIn("other", md, "a case without targets has no column")
        self.assertEqual(self.mod.targets_markdown({"cases": [{"name": "x", "models1d": []}]}), [])

    def test_phase_table_groups_the_phases_against_the_reference(self):
        # five segments: first, contractions 2-4, last, recovery; the reference's durations are
        # its extrapolated phases with their errors, its distances its finest run's with a
        # cycle; each model's time with its relative difference, its distance with the signed
        # difference in distance; a model whose phases do not match is shown without figures
        self.assertEqual([g[1] for g in self.mod.phase_groups(6)], [[0], [1, 2, 3], [4], [5]])
        self.assertEqual([g[1] for g in self.mod.phase_groups(3)], [[0], [1], [2]])
        self.assertEqual([g[1] for g in self.mod.phase_groups(2)], [[0], [1]])
        ms, nm = 1e-3, 1e-9
        phases = [{"value": v * ms, "error": 0.1 * ms} for v in (80, 30, 40, 40, 20, 200)]
        fine = {"has_cycle": True, "series": {"t_s": [0]}, "cell_size_m": 2e-8,
                "cycle_phase_times_s": [v * ms for v in (81, 30, 40, 40, 20, 201)],
                "cycle_phase_displacements_m": [v * nm for v in (3, 7, 14, 19, 19, -9)]}
        case = {"name": "c", "runs3d": [], "reference": {
            "runs": [fine, dict(fine, has_cycle=False, cell_size_m=1e-8)], "cycle_time_s": {"phases": phases}},
            "models1d": [
                {"label": "plain", "has_cycle": True,
                 "cycle_phase_times_s": [v * ms for v in (40, 30, 50, 60, 10, 100)],
                 "cycle_phase_displacements_m": [v * nm for v in (1, 7, 14, 12, 2, 1)]},
                {"label": "paper", "has_cycle": True, "cycle_phase_times_s": [0.1, 0.2],
                 "cycle_phase_displacements_m": [nm, nm]},
                {"label": "stalls", "has_cycle": False}]}
        md = "\n".join(self.mod.phases_markdown(case))
        self.assertIn("| | first contraction (front segment) | contractions 2–4 | last contraction (rear segment, 5) "
                      "| recovery |", md)
        self.assertIn("| reference | 80 ms ± 0.1 ms; 3 nm | 110 ms ± 0.3 ms; 40 nm | 20 ms ± 0.1 ms; 19 nm | "
                      "200 ms ± 0.1 ms; -9 nm |", md)
        self.assertIn("| plain | 40 ms (-50.0 %); 1 nm (-2 nm) | 140 ms (+27.3 %); 33 nm (-7 nm) | "
                      "10 ms (-50.0 %); 2 nm (-17 nm) | 100 ms (-50.0 %); 1 nm (+10 nm) |", md)
        self.assertIn("| paper | — | — | — | — |", md)
        self.assertNotIn("stalls", md)
        self.assertIn("h = 20 nm", md)
        self.assertNotIn("3D, finest grid", md)
        # beside an axisymmetric reference, the finest 3D run with the same phases gets a row
        # of its own, set against the reference like a model (a coarser one and one without
        # phases are not shown)
        run3d = {"has_cycle": True, "cell_size_m": 7.8125e-9,
                 "cycle_phase_times_s": [v * ms for v in (160, 60, 80, 80, 40, 400)],
                 "cycle_phase_displacements_m": [v * nm for v in (2, 5, 10, 13, 13, -4)]}
        case["runs3d"] = [dict(run3d, cell_size_m=1e-8), run3d, {"has_cycle": True, "cell_size_m": 5e-9}]
        md = "\n".join(self.mod.phases_markdown(case))
        self.assertIn("| 3D, finest grid (h = 7.81 nm) | 160 ms (+100.0 %); 2 nm (-1 nm) | 220 ms (+100.0 %); "
                      "28 nm (-12 nm) | 40 ms (+100.0 %); 13 nm (-6 nm) | 400 ms (+100.0 %); -4 nm (+5 nm) |", md)
        self.assertIn("the tier it judges", md)
        case["runs3d"] = []
        # without extrapolated phases: the finest run's durations, no error bars
        del case["reference"]["cycle_time_s"]
        md = "\n".join(self.mod.phases_markdown(case))
        self.assertIn("| reference | 81 ms; 3 nm |", md)
        # no 1D model with matching phases: no table
        self.assertEqual(self.mod.phases_markdown(dict(case, models1d=case["models1d"][1:])), [])
        # no reference run with phase displacements: no table
        fine.pop("cycle_phase_displacements_m")
        self.assertEqual(self.mod.phases_markdown(case), [])

    def test_phase_figure_draws_the_reference_and_each_model_per_group(self):
        # two panels (time on a log scale, distance with a zero line), one bar per group for the
        # reference (with its error bar) and for each model with matching phases; a model more
        # than 50 times the reference's largest distance is named in the title, not drawn; no
        # figure without reference phases
        ms, nm = 1e-3, 1e-9
        fine = {"has_cycle": True, "series": {"t_s": [0]}, "cell_size_m": 2e-8,
                "cycle_phase_times_s": [v * ms for v in (80, 30, 20, 200)],
                "cycle_phase_displacements_m": [v * nm for v in (3, 14, 19, -9)]}
        ok = {"label": "plain", "has_cycle": True, "cycle_phase_times_s": [v * ms for v in (40, 30, 10, 100)],
              "cycle_phase_displacements_m": [v * nm for v in (1, 14, 2, 1)]}
        huge = dict(ok, label="paper", cycle_phase_displacements_m=[v * 1e3 * nm for v in (1, 14, 2, 1)])
        other = dict(ok, label="two phases", cycle_phase_times_s=[0.1, 0.2], cycle_phase_displacements_m=[nm, nm])
        case = {"name": "c", "runs3d": [], "reference": {
            "runs": [fine], "cycle_time_s": {"phases": [{"value": v * ms, "error": 0.5 * ms} for v in (80, 30, 20, 200)]}},
            "models1d": [ok, huge, other]}
        case["runs3d"] = [{"has_cycle": True, "cell_size_m": 8e-9, "cycle_phase_times_s": [v * ms for v in (90, 40, 30, 300)],
                           "cycle_phase_displacements_m": [v * nm for v in (2, 10, 8, -5)]}]
        self.assertTrue(self.mod.phases_figure(case, f"{self.d}/p.png"))
        self.assertEqual(len(self.closed[-1].axes[0].patches), 3 * 4)  # the finest 3D run beside the axi reference
        self.assertIn("3D and 1D models", self.closed[-1]._suptitle.get_text())
        case["runs3d"] = []
        self.assertTrue(self.mod.phases_figure(case, f"{self.d}/p.png"))
        fig = self.closed[-1]
        t_ax, d_ax = fig.axes[:2]
        self.assertEqual(t_ax.get_yscale(), "log")
        self.assertEqual(len(t_ax.patches), 2 * 4)  # reference and one model, four groups each
        heights = sorted(round(b.get_height(), 6) for b in d_ax.patches)
        self.assertEqual(heights, sorted([3, 14, 19, -9, 1, 14, 2, 1]))
        self.assertEqual([t.get_text() for t in t_ax.get_xticklabels()][-1], "recovery")
        self.assertIn("off scale, not drawn: paper", fig._suptitle.get_text())
        # the reference's error bars, and only the reference's
        self.assertEqual(sum(c.__class__.__name__ == "ErrorbarContainer" for c in t_ax.containers), 1)
        self.assertTrue(os.path.exists(f"{self.d}/p.png"))
        case["models1d"] = [huge, other]
        self.assertFalse(self.mod.phases_figure(case, f"{self.d}/q.png"))
        del fine["cycle_phase_displacements_m"]
        self.assertFalse(self.mod.phases_figure(dict(case, models1d=[ok]), f"{self.d}/q.png"))

    def test_coarse_grids_are_told_apart(self):
        s = {"t_s": [0, 0.5, 1], "velocity_m_per_s": [0, 1e-8, 0]}
        case = {"name": "c", "models1d": [], "runs3d": [
            {"has_cycle": True, "series": s, "cycle_time_s": 1.0, "cell_size_m": h} for h in (4e-8, 3.2e-8, 2.7e-8)]}
        self.mod.velocity_figure(case, f"{self.d}/v.png")
        lines = [ln for ln in self.closed[-1].axes[0].get_lines() if ln.get_label().startswith("3D")]
        styles = {(str(ln.get_color()), ln.get_linestyle()) for ln in lines}
        self.assertEqual(len(styles), 3)

    def test_velocity_figure_draws_the_finest_axi_run_with_a_cycle(self):
        # the U(t) verdict's reference: the finest axi run that completed a cycle (not the
        # finest grid, which here did not), in both panels, named; none without a reference
        s = {"t_s": [0, 0.5, 1], "velocity_m_per_s": [0, 1e-8, 0]}
        case = {"name": "c", "models1d": [], "runs3d": [
            {"has_cycle": True, "series": s, "cycle_time_s": 1.0, "cell_size_m": 4e-8}],
            "reference": {"runs": [
                {"has_cycle": True, "series": s, "cycle_time_s": 2.0, "cell_size_m": 3e-8},
                {"has_cycle": True, "series": s, "cycle_time_s": 2.0, "cell_size_m": 2e-8},
                {"has_cycle": False, "series": s, "cell_size_m": 1.5e-8}]}}
        self.mod.velocity_figure(case, f"{self.d}/v.png")
        fig = self.closed[-1]
        axi = [[ln for ln in ax.get_lines() if ln.get_label().startswith("axisymmetric reference")]
               for ax in fig.axes[:2]]
        for lines in axi:
            self.assertEqual(len(lines), 1)
            self.assertIn("h = 20 nm", lines[0].get_label())
        self.assertEqual(list(axi[1][0].get_xdata()), [0, 0.25, 0.5])  # its phase on its own cycle (2 s)
        self.assertIn("axisymmetric reference", fig._suptitle.get_text())
        del case["reference"]
        self.mod.velocity_figure(case, f"{self.d}/v.png")
        self.assertFalse([ln for ln in self.closed[-1].axes[0].get_lines() if "axisymmetric" in ln.get_label()])

    def test_velocity_figure_puts_the_1d_models_in_a_row_of_their_own(self):
        # with 1D models: the 3D grids and the axi reference above, the 1D models against the
        # reference below (the finest 3D run when there is no reference), the same U scale in
        # both rows, every label once in the legend; an off-scale model is not drawn
        s = {"t_s": [0, 0.5, 1], "velocity_m_per_s": [0, 1e-8, 0]}
        big = {"t_s": [0, 0.5, 1], "velocity_m_per_s": [0, 1e-3, 0]}
        fast = {"t_s": [0, 0.25, 0.5], "velocity_m_per_s": [0, 3e-8, 0]}
        models = [{"label": "a", "has_cycle": True, "series": fast, "cycle_time_s": 0.5},
                  {"label": "b", "has_cycle": True, "series": s, "cycle_time_s": 1.0},
                  {"label": "paper", "has_cycle": True, "series": big, "cycle_time_s": 1.0},
                  {"label": "stops", "has_cycle": False}]
        runs = [{"has_cycle": True, "series": s, "cycle_time_s": 1.0, "cell_size_m": h} for h in (4e-8, 3e-8)]
        case = {"name": "c", "models1d": models, "runs3d": runs,
                "reference": {"runs": [{"has_cycle": True, "series": s, "cycle_time_s": 2.0, "cell_size_m": 2e-8}]}}
        self.mod.velocity_figure(case, f"{self.d}/v.png")
        fig = self.closed[-1]
        plots = [a for a in fig.axes if a.get_lines()]
        self.assertEqual(len(plots), 4)
        labels = [[ln.get_label() for ln in a.get_lines() if not ln.get_label().startswith("_")] for a in plots]
        for top in labels[:2]:
            self.assertEqual(sum(l.startswith("3D") for l in top), 2)
            self.assertEqual(sum(l.startswith("axisymmetric reference") for l in top), 1)
            self.assertFalse([l for l in top if l.startswith("1D")])
        for bottom in labels[2:]:
            self.assertEqual([l for l in bottom if l.startswith("1D")], ["1D: a", "1D: b"])
            self.assertEqual(sum(l.startswith("axisymmetric reference") for l in bottom), 1)
            self.assertFalse([l for l in bottom if l.startswith("3D")])
        for j in range(2):
            self.assertEqual(plots[j].get_ylim(), plots[2 + j].get_ylim())
        self.assertGreaterEqual(plots[0].get_ylim()[1], 30.0)  # the fastest 1D model's 30 nm/s fits the top row
        legend = [t.get_text().replace("\n", " ") for t in fig.legends[0].get_texts()]
        self.assertEqual(len(legend), len(set(legend)))
        self.assertEqual(sum(t.startswith("axisymmetric reference") for t in legend), 1)
        self.assertIn("paper (peak", fig._suptitle.get_text())
        # no reference: the finest 3D run is the bottom row's
        del case["reference"]
        self.mod.velocity_figure(case, f"{self.d}/v.png")
        plots = [a for a in self.closed[-1].axes if a.get_lines()]
        bottom = [ln.get_label() for ln in plots[2].get_lines() if not ln.get_label().startswith("_")]
        self.assertEqual([l for l in bottom if l.startswith("3D")], ["3D, h = 30 nm (finest)"])

    def test_convergence_grids_apart_and_not_asymptotic_said(self):
        runs = [{"has_cycle": True, "cell_size_m": h, "displacement_per_cycle_m": d}
                for h, d in ((4e-8, 7e-10), (3.2e-8, 2.7e-9), (2.67e-8, 3.7e-9))]
        case = {"name": "c", "runs3d": runs, "models1d": [], "reference3d": {
            "order_range": [0.5, 2], "displacement_per_cycle_m": {
                "value": 3.7e-9, "error": 3e-9, "asymptotic": False, "observed_order": 2.94, "order": None}}}
        self.assertTrue(self.mod.convergence_figure(case, f"{self.d}/c.png"))
        ax = self.closed[-1].axes[0]
        markers = {ln.get_marker() for ln in ax.get_lines() if len(ln.get_xdata()) == 1 and ln.get_color() == "k"}
        self.assertEqual(len(markers), 3)
        self.assertIn("h = 40 nm", [t.get_text() for t in ax.texts])
        legend = " ".join(t.get_text() for t in ax.get_legend().get_texts())
        self.assertIn("not asymptotic", legend)
        self.assertIn("observed order 2.94", legend.replace("\n", " "))

    def test_convergence_has_a_cycle_time_panel_and_draws_the_reports_expansion(self):
        runs = [{"has_cycle": True, "cell_size_m": h, "displacement_per_cycle_m": d, "cycle_time_s": t}
                for h, d, t in ((1.04e-8, 2.70e-8, 1.10), (7.8e-9, 2.92e-8, 0.88), (6.25e-9, 3.03e-8, 0.80),
                                (5.2e-9, 3.12e-8, 0.72))]
        fit = {"f0": 3.46e-8, "a_per_m": -0.8, "b_per_m2": 1e6}
        ref = {"value": 3.46e-8, "error": 6e-9, "asymptotic": False, "method": "expansion_fit", "order": 1,
               "observed_order": None, "expansion": fit}
        case = {"name": "c", "runs3d": runs, "models1d": [], "reference3d": {
            "order_range": [0.5, 2], "displacement_per_cycle_m": ref,
            "cycle_time_s": {"value": 0.59, "error": 0.69, "asymptotic": False, "method": "finest_grid",
                             "order": None, "observed_order": None}}}
        self.assertTrue(self.mod.convergence_figure(case, f"{self.d}/c2.png"))
        axes = self.closed[-1].axes
        self.assertEqual(len(axes), 2)
        self.assertEqual(axes[1].get_ylabel(), "cycle time [s]")
        fitted = [ln for ln in axes[0].get_lines() if ln.get_label().startswith("3D: fitted")]
        self.assertEqual(len(fitted), 1)
        x, y = fitted[0].get_xdata(), fitted[0].get_ydata()
        self.assertAlmostEqual(x[0], 0.0)
        self.assertAlmostEqual(y[0], 34.6, places=6)  # f0 in nm, from the report's coefficients
        self.assertFalse([ln for ln in axes[1].get_lines() if ln.get_label().startswith("3D: fitted")])
        # 0.59 s +- 0.69 s: a cycle time is positive, so its axis starts at zero and cuts the bar
        self.assertEqual(axes[1].get_ylim()[0], 0.0)
        self.assertGreater(axes[1].get_ylim()[1], 1.28)

    def test_sweep_names_an_off_scale_model_and_keeps_the_legend_off_the_axes(self):
        # a model 50 times the references at one case (the paper's reproduction: 175 um against
        # 74 nm) is named in the title, not drawn; the others are drawn, the legend below the axes
        def case(v, ref, paper):
            return {"group": "amplitude", "sweep_value": v,
                    "reference3d": {"displacement_per_cycle_m": {"value": 0.9 * ref, "error": 1e-9}},
                    "reference": {"displacement_per_cycle_m": {"value": ref, "error": 1e-10}},
                    "models1d": [{"label": "default", "displacement_per_cycle_m": 0.8 * ref},
                                 {"label": "paper's", "displacement_per_cycle_m": paper}]}
        report = {"suite": "s", "cases": [case(0.55, 7.4e-8, 1.75e-4), case(0.82, 1.9e-8, 4.6e-8)]}
        self.assertTrue(self.mod.sweep_figure(report, "amplitude", "R_f / R0", "displacement_per_cycle_m",
                                              "displacement per cycle [nm]", 1e9, f"{self.d}/s.png", "t"))
        fig = self.closed[-1]
        ax = fig.axes[0]
        drawn = [ln.get_label() for ln in ax.get_lines()]
        self.assertIn("1D: default", drawn)
        self.assertNotIn("1D: paper's", drawn)
        self.assertIn("off scale, not drawn: 1D: paper's (up to 175 µm)", fig._suptitle.get_text())
        self.assertLess(ax.get_ylim()[1], 100)  # nm: the drawn lines set the scale
        self.assertTrue(legend_outside(fig, ax, fig.legends[0]))
        self.assertGreater(ax.get_position().width, 0.7)  # the axes keep the figure's width

    def test_reference_convergence_marks_the_grids_without_a_cycle(self):
        ok = [{"has_cycle": True, "cell_size_m": h, "displacement_per_cycle_m": d, "cycle_time_s": t}
              for h, d, t in ((1.25e-8, 7.8e-8, 3.6), (1.04e-8, 7.5e-8, 3.4))]
        stuck = [{"has_cycle": False, "cell_size_m": h, "status": "failed: numerical failure: the protocol did "
                  "not complete 1 cycle(s) within full3d.time_limit = 5 s"} for h in (1.56e-8, 7.81e-9)]
        val = {"value": 1.0e-7, "error": 1e-9, "converged": False}
        # the long legend entries of the converged suite's two-panel cases: an expansion fit's
        # with the three finest grids' order, and a cycle time summed from seven phases
        phases = [{"observed_order": p} for p in (2.63, 5.56, None, 0.95, 5.13, 4.31, 1.56)]
        case = {"name": "c", "runs3d": stuck[:1] + ok + stuck[1:], "models1d": [],
                "reference3d": {"displacement_per_cycle_m": dict(val, method="expansion_fit", observed_order=1.98),
                                "cycle_time_s": dict(val, value=2.7)},
                "reference": {"runs": [dict(r, cell_size_m=2 * r["cell_size_m"]) for r in ok],
                              "displacement_per_cycle_m": val, "cycle_time_s": dict(val, value=2.7, phases=phases)}}
        self.assertTrue(self.mod.reference_convergence_figure(case, f"{self.d}/r.png"))
        ax = self.closed[-1].axes[0]
        marks = [ln for ln in ax.get_lines() if ln.get_linestyle() == ":"]
        self.assertEqual(sorted(round(ln.get_xdata()[0], 2) for ln in marks), [7.81, 15.6])
        # the labels are wrapped to the panel's width: read them with the line breaks as spaces
        legend = " ".join(" ".join(t.get_text().split()) for t in ax.get_legend().get_texts())
        self.assertIn("3D runs without a cycle (time limit): h = 7.81, 15.6 nm", legend)
        self.assertNotIn("axisymmetric runs without a cycle", legend)
        # the two panels' legends neither overlap nor leave the figure
        fig = self.closed[-1]
        fig.canvas.draw()
        boxes = [a.get_legend().get_window_extent(fig.canvas.get_renderer()) for a in fig.axes[:2]]
        self.assertLess(boxes[0].x1, boxes[1].x0)
        self.assertGreaterEqual(boxes[0].x0, fig.bbox.x0)
        self.assertLessEqual(boxes[1].x1, fig.bbox.x1)

    def test_pareto_labels_do_not_overlap(self):
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots()
        ax.plot([1, 1.0001, 10], [1, 1, 1])
        texts = [ax.annotate(f"rtol = 1e-0{k}", (1 + 1e-4 * k, 1), xytext=(4, -10), textcoords="offset points",
                             fontsize=7) for k in range(3)]
        self.assertGreater(self.mod.declutter(fig, texts), 0)
        fig.canvas.draw()
        boxes = [t.get_window_extent() for t in texts]
        for i in range(len(boxes)):
            for j in range(i):
                self.assertFalse(boxes[i].overlaps(boxes[j]))


class ValidationErrorText(unittest.TestCase):
    """A value with its error in the value's own SI prefix (the phase table's durations): the
    error is scaled by the prefix itself, not by the rounded value's digits."""

    def setUp(self):
        self.mod = load("plot_validation")

    def test_the_error_takes_the_values_prefix(self):
        pm = self.mod.pm_in_unit_of
        # 100.4 ms shows as 100 ms; its error 0.1252 ms must read 0.13 ms (0.12 when scaled by
        # the rounded value's ratio 0.1004 / 100, 0.4 % off)
        self.assertEqual(pm(0.1004, 1.252e-4, "s"), "100 ms ± 0.13 ms")
        self.assertEqual(pm(1.0585, 0.0098, "s"), "1.06 s ± 0.0098 s")
        self.assertEqual(pm(151.2e-9, 1.45e-9, "m"), "151 nm ± 1.4 nm")
        self.assertEqual(pm(0.32, None, "s"), "320 ms")
        # an error below 10^-4 of the prefix's unit takes a prefix of its own
        self.assertEqual(pm(0.32, 2e-9, "s"), "320 ms ± 2 ns")


class ValidationWrinkleCell(unittest.TestCase):
    """The report's wall-wrinkle cell: the lobe number, the lobes in order when they changed
    during the run, "round" for a wall held axisymmetric."""

    def setUp(self):
        self.mod = load("plot_validation")

    def test_lobes_and_their_change(self):
        run = {"max_wrinkle_m": 11.6e-9, "max_wrinkle_over_h": 3.0, "max_wrinkle_mode": 8}
        self.assertEqual(self.mod.wrinkle(run), "11.6 nm (m = 8)")
        run["wrinkle_modes_over_half_cell"] = [8]
        self.assertEqual(self.mod.wrinkle(run), "11.6 nm (m = 8)")
        run["wrinkle_modes_over_half_cell"] = [8, 4]
        self.assertEqual(self.mod.wrinkle(run), "11.6 nm (m = 8, then 4)")
        self.assertEqual(self.mod.wrinkle({"max_wrinkle_m": 1e-20, "max_wrinkle_over_h": 1e-12}), "round")

    def test_the_wrinkle_paragraph_names_what_chose_the_lobes(self):
        """A case whose grids all grew the seed's lobes and then the secondary seed's is
        said to follow its seeds; one grid that took other lobes makes it the grid's."""
        def run(modes, secondary=4):
            return {"max_wrinkle_m": 16e-9, "max_wrinkle_over_h": 3.0, "max_wrinkle_mode": modes[-1],
                    "wrinkle_modes_over_half_cell": modes, "seed_mode": 8, "secondary_seed_mode": secondary}
        grids = [run([8, 4]), run([8, 4]), run([8, 4])]
        text = " ".join(self.mod.wrinkle_paragraph(grids))
        self.assertIn("the m = 4 lobes of its secondary seed, on every grid", text)
        self.assertNotIn("follows the grid", text)
        text = " ".join(self.mod.wrinkle_paragraph(grids[:2] + [run([8, 3, 5])]))
        self.assertIn("lobes whose pattern follows the grid", text)
        text = " ".join(self.mod.wrinkle_paragraph([run([8], 0)] * 2))
        self.assertIn("the m = 8 lobes seeded in its stress-free shape, on every grid", text)


if __name__ == "__main__":
    unittest.main()
