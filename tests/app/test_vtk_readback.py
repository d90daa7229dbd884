"""A 3D run's VTK frames read back by VTK's own XML readers (python3-vtk9, the readers of
ParaView 5.11) and compared with an independent decoding of the same files (base64, the
zlib block header, the raw arrays): every frame of membrane.pvd and fluid.pvd opens without
an error, carries its time (FieldData TimeValue, equal to its collection's timestep), and every
array VTK reads holds the values written, with its type (segment and the cylinder's
inside_container as 32-bit integers).

usage: test_vtk_readback.py SWIM_EXECUTABLE SOURCE_DIR
Run by CTest (label regression) with /usr/bin/python3; exits 77 (skipped) without VTK's Python
modules.
"""
import base64
import json
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import unittest
import xml.etree.ElementTree as ET
import zlib

try:
    from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: F401
    from vtkmodules.vtkCommonCore import vtkCommand
    from vtkmodules.vtkIOXML import vtkXMLImageDataReader, vtkXMLPolyDataReader
except ImportError:
    print("VTK's Python modules (python3-vtk9) are not importable by", sys.executable)
    sys.exit(77)

SWIM, SOURCE = sys.argv[1], sys.argv[2]
TYPES = {"Float32": "f", "Float64": "d", "Int32": "i", "Int64": "q", "UInt8": "B", "UInt32": "I", "UInt64": "Q"}
VTK_TYPE = {"Float32": "vtkFloatArray", "Float64": "vtkDoubleArray", "Int32": "vtkIntArray", "Int64": "vtkLongLongArray",
            "UInt8": "vtkUnsignedCharArray"}


def decode(body, vtype):
    """The values of one binary, zlib-compressed DataArray body (header_type UInt32): the block
    header [blocks, block size, last block size, compressed sizes...], then the blocks, each
    base64-encoded apart from the header."""
    body = body.strip()
    n_head = base64.b64decode(body[:8])  # the first 4 UInt32 words are 16 bytes = 24 base64 chars
    nblocks = struct.unpack("<I", n_head[:4])[0]
    head_len = 4 * (3 + nblocks)
    head_chars = 4 * ((head_len + 2) // 3)
    head = struct.unpack(f"<{3 + nblocks}I", base64.b64decode(body[:head_chars])[:head_len])
    data = base64.b64decode(body[head_chars:])
    raw, at = b"", 0
    for size in head[3:]:
        raw += zlib.decompress(data[at:at + size])
        at += size
    fmt = TYPES[vtype]
    return list(struct.unpack(f"<{len(raw) // struct.calcsize(fmt)}{fmt}", raw))


def arrays_of(path):
    """Every DataArray of a frame as written: name -> (section, type, components, values); the
    unnamed point coordinates under "Points", the polygons' arrays under their own names."""
    root = ET.parse(path).getroot()
    assert root.get("compressor") == "vtkZLibDataCompressor", path
    assert root.get("header_type") == "UInt32", path
    out = {}
    for section in ("FieldData", "PointData", "CellData", "Points", "Polys"):
        for sec in root.iter(section):
            for a in sec.iter("DataArray"):
                out[a.get("Name") or section] = (section, a.get("type"), int(a.get("NumberOfComponents", "1")),
                                      decode(a.text, a.get("type")))
    return out


def read_with_vtk(path):
    """VTK's own reader of the file, with its errors collected."""
    reader = vtkXMLPolyDataReader() if path.endswith(".vtp") else vtkXMLImageDataReader()
    errors = []
    reader.AddObserver(vtkCommand.ErrorEvent, lambda obj, ev: errors.append(ev))
    reader.SetFileName(path)
    reader.Update()
    return reader.GetOutput(), errors


class VtkReadsEveryFrame(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="swim_vtk_readback_")
        cls.out = os.path.join(cls.tmp, "run")
        # the paper's rigid cylinder (its fluid frames carry the inside/outside mask), 4 ms
        cmd = [SWIM, "run", os.path.join(SOURCE, "data/scenes/paper_aspect_L0.2.json"), "--tier", "3d", "--quiet",
               "--threads", "2", "--out", cls.out, "--set", 'time.duration="4 ms"',
               "--set", 'full3d.output.vtk_interval="2 ms"', "--set", "full3d.output.fluid_fields=true",
               "--set", 'full3d.output.fluid_interval="2 ms"']
        cls.proc = subprocess.run(cmd, capture_output=True, text=True)
        with open(os.path.join(cls.out, "summary.json")) as f:
            cls.summary = json.load(f)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def frames(self, kind):
        root = ET.parse(os.path.join(self.out, f"{kind}.pvd")).getroot()
        return [(float(d.get("timestep")), os.path.join(self.out, d.get("file"))) for d in root.iter("DataSet")]

    def check_arrays(self, data, written, sections):
        """Every array written in `sections` is read by VTK under its name, with its type,
        components and values."""
        for name, (section, vtype, comps, values) in written.items():
            if section not in sections:
                continue
            with self.subTest(array=name):
                arr = sections[section](data).GetArray(name)
                self.assertIsNotNone(arr, name)
                self.assertEqual(arr.GetClassName(), VTK_TYPE[vtype])
                self.assertEqual(arr.GetNumberOfComponents(), comps)
                self.assertEqual(arr.GetNumberOfValues(), len(values))
                self.assertEqual(list(vtk_to_numpy(arr).ravel()), values)

    def test_the_run_succeeds(self):
        self.assertEqual(self.proc.returncode, 0, self.proc.stderr)
        self.assertEqual(self.summary["status"], "ok")

    def test_membrane_frames(self):
        frames = self.frames("membrane")
        self.assertGreaterEqual(len(frames), 2)
        segments = self.summary["scene"]["protocol"]["segments"]
        for t, path in frames:
            with self.subTest(frame=os.path.basename(path)):
                data, errors = read_with_vtk(path)
                self.assertEqual(errors, [])
                written = arrays_of(path)
                self.assertGreater(data.GetNumberOfPoints(), 0)
                self.assertEqual(data.GetNumberOfPoints() * 3, len(written["Points"][3]))
                self.assertGreater(data.GetNumberOfPolys(), 0)
                tv = data.GetFieldData().GetArray("TimeValue")
                self.assertIsNotNone(tv)
                self.assertAlmostEqual(tv.GetValue(0), t, delta=1e-9 * max(1.0, t))
                seg = data.GetPointData().GetArray("segment") or data.GetCellData().GetArray("segment")
                self.assertEqual(seg.GetClassName(), "vtkIntArray")
                self.assertEqual(seg.GetRange(), (0.0, float(segments - 1)))
                pts = list(vtk_to_numpy(data.GetPoints().GetData()).ravel())
                self.assertEqual(pts, written["Points"][3])
                # the triangles: VTK's offsets start at 0, the file lists each polygon's end
                polys = data.GetPolys()
                self.assertEqual(list(vtk_to_numpy(polys.GetConnectivityArray())), written["connectivity"][3])
                self.assertEqual(list(vtk_to_numpy(polys.GetOffsetsArray()))[1:], written["offsets"][3])
                self.check_arrays(data, written, {"FieldData": lambda d: d.GetFieldData(),
                                                  "PointData": lambda d: d.GetPointData(),
                                                  "CellData": lambda d: d.GetCellData()})

    def test_fluid_frames_of_the_cylinder(self):
        frames = self.frames("fluid")
        self.assertGreaterEqual(len(frames), 2)
        for t, path in frames:
            with self.subTest(frame=os.path.basename(path)):
                data, errors = read_with_vtk(path)
                self.assertEqual(errors, [])
                with open(path) as f:
                    ext = [int(v) for v in re.search(r'WholeExtent="([^"]+)"', f.read()).group(1).split()]
                self.assertEqual(list(data.GetExtent()), ext)
                tv = data.GetFieldData().GetArray("TimeValue")
                self.assertAlmostEqual(tv.GetValue(0), t, delta=1e-9 * max(1.0, t))
                mask = data.GetCellData().GetArray("inside_container")
                self.assertEqual(mask.GetClassName(), "vtkIntArray")
                self.assertEqual(mask.GetRange(), (0.0, 1.0))  # both sides of the wall present
                self.assertEqual(mask.GetNumberOfTuples(), data.GetNumberOfCells())
                self.check_arrays(data, arrays_of(path), {"FieldData": lambda d: d.GetFieldData(),
                                                          "PointData": lambda d: d.GetPointData(),
                                                          "CellData": lambda d: d.GetCellData()})


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
