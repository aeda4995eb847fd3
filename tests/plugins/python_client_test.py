"""Tests of the shared plugin package footfall_client (plain python3, unittest) against a real
libfootfall.so and a real footfalld started here on a free loopback port.

Run: FOOTFALL_LIB=build/client/lib/libfootfall.so FOOTFALLD=build/server/service/footfalld \
     PYTHONPATH=plugins/python python3 -m unittest tests/plugins/python_client_test.py
"""

import contextlib
import ctypes
import json
import math
import os
import pickle
import re
import signal
import subprocess
import sys
import tempfile
import time
import types
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(REPO, "plugins", "python"))

import footfall_client as ff  # noqa: E402

HILLS = os.path.join(REPO, "data", "terrain", "hills.pts")
CHARACTERS = os.environ.get("FOOTFALL_CHARACTERS") or os.path.join(REPO, "data", "characters")


def sample_rows(flat):
    """Flat samples (sampling.sample_triangles_flat's array('d'), 6 doubles a sample) as a list
    of (x, y, z, nx, ny, nz) tuples; AssertionError for anything else."""
    from array import array
    if not (type(flat) is array and flat.typecode == "d" and len(flat) % 6 == 0):
        raise AssertionError("expected an array('d') of whole samples, got a %s"
                             % type(flat).__name__)
    return list(zip(*[iter(flat)] * 6))


def packed_rows(rows):
    """The samples' doubles, struct-packed in order (their bits); only floats."""
    import struct
    values = [v for row in rows for v in row]
    for v in values:
        if type(v) is not float:
            raise AssertionError("%r is a %s, not a float" % (v, type(v).__name__))
    return struct.pack("<%dd" % len(values), *values)


def sampling_meshes():
    """(name, points, triangles, separations) of meshes for the resampling's tests: a waved
    grid, a closed box (90 degree creases), stairs, and triangles sharing a vertex with a
    zero-area one, a repeated vertex and integer coordinates."""
    n, spacing = 9, 0.5
    wavy = [(i * spacing, 0.3 * math.sin(0.9 * i * spacing) * math.cos(0.7 * j * spacing),
             j * spacing) for j in range(n) for i in range(n)]
    grid_tris = []
    for j in range(n - 1):
        for i in range(n - 1):
            a = j * n + i
            grid_tris += [(a, a + n, a + 1), (a + 1, a + n, a + n + 1)]
    corners = [(x, y, z) for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)]
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    box_tris = [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]
    profile = []
    for k in range(4):
        profile += [(k * 0.17, k * 0.28), ((k + 1) * 0.17, k * 0.28)]
    profile.append((4 * 0.17, 4 * 0.28))
    stairs = [(x, y, z) for y, z in profile for x in (0.0, 1.2)]
    stairs_tris = []
    for k in range(len(profile) - 1):
        a = 2 * k
        stairs_tris += [(a, a + 2, a + 1), (a + 1, a + 2, a + 3)]
    odd = [(0, 0, 0), (2, 0, 0), (0, 1, 2), (1, 3, 1), (1.0, 0.0, 0.0), (0.5, 0.25, 1.0)]
    odd_tris = [(0, 2, 1), (1, 2, 3), (0, 4, 1), (0, 0, 3), (0, 5, 2)]
    return [("wavy grid", wavy, grid_tris, (0.09, 0.6)), ("box", corners, box_tris, (0.23, 2.0)),
            ("stairs", stairs, stairs_tris, (0.05, 0.4)), ("odd", odd, odd_tris, (0.3, 0.7))]


def tuples_and_flat_samples():
    """(name, sample_triangles' tuples, sample_triangles_flat's array) of each of
    sampling_meshes() at its first separation, with corner normals."""
    for name, pts, tris, separations in sampling_meshes():
        normals = ff.sampling.corner_normals(pts, tris)
        yield (name,
               ff.sampling.sample_triangles(pts, tris, separations[0], corner_normals=normals),
               ff.sampling.sample_triangles_flat(pts, tris, separations[0],
                                                 corner_normals=normals))


def flat_grid(n=21, spacing=0.5, height=0.0):
    """n x n samples on the plane y = height, normal +Y, as 6-tuples."""
    return [(i * spacing, height, j * spacing, 0.0, 1.0, 0.0) for i in range(n) for j in range(n)]


class EmbeddedTest(unittest.TestCase):
    def setUp(self):
        self.s = ff.Session.embedded()

    def tearDown(self):
        self.s.close()

    def test_samples_load_and_snap(self):
        t = self.s.load_samples(flat_grid(), "flat")
        count, bounds = self.s.info(t)
        self.assertEqual(count, 21 * 21)
        self.assertEqual(bounds, (0.0, 0.0, 0.0, 10.0, 0.0, 10.0))
        hold = self.s.snap(t, [(1.1, 3.0, 2.4)])[0]
        self.assertTrue(hold.ok)
        self.assertEqual(hold.point, (1.0, 0.0, 2.5))
        self.assertEqual(hold.normal, (0.0, 1.0, 0.0))
        # A flat sequence of floats is accepted as well as tuples.
        self.assertEqual(self.s.snap(t, [1.1, 3.0, 2.4])[0], hold)

    def test_next_steps_forward(self):
        t = self.s.load_samples(flat_grid(), "flat")
        hold = self.s.next(t, [(2.0, 0.0, 2.0, 0.0, 0.0, 1.0)])[0]
        self.assertTrue(hold.ok, hold)
        self.assertAlmostEqual(hold.point[0], 2.0)
        self.assertAlmostEqual(hold.point[2], 3.0)

    def test_bad_input_raises_with_status_and_message(self):
        with self.assertRaises(ff.FootfallError) as e:
            self.s.load_file(os.path.join(tempfile.gettempdir(), "no-such-terrain.pts"))
        self.assertEqual(e.exception.status_name, "io_error")
        self.assertIn("no-such-terrain.pts", e.exception.message)
        self.assertEqual(e.exception.call, "ffc_load_file")
        with self.assertRaises(ff.FootfallError) as e:
            self.s.load_samples([(1, 2, 3)])
        self.assertEqual(e.exception.status_name, "invalid_argument")
        with self.assertRaises(ff.FootfallError) as e:
            self.s.snap(12345, [(0, 0, 0)])
        self.assertEqual(e.exception.status_name, "unknown_terrain")
        self.assertTrue(e.exception.message)

    def test_paths_as_bytes_path_objects_and_undecodable_names(self):
        import pathlib
        import shutil
        # bytes were sent as the text "b'...'"; an undecodable name raised UnicodeEncodeError.
        t = self.s.load_file(HILLS.encode())
        self.assertEqual(self.s.info(t)[0], self.s.info(self.s.load_file(pathlib.Path(HILLS)))[0])
        folder = tempfile.mkdtemp()
        try:
            odd = os.path.join(folder.encode(), b"h\xe9\xff.pts")
            shutil.copyfile(HILLS, odd)
            name = os.fsdecode(odd)  # a str holding surrogate escapes
            self.assertEqual(self.s.info(self.s.load_file(name))[0], self.s.info(t)[0])
        finally:
            shutil.rmtree(folder)
        with self.assertRaises(ff.FootfallError) as e:
            self.s.load_file(12345)
        self.assertEqual(e.exception.status_name, "invalid_argument")

    def test_closed_sessions_do_not_answer_and_odd_arguments_raise_footfall_errors(self):
        s = ff.Session.embedded()
        s.close()
        self.assertFalse(s.ping())
        with self.assertRaises(ff.FootfallError):
            self.s.check_character(b"{}")
        with self.assertRaises(ff.FootfallError) as e:
            self.s.load_file("/tmp/no\x00pe.pts")
        self.assertIn("NUL", e.exception.message)
        # An upload's name, or a JSON text, cut short at a NUL by the C library: refused whole.
        with self.assertRaises(ff.FootfallError) as e:
            self.s.load_samples([(0, 0, 0, 0, 1, 0)], "ground\x00 (copy)")
        self.assertIn("NUL", e.exception.message)
        self.assertEqual(e.exception.status_name, "invalid_argument")
        with self.assertRaises(ff.FootfallError) as e:
            self.s.check_character('{"format": "footfall-character"}\x00 trailing')
        self.assertIn("NUL byte at offset 32", e.exception.message)
        folder = tempfile.mkdtemp()
        try:
            fifo = os.path.join(folder, "out.pts")
            os.mkfifo(fifo)
            with self.assertRaises(ValueError):  # writing would wait for a reader
                ff.sampling.write_point_file(fifo, [(0, 0, 0, 0, 1, 0)])
        finally:
            os.unlink(fifo)
            os.rmdir(folder)

    def test_bad_terrain_ids_numbers_and_requests_raise_footfall_errors(self):
        t = self.s.load_samples(flat_grid(3), "small")
        # Ids beyond uint32_t wrapped onto another terrain (unload(2**32 + t) unloaded t).
        for bad in (2 ** 32 + t, -1, None, "x", 1.0, True):
            with self.assertRaises(ff.FootfallError) as e:
                self.s.unload(bad)
            self.assertEqual(e.exception.status_name, "invalid_argument")
            self.assertIn("terrain", e.exception.message)
            for call in (lambda: self.s.info(bad), lambda: self.s.snap(bad, [(0, 0, 0)]),
                         lambda: self.s.next(bad, [(0, 0, 0, 1, 0, 0)]),
                         lambda: self.s.generate(bad, {"steps": 1})):
                with self.assertRaises(ff.FootfallError):
                    call()
        self.assertEqual(self.s.info(t)[0], 9)  # still loaded
        deep = {}
        for _ in range(100000):  # nested past Python's recursion limit
            deep = {"a": deep}
        for call in (lambda: self.s.next(t, [(0, 0, 0, 1, 0, 0)], "wide"),
                     lambda: self.s.load_file("x.pts", "fine"),
                     lambda: self.s.generate(t, ["steps", 1]),
                     lambda: self.s.generate(t, {"steps": float("nan")}),
                     lambda: self.s.generate(t, {"steps": object()}),
                     lambda: self.s.next(t, [(0, 0, 0, 1, 0, 0)], 10 ** 400),
                     lambda: self.s.snap(t, [(10 ** 400, 0, 0)]),
                     lambda: self.s.load_file("x.pts", 10 ** 400),
                     # (A NaN separation was taken for the default, an infinite one refused.)
                     lambda: self.s.load_file(HILLS, float("nan")),
                     lambda: self.s.load_server_file(HILLS, float("nan")),
                     lambda: self.s.generate(t, deep),
                     lambda: self.s.check_character(deep)):
            with self.assertRaises(ff.FootfallError) as e:
                call()
            self.assertEqual(e.exception.status_name, "invalid_argument")
        self.s.unload(t)

    def test_unbounded_timeouts_are_refused(self):
        for timeout in (float("inf"), float("nan"), 1e300, "soon", 10 ** 400, 1e-9, 0.0009):
            with self.assertRaises(ff.FootfallError) as e:
                ff.Session.rpc("127.0.0.1", 9, timeout)
            self.assertIn("timeout", e.exception.message)

    def test_an_open_that_runs_out_of_memory_says_so(self):
        # ffc_open_* returned NULL for want of memory: the package said the host was bad, or
        # "internal_error", where the library says it ran out of memory.
        script = (
            "import os, sys\n"
            "import footfall_client as ff\n"
            "from footfall_client.library import load_library\n"
            "load_library()  # its static constructors before memory runs out\n"
            "flag = sys.argv[1]\n"
            "for open_ in (lambda: ff.Session.rpc('127.0.0.1', 7407), ff.Session.embedded):\n"
            "    with open(flag, 'w') as f:\n"
            "        f.write('0\\n')\n"
            "    try:\n"
            "        open_()\n"
            "        print('opened')\n"
            "    except ff.FootfallError as e:\n"
            "        print(e.status_name, '|', e.message)\n"
            "    finally:\n"
            "        os.unlink(flag)\n")
        with tempfile.TemporaryDirectory() as tmp:
            env = dict(os.environ, LD_PRELOAD=os.environ["FOOTFALL_FAILING_NEW"],
                       FOOTFALL_FAIL_NEW_WHILE=os.path.join(tmp, "flag"),
                       FOOTFALL_FAIL_NEW_EVERY="1")
            run = subprocess.run([sys.executable, "-c", script, os.path.join(tmp, "flag")],
                                 env=env, capture_output=True, text=True, timeout=60)
        self.assertEqual(run.returncode, 0, run.stderr)
        lines = run.stdout.splitlines()
        self.assertEqual(len(lines), 2, run.stdout)
        for line in lines:
            self.assertTrue(line.startswith("limit_exceeded | ") and "out of memory" in line,
                            line)

    def test_closed_session_raises_instead_of_crashing(self):
        self.s.close()
        with self.assertRaises(ff.FootfallError) as e:
            self.s.snap(0, [(0, 0, 0)])
        self.assertIn("closed", e.exception.message)


class SharedLogicTest(unittest.TestCase):
    """The pure-Python parts both plugins use: mesh resampling and character files."""

    def test_a_biped_on_a_wall_is_told_in_the_scene_s_terms(self):
        # The generator advises giving the request's "up", which the plugins never set (their
        # scene's up is footfall's): said in Blender and Maya as advice their users can follow.
        wall = [(0.0, 0.1 * i, 0.1 * j, 1.0, 0.0, 0.0) for i in range(41) for j in range(41)]
        with ff.Session.embedded() as s:
            terrain = s.load_samples(wall, "wall")
            request = {"character": ff.character.load(os.path.join(CHARACTERS, "biped.json")),
                       "steps": 4}
            status, _, message, _ = s.generate_json_with_notes(terrain, request)
        self.assertNotEqual(status, 0)
        self.assertIn("; if the terrain's up is not (0.0000, 1.0000, 0.0000), give the world up "
                      "with request: 'up' (X up: [1, 0, 0])", message)
        said = ff.character.in_scene_terms(message, "Z")
        self.assertNotIn("request: 'up'", said)
        self.assertIn("ground leans 90 deg, more than max_slope_deg 45; a biped stands upright "
                      "along the scene's Z axis: turn the terrain so that its ground faces +Z; "
                      "walk stopped", said)
        self.assertEqual(ff.character.in_scene_terms("step 2: a cliff", "Y"), "step 2: a cliff")

    def test_errors_survive_pickling(self):
        # A multiprocessing pool sends a worker's exception back pickled: one that cannot be
        # rebuilt kills the pool's result thread and the caller waits forever.
        for error in (ff.FootfallError(8, "footfalld at 127.0.0.1:1: refused", "ffc_snap"),
                      ff.WalkStopped(1, "step 3: a cliff", {"tracks": []})):
            copy = pickle.loads(pickle.dumps(error))
            self.assertIs(type(copy), type(error))
            self.assertEqual((copy.status, copy.status_name, copy.message, copy.call, str(copy)),
                             (error.status, error.status_name, error.message, error.call,
                              str(error)))
            self.assertEqual(getattr(copy, "walk", None), getattr(error, "walk", None))
        stopped = ff.WalkStopped(1, "step 3: a cliff", {"tracks": []}, notes=["far start"])
        self.assertEqual(pickle.loads(pickle.dumps(stopped)).notes, ["far start"])

    def test_square_resampled_in_halves(self):
        pts = [(0, 0, 0), (1, 0, 0), (1, 0, 1), (0, 0, 1)]
        tris = [(0, 2, 1), (0, 3, 2)]  # counter-clockwise seen from +Y
        samples = ff.sampling.sample_triangles(pts, tris, 0.75)  # diagonal 1.41: halves
        self.assertEqual(sorted(s[:3] for s in samples),
                         sorted((x / 2, 0.0, z / 2) for x in range(3) for z in range(3)))
        for s in samples:
            self.assertEqual(s[3:], (0.0, 1.0, 0.0))
        with ff.Session.embedded() as s:
            t = s.load_samples(samples, "square")
            self.assertEqual(s.info(t)[0], 9)

    def test_point_file_round_trips_exactly(self):
        samples = ff.sampling.sample_triangles([(0, 0.1, 0), (0.3, 0.7, 0), (0, 0.2, 0.9)],
                                               [(0, 2, 1)], 0.1)
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "t.pts")
            ff.sampling.write_point_file(path, samples)
            with ff.Session.embedded() as s:
                a, b = s.load_file(path), s.load_samples(samples)
                probe = [p[:3] for p in samples[::7]]
                self.assertEqual(s.snap(a, probe), s.snap(b, probe))

    def test_corner_normals_keep_sharp_edges(self):
        # A floor square and a square folded up from its edge z = 0 by `fold` degrees, vertices
        # shared: smooth across 20 degrees, sharp across 90 (the crease angle is 60).
        for fold, sharp in ((20.0, False), (90.0, True)):
            a = math.radians(fold)
            pts = [(0, 0, -1), (1, 0, -1), (0, 0, 0), (1, 0, 0),
                   (0, math.sin(a), math.cos(a)), (1, math.sin(a), math.cos(a))]
            tris = [(0, 2, 3), (0, 3, 1), (2, 4, 5), (2, 5, 3)]
            normals = ff.sampling.corner_normals(pts, tris)
            floor = normals[0][1]  # tris[0] corner at vertex 2, on the fold
            self.assertAlmostEqual(floor[1], 1.0 if sharp else math.cos(a / 2), delta=0.1)
            self.assertEqual(normals[0][0], (0.0, 1.0, 0.0))  # away from the fold: the face's
            samples = ff.sampling.sample_triangles(pts, tris, 0.25, corner_normals=normals)
            on_floor = [s for s in samples if s[1] == 0 and s[2] < -1e-9]
            self.assertTrue(on_floor)
            leaning = [s for s in on_floor if abs(s[4] - 1.0) > 1e-9]
            self.assertEqual(leaning == [], sharp)
        # Smoothed everywhere (180): the fold's corner leans even at 90 degrees.
        self.assertLess(ff.sampling.corner_normals(pts, tris, 180)[0][1][1], 0.99)
        # Per-vertex normals, as callers gave them before corner normals, still interpolate.
        up = [(0.0, 1.0, 0.0)] * len(pts)
        for s in ff.sampling.sample_triangles(pts, tris, 0.25, up):
            self.assertEqual(s[3:], (0.0, 1.0, 0.0))

    def test_flattened_rows_are_the_same_numbers_and_errors_on_the_fast_path(self):
        # Session's _flat takes lists of tuples of floats (sample_triangles' samples), flat
        # lists and buffers of doubles without its loop over the numbers; an iterator of the
        # same rows still takes the loop: both give the same doubles, or the same error.
        from array import array
        from footfall_client.session import _flat

        def flat(rows, width=6):
            try:
                return ("ok", _flat(rows, width, "samples").tobytes())
            except ff.FootfallError as e:
                return (e.status_name, e.message)

        rows = [(0.1 * i, -0.0, 1e300, float(i), 2, -3) for i in range(50)]
        doubles = array("d", [v for row in rows for v in row])
        cases = [rows, tuple(rows), [list(row) for row in rows], list(doubles), [], [1, 2],
                 [(1.0, 2.0, 3.0)], [(1.0,) * 6, (1.0,) * 5], [(1.0,) * 5 + ("2.5",)],
                 [(1.0,) * 5 + (True,)], [(1.0,) * 5 + (10 ** 400,)], [(1.0,) * 5 + (None,)],
                 [(1.0,) * 6, 7.0, 8.0, 9.0, 1.0, 2.0, 3.0], list(doubles)[:-1]]
        for rows_ in cases:
            self.assertEqual(flat(rows_), flat(iter(rows_)), rows_[:2])
        self.assertEqual(flat(doubles), flat(iter(rows)))
        self.assertEqual(flat(memoryview(doubles).cast("B").cast("d", (50, 6))), flat(rows))
        self.assertEqual(flat(doubles[:-1]), flat(iter(doubles[:-1])))
        self.assertEqual(flat(b"\x00" * 48), flat(iter(b"\x00" * 48)))
        self.assertEqual(flat(rows, 3)[0], "invalid_argument")

    def test_flat_samples_are_the_tuples_doubles(self):
        # sample_triangles_flat (what both plugins send) holds sample_triangles' doubles in
        # their order, bit for bit, with every kind of normal, and raises its errors.
        from array import array
        for name, pts, tris, separations in sampling_meshes():
            corners = ff.sampling.corner_normals(pts, tris, pure=True)
            some_none = [None if t % 3 == 0 else c for t, c in enumerate(corners)]
            vertex = [(math.sin(i), math.cos(i), 0.5) for i in range(len(pts))]
            for separation in separations:
                for normals, kwargs in (("face", {}), ("corner", {"corner_normals": corners}),
                                        ("some None", {"corner_normals": some_none}),
                                        ("vertex", {"vertex_normals": vertex})):
                    label = "%s at %g, %s normals" % (name, separation, normals)
                    tuples = ff.sampling.sample_triangles(pts, tris, separation, pure=True,
                                                          **kwargs)
                    self.assertGreater(len(tuples), 3, label)
                    for pure in (True, False):  # (the loops here without numpy: the same)
                        flat = ff.sampling.sample_triangles_flat(pts, tris, separation,
                                                                 pure=pure, **kwargs)
                        self.assertIs(type(flat), array, label)
                        self.assertEqual(flat.typecode, "d", label)
                        self.assertEqual(len(flat), 6 * len(tuples), label)
                        self.assertEqual(packed_rows(sample_rows(flat)), packed_rows(tuples),
                                         label)
        pts = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 0.0, 1.0)]
        for args, message in (((pts, [(0, 1, 2)], 0), "separation must be > 0"),
                              ((pts, [(0, 1, 2)], 1e-4), "would make more than 2000000"),
                              (([(float("nan"), 0, 0)] + pts[1:], [(0, 1, 2)], 0.1),
                               "triangle 0")):
            with self.assertRaises(ValueError) as e:
                ff.sampling.sample_triangles_flat(*args, pure=True)
            self.assertIn(message, str(e.exception))
        with self.assertRaises(ValueError) as e:
            ff.sampling.sample_triangles_flat(pts, [(0, 1, 2)], 0.1, max_samples=5)
        self.assertIn("would make more than 5 samples", str(e.exception))
        with self.assertRaises(IndexError):
            ff.sampling.sample_triangles_flat(pts, [(0, 1, 7)], 0.1, pure=True)
        # The pure-Python loops keep their limit, for the flat samples too.
        self.assertEqual(ff.sampling.flat_sample_limit(pure=True), ff.sampling.MAX_SAMPLES)
        if not ff.sampling.USE_NUMPY:
            self.assertEqual(ff.sampling.flat_sample_limit(), ff.sampling.MAX_SAMPLES)

    def test_point_files_of_flat_samples_are_the_tuples_text(self):
        # write_point_file writes the same bytes for the flat array as for the tuples (repr of
        # each double, spaced, a line a sample), and refuses a part of a sample before writing.
        from array import array
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "t.pts")
            for name, tuples, flat in tuples_and_flat_samples():
                texts = []
                for samples in (tuples, flat, memoryview(flat)):
                    ff.sampling.write_point_file(path, samples, "from " + name)
                    with open(path, "rb") as f:
                        texts.append(f.read())
                self.assertEqual(texts[0].count(b"\n"), len(tuples) + 1, name)
                self.assertEqual(texts[1], texts[0], name)
                self.assertEqual(texts[2], texts[0], name)
            # Doubles whose repr takes every digit, an exponent, or a sign of zero.
            odd = [(0.1 + 0.2, -0.0, 1e-300, 1.7976931348623157e308, 5e-324, -2.5),
                   (1.0 / 3.0, 2.0 ** 60, -1e22, 123456789.123456789, 0.0, 1.0)]
            ff.sampling.write_point_file(path, odd)
            with open(path, "rb") as f:
                want = f.read()
            ff.sampling.write_point_file(path, array("d", [v for row in odd for v in row]))
            with open(path, "rb") as f:
                self.assertEqual(f.read(), want)
            never = os.path.join(tmp, "never.pts")
            with self.assertRaises(ValueError) as e:
                ff.sampling.write_point_file(never, array("d", [0.0] * 13))
            self.assertIn("13 numbers", str(e.exception))
            self.assertFalse(os.path.exists(never))

    def test_flat_samples_load_the_tuples_terrain(self):
        # Session.load_samples takes the flat array as it is (no copy, no loop over the
        # numbers): the same terrain as the tuples' (count, bounds, every snap and normal).
        from footfall_client.session import _flat
        for name, tuples, flat in tuples_and_flat_samples():
            self.assertIs(_flat(flat, 6, "samples"), flat)
            probe = [(x + 0.013, y + 0.2, z - 0.021) for x, y, z, *_ in tuples[::3]]
            probe += [(x, y, z) for x, y, z, *_ in tuples[1::4]]
            with ff.Session.embedded() as s:
                a, b = s.load_samples(tuples, "tuples"), s.load_samples(flat, "flat")
                self.assertEqual(s.info(b), s.info(a), name)
                self.assertEqual(s.info(b)[0], len(flat) // 6, name)
                self.assertEqual(s.snap(b, probe), s.snap(a, probe), name)
                self.assertEqual(s.normal(b, probe), s.normal(a, probe), name)
            flat.append(0.0)  # (lent to the call, not kept: the array still grows)
        with ff.Session.embedded() as s:
            from array import array
            with self.assertRaises(ff.FootfallError) as e:
                s.load_samples(array("d", [0.0] * 7))
            self.assertIn("7 numbers is not a multiple of 6", e.exception.message)

    def test_separation_must_be_positive(self):
        with self.assertRaises(ValueError):
            ff.sampling.sample_triangles([(0, 0, 0)] * 3, [(0, 1, 2)], 0)

    def test_sampling_refuses_vertices_that_are_not_finite(self):
        # (An infinite vertex, which a huge object scale makes in Blender's floats, or a
        # separation too small for a double to count its samples, raised OverflowError, and a
        # NaN vertex "cannot convert float NaN to integer": Terrain Setup showed a traceback.)
        inf, nan = float("inf"), float("nan")
        for pts, separation, message in (
                ([(inf, 0, 0), (1, 0, 0), (0, 0, 1)], 0.1, "triangle 0"),
                ([(nan, 0, 0), (1, 0, 0), (0, 0, 1)], 0.1, "triangle 0"),
                # (A NaN in a later corner: max() kept the first edge's finite length.)
                ([(0, 0, 0), (1, 0, 0), (0, nan, 1)], 0.1, "triangle 0"),
                ([(0, 0, 0), (1, 0, 0), (0, 0, 1), (nan, 0, 0)], 0.1, "triangle 1"),
                ([(1e308, 0, 0), (-1e308, 0, 0), (0, 0, 1)], 0.1, "triangle 0"),
                ([(1e300, 0, 0), (-1e300, 0, 0), (0, 0, 1e300)], 0.1, "triangle 0"),
                ([(1e100, 0, 0), (-1e100, 0, 0), (0, 0, 1e100)], 0.1, "would make more than"),
                ([(0, 0, 0), (1, 0, 0), (0, 0, 1)], 1e-300, "would make more than")):
            with self.assertRaises(ValueError, msg=str(pts)) as e:
                ff.sampling.sample_triangles(pts, [(0, 1, 2), (0, 1, len(pts) - 1)], separation)
            self.assertIn(message, str(e.exception))

    def test_sampling_refuses_more_samples_than_a_dcc_can_hold_before_sampling(self):
        # A 10 m square at 1 mm: about 100 million samples (tens of GB in pure Python).
        pts = [(0, 0, 0), (10, 0, 0), (0, 0, 10), (10, 0, 10)]
        with self.assertRaises(ValueError) as e:
            ff.sampling.sample_triangles(pts, [(0, 2, 1), (1, 2, 3)], 0.001)
        self.assertIn("would make more than 2000000 samples", str(e.exception))
        self.assertEqual(len(ff.sampling.sample_triangles(pts, [(0, 2, 1)], 20.0)), 3)
        # Shared lattice points are counted once: a 700 x 700 vertex grid at its own spacing
        # (490,000 samples) passes (it was refused at any separation).
        n = 700
        grid = [(float(i), 0.0, float(j)) for j in range(n) for i in range(n)]
        tris = []
        for j in range(n - 1):
            for i in range(n - 1):
                a = j * n + i
                tris += [(a, a + n, a + 1), (a + 1, a + n, a + n + 1)]
        ff.sampling.check_sample_count(grid, tris, 1.5)

    def test_character_checked_as_the_generator_reads_it(self):
        with open(os.path.join(CHARACTERS, "biped.json")) as f:
            data = json.load(f)
        s = ff.Session.embedded()
        try:
            s.check_character(data)
            for key, value, message in (("version", 2, "version"),
                                        ("frames_per_step", 1, "'frames_per_step' = 1"),
                                        ("colour", "red", "unknown field 'colour'")):
                bad = dict(data)
                bad[key] = value
                with self.assertRaises(ff.FootfallError) as e:
                    s.check_character(bad, "bad.json")
                self.assertIn(message, e.exception.message)
                self.assertTrue(e.exception.message.startswith("bad.json"), e.exception.message)
        finally:
            s.close()
        self.assertEqual(ff.character.display_name(data, "file"), data["name"])
        self.assertEqual(ff.character.display_name({}, "file"), "file")
        with self.assertRaises(ff.FootfallError):
            ff.character.display_name({"name": 5}, "file")

    def test_rest_positions_about_the_feet_centroid(self):
        # The walk keeps the body over the feet's centroid: setup places feet as it does.
        data = {"feet": [{"name": "A", "rest": [0.4, 0, 0.2]}, {"name": "B", "rest": [0.2, 0, 0.2]}]}
        got = ff.character.rest_positions(data)
        self.assertEqual([n for n, _ in got], ["A", "B"])
        for (_, p), want in zip(got, ((0.1, 0.0, 0.0), (-0.1, 0.0, 0.0))):
            for a, b in zip(p, want):
                self.assertAlmostEqual(a, b)

    def test_files_that_are_not_regular_are_refused_before_opening(self):
        # Opening a FIFO waits for a writer: the DCC hung.
        folder = tempfile.mkdtemp()
        try:
            fifo = os.path.join(folder, "character.json")
            os.mkfifo(fifo)
            with self.assertRaises(ff.FootfallError) as e:
                ff.character.load(fifo)
            self.assertIn("not a regular file", e.exception.message)
        finally:
            os.unlink(fifo)
            os.rmdir(folder)

    def test_frame_quaternion(self):
        from footfall_client.rotation import quat_from_frame, quat_to_euler_xyz
        self.assertEqual(quat_from_frame((0, 1, 0), (0, 0, 1)), (0.0, 0.0, 0.0, 1.0))
        for up, forward in (((1, 1, 0), (0, 0, 1)), ((0, 0.2, 1), (1, 0, 0)),
                            ((0, -1, 0), (0, 0, 1)), ((0, 1, 0), (0, 1, 0))):
            x, y, z, w = quat_from_frame(up, forward)

            def rotate(v):  # q v q*
                t = (2 * (y * v[2] - z * v[1]), 2 * (z * v[0] - x * v[2]), 2 * (x * v[1] - y * v[0]))
                return (v[0] + w * t[0] + y * t[2] - z * t[1], v[1] + w * t[1] + z * t[0] - x * t[2],
                        v[2] + w * t[2] + x * t[1] - y * t[0])
            n = math.sqrt(sum(c * c for c in up))
            for a, b in zip(rotate((0, 1, 0)), (c / n for c in up)):
                self.assertAlmostEqual(a, b)
            z_axis = rotate((0, 0, 1))
            self.assertAlmostEqual(sum(z_axis[i] * up[i] for i in range(3)), 0)
            self.assertEqual(len(quat_to_euler_xyz((x, y, z, w))), 3)

    def test_character_pairs_and_overrides(self):
        data = ff.character.parse(json.dumps({
            "feet": [{"name": "L", "rest": [0.1, 0, 0]}, {"name": "R", "rest": [-0.1, 0, 0]},
                     {"name": "T", "rest": [0, 0, -0.5]}],
            "step_length": 0.6, "frames_per_step": 12}))
        self.assertEqual(ff.character.pairs(data), [("L_R", ["L", "R"]), ("T", ["T"])])
        data["pairs"] = [["L"], ["R", "T"]]
        self.assertEqual(ff.character.pairs(data), [("L", ["L"]), ("R_T", ["R", "T"])])
        out = ff.character.with_overrides(data, step_length=0.8, step_height=0, frames_per_step=9,
                                          foot_length=0.25)
        self.assertEqual((out["step_length"], out["frames_per_step"], out["foot_length"]),
                         (0.8, 9, 0.25))
        self.assertNotIn("step_height", out)
        self.assertNotIn("foot_length", ff.character.with_overrides(data, foot_length=0))
        self.assertEqual(data["step_length"], 0.6)
        with self.assertRaises(ff.FootfallError) as e:
            ff.character.parse('{"feet": [{"name": "L"}]}', "bad.json")
        self.assertIn("bad.json: feet[0]", e.exception.message)

    def test_a_character_scaled_here_walks_as_the_generator_scales_it(self):
        # The Maya plugin scales a character file in metres to the scene's unit itself: the same
        # lengths as a request's "scale" (ScaleCharacter), so the same walk, byte for byte.
        data = ff.character.load(os.path.join(CHARACTERS, "quadruped.json"))
        del data["max_rise"]  # the generator's default, scaled too
        self.assertEqual(ff.character.scaled(data, 100.0)["max_rise"], 35.0)
        self.assertEqual(ff.character.unit_scale("m", "cm"), 100.0)
        self.assertEqual(ff.character.unit_scale("centimeter", "m"), 0.01)
        self.assertAlmostEqual(ff.character.unit_scale("ft", "in"), 12.0, places=12)
        with self.assertRaises(ValueError) as e:
            ff.character.unit_scale("furlong", "m")
        self.assertIn("unknown linear unit 'furlong'", str(e.exception))
        for bad in (0, -1.0, float("nan"), float("inf"), "2", True):
            with self.assertRaises(ValueError):
                ff.character.scaled(data, bad)
        flat = [(x * 4.0, 0.0, z * 4.0, 0.0, 1.0, 0.0) for z in range(201) for x in range(201)]
        with ff.Session.embedded() as s:
            t = s.load_samples(flat, "flat-cm")
            request = {"start": [400.0, 0.0, 400.0], "steps": 6}
            here = s.generate(t, dict(request, character=ff.character.scaled(data, 100.0)))
            there = s.generate(t, dict(request, character=data, scale=100.0))
            # Unscaled, the metres character stops at once, and a note says which scale fits.
            with self.assertRaises(ff.WalkStopped) as e:
                s.generate(t, dict(request, character=data))
        self.assertEqual(json.dumps(here), json.dumps(there))
        self.assertTrue(any(n.endswith("(request: 'scale'; 100 from metres to centimetres)")
                            for n in e.exception.notes), e.exception.notes)
        self.assertEqual(here["stopped"], "")
        body = [tr for tr in here["tracks"] if tr["kind"] == "body"][0]
        self.assertAlmostEqual(body["keys"][0]["position"][1], data["body_height"] * 100.0,
                               places=6)
        self.assertNotIn("max_rise", data)  # the character given is left as it was

    def test_character_files_the_plugins_cannot_rig_are_refused_before_anything_is_made(self):
        # Each of these escaped from Blender's Character Setup as a Python traceback
        # (KeyError, ZeroDivisionError, IndexError), after half the rig was made.
        feet = '[{"name": "L", "rest": [0.1, 0, 0]}, {"name": "R", "rest": [-0.1, 0, 0]}]'
        cases = {'{"feet": %s, "pairs": [["L", "NOPE"]]}' % feet: "pairs[0]: no foot named 'NOPE'",
                 '{"feet": %s, "pairs": [[]]}' % feet: "pairs[0]: expected a non-empty list",
                 '{"feet": [{"name": "L", "rest": [0.1, 0]}]}': "feet[0]: expected",
                 '{"feet": [{"name": "", "rest": [0.1, 0, 0]}]}': "feet[0]: expected",
                 '{"feet": [{"name": "L", "rest": [0, 0, 0]}, {"name": "L", "rest": [1, 0, 0]}]}':
                     "feet[1]: the name 'L' is used twice",
                 # An integer beyond a double (OverflowError escaped).
                 '{"feet": [{"name": "L", "rest": [1%s, 0, 0]}]}' % ("0" * 400): "feet[0]: expected"}
        for text, message in cases.items():
            with self.assertRaises(ff.FootfallError, msg=text) as e:
                ff.character.parse(text, "c.json")
            self.assertIn("c.json: " + message, e.exception.message)

    def test_json_files_with_a_byte_order_mark_or_deep_nesting(self):
        # A character or walk file starting with a UTF-8 byte order mark (as some Windows
        # editors save) was refused, while `footfall generate` reads it; JSON nested some
        # hundreds of levels deep raised RecursionError through the plugin.
        cli = os.environ.get("FOOTFALL_CLI") or os.path.join(REPO, "build", "client", "cli",
                                                               "footfall")
        folder = tempfile.mkdtemp()
        try:
            plain = os.path.join(CHARACTERS, "biped.json")
            with open(plain, "rb") as f:
                text = f.read()
            marked = os.path.join(folder, "biped_bom.json")
            with open(marked, "wb") as f:
                f.write(b"\xef\xbb\xbf" + text)
            self.assertEqual(ff.character.load(marked), ff.character.load(plain))
            walks = []
            for character in (plain, marked):  # the command line reads both alike
                out = os.path.join(folder, "walk.json")
                subprocess.run([cli, "generate", "--terrain", HILLS, "--character", character,
                                "--steps", "2", "--out", out], check=True, capture_output=True)
                with open(out, "rb") as f:
                    walks.append(f.read())
            self.assertEqual(walks[0], walks[1])
            walk_file = os.path.join(folder, "walk_bom.json")
            with open(walk_file, "wb") as f:
                f.write(b"\xef\xbb\xbf" + walks[0])
            walk = ff.character.read_json(walk_file, "walk file")
            self.assertEqual(walk, json.loads(walks[0]))
            ff.character.check_walk(walk, walk_file)
            # Deep nesting: closed, never closed, inside a character, inside a walk file.
            depth = ff.character.MAX_JSON_DEPTH
            for text in ("[" * 100000 + "]" * 100000, "[" * 100000, "{\"a\":" * 5000 + "1" +
                         "}" * 5000, "[" * (depth + 1) + "]" * (depth + 1)):
                with self.assertRaises(ff.FootfallError) as e:
                    ff.character.parse_json(text, "deep.json")
                self.assertEqual(e.exception.status_name, "parse_error")
                self.assertEqual(e.exception.message,
                                 "deep.json: nested deeper than %d levels" % depth)
            nested = [[]]
            for _ in range(depth - 2):
                nested = [nested]
            self.assertEqual(ff.character.parse_json(json.dumps(nested)), nested)
            # Deep brackets before a string of escaped quotes never closed: refused as JSON in
            # one pass (removing its strings took minutes for 200 KB; this is 2 MB).
            for end in ("", "\\"):
                text = "[" * 70 + '"' + '\\"' * 1000000 + end + "]" * 70
                with self.assertRaises(ff.FootfallError) as e:
                    ff.character.parse_json(text, "quotes.json")
                self.assertEqual(e.exception.status_name, "parse_error")
                self.assertRegex(e.exception.message,
                                 r"^quotes\.json: (Unterminated string|Invalid \\escape)")
            # Brackets inside strings are text, not nesting.
            self.assertEqual(ff.character.parse_json('{"name": "%s"}' % ("[" * 1000)),
                             {"name": "[" * 1000})
            deep_character = os.path.join(folder, "deep.json")
            with open(deep_character, "w") as f:
                f.write('{"feet": ' + "[" * 5000 + "]" * 5000 + "}")
            with self.assertRaises(ff.FootfallError) as e:
                ff.character.load(deep_character)
            self.assertIn("nested deeper than %d levels" % depth, e.exception.message)
            with open(walk_file, "w") as f:
                f.write('{"tracks": ' + "[" * 5000 + "]" * 5000 + "}")
            with self.assertRaises(ff.FootfallError) as e:
                ff.character.read_json(walk_file, "walk file")
            self.assertEqual(e.exception.message, "%s: nested deeper than %d levels"
                             % (walk_file, depth))
        finally:
            for name in os.listdir(folder):
                os.unlink(os.path.join(folder, name))
            os.rmdir(folder)

    def test_walk_files_are_checked_before_anything_is_keyed(self):
        good = {"tracks": [{"name": "L", "kind": "foot", "keys": [
            {"frame": 1, "position": [0, 0, 0]}]}, {"name": "body", "kind": "body", "keys": [
                {"frame": 1, "position": [0, 1, 0], "rotation": [0, 0, 0, 1]}]}]}
        ff.character.check_walk(good, "w.json")
        bad = [({"tracks": [1]}, "tracks[0]: expected"),
               ({"tracks": [{"name": "L", "keys": [{"frame": 1, "position": [0, 0]}]}]},
                "tracks[0].keys[0]: expected \"position\""),
               ({"tracks": [{"name": "L", "keys": [{"frame": float("nan"),
                                                    "position": [0, 0, 0]}]}]},
                "tracks[0].keys[0]: expected a finite \"frame\""),
               ({"tracks": [{"name": "b", "kind": "body", "keys": [
                   {"frame": 1, "position": [0, 0, 0], "rotation": [0, 0, 1]}]}]},
                "expected \"rotation\""),
               ([], "expected footfall walk JSON")]
        # A foot's rotations (foot rotations asked for) are on all its keys or on none.
        turned = {"frame": 1, "position": [0, 0, 0], "rotation": [0, 0, 0, 1]}
        ff.character.check_walk({"tracks": [{"name": "L", "keys": [turned, dict(turned,
                                                                                 frame=2)]}]})
        bad += [({"tracks": [{"name": "L", "keys": [{"frame": 1, "position": [0, 0, 0]},
                                                    dict(turned, frame=2)]}]},
                 "tracks[0].keys[1]: expected a rotation on every key of a foot track or on none "
                 "(the first key has none)"),
                ({"tracks": [{"name": "L", "keys": [turned, {"frame": 2,
                                                             "position": [0, 0, 0]}]}]},
                 "(the first key has one)")]
        # Integers beyond a double, as JSON allows them (math.isfinite raised OverflowError,
        # which Blender's Import showed as a traceback).
        huge = 10 ** 400
        bad += [({"tracks": [{"name": "L", "keys": [{"frame": huge, "position": [0, 0, 0]}]}]},
                 "tracks[0].keys[0]: expected a finite \"frame\""),
                ({"tracks": [{"name": "L", "keys": [{"frame": 1, "position": [0, -huge, 0]}]}]},
                 "tracks[0].keys[0]: expected \"position\""),
                (ff.character.parse_json('{"tracks": [{"name": "b", "kind": "body", "keys": '
                                         '[{"frame": 1, "position": [0, 0, 0], "rotation": '
                                         '[0, 0, 0, 1%s]}]}]}' % ("0" * 400)),
                 "expected \"rotation\"")]
        # As footfall's reader takes them (the viewer refused these; Import keyed them, the
        # second of two keys at one frame over the first): a later format version, two keys
        # at one frame, a bad phase or frame rate.
        foot = good["tracks"][0]
        key = foot["keys"][0]
        bad += [(dict(good, version=2), "w.json: version: expected 1"),
                (dict(good, format="footfall-scene"), "format: expected \"footfall-walk\""),
                (dict(good, fps=0), "fps: expected a positive number"),
                (dict(good, fps="24"), "fps: expected a positive number"),
                ({"tracks": [dict(foot, keys=[key, dict(key)])]},
                 "tracks[0].keys[1].frame: frames must increase along a track (1 after 1)"),
                ({"tracks": [dict(foot, keys=[dict(key, frame=2), key])]},
                 "frames must increase along a track (1 after 2)"),
                ({"tracks": [dict(foot, keys=[dict(key, phase="lift")])]},
                 "tracks[0].keys[0].phase: expected \"start\", \"mid\" or \"end\"")]
        ff.character.check_walk(dict(good, format="footfall-walk", version=1, fps=30.0))
        ff.character.check_walk({"tracks": [dict(foot, keys=[dict(key, phase="end")])]})
        for walk, message in bad:
            with self.assertRaises(ValueError, msg=str(walk)) as e:
                ff.character.check_walk(walk, "w.json")
            self.assertIn(message, str(e.exception))


class RpcTest(unittest.TestCase):
    def setUp(self):
        self.server = ff.LocalServer().start()
        self.s = ff.Session.rpc("127.0.0.1", self.server.port, timeout=5.0)

    def tearDown(self):
        self.s.close()
        self.server.stop()

    def test_rpc_answers_equal_embedded(self):
        t = self.s.load_file(HILLS)
        with ff.Session.embedded() as local:
            lt = local.load_file(HILLS)
            self.assertEqual(self.s.info(t), local.info(lt))
            points = [(x * 0.7 + 1, 5.0, x * 0.9 + 2) for x in range(40)]
            self.assertEqual(self.s.snap(t, points), local.snap(lt, points))
            self.assertEqual(self.s.normal(t, points), local.normal(lt, points))
            steps = [(p[0], 0.5, p[2], 1.0, 0.0, 0.0) for p in points]
            self.assertEqual(self.s.next(t, steps, 0.3), local.next(lt, steps, 0.3))

    def test_threads_sharing_a_session_take_turns_and_close_waits(self):
        # Closing a session while another thread was in a call on it freed it under that call
        # (a segfault of the interpreter); failures' messages crossed between the threads.
        import threading
        for _ in range(10):
            s = ff.Session.rpc("127.0.0.1", self.server.port, timeout=5.0)
            t = s.load_file(HILLS)
            errors = []

            def query():
                try:
                    for _ in range(2000):
                        s.snap(t, [(10, 5, 10)] * 64)
                except ff.FootfallError as e:
                    errors.append(e.message)
            worker = threading.Thread(target=query)
            worker.start()
            time.sleep(0.02)
            s.close()
            worker.join()
            self.assertEqual(errors, ["the session is closed"])
        t = self.s.load_file(HILLS)
        crossed = []

        def fail(call, expected):
            for _ in range(300):
                try:
                    call()
                except ff.FootfallError as e:
                    if expected not in e.message:
                        crossed.append(e.message)
        threads = [threading.Thread(target=fail, args=(lambda: self.s.info(t + 1000),
                                                       "no terrain with handle")),
                   threading.Thread(target=fail, args=(
                       lambda: self.s.load_file("/no/such/terrain.pts"), "terrain.pts"))]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        self.assertEqual(crossed, [])

    def test_a_terrain_name_given_as_bytes_is_sent_as_its_bytes(self):
        # str(b"ridge") named the terrain "b'ridge'" in footfalld's log.
        samples = [(0.0, 0.0, 0.0, 0.0, 1.0, 0.0), (1.0, 0.0, 0.0, 0.0, 1.0, 0.0)]
        for name, logged in ((b"ridge", "'ridge'"), (bytearray(b"caf\xc3\xa9"), "'caf\u00e9'"),
                             ("stairs", "'stairs'")):
            self.s.load_samples(samples, name=name)
            deadline = time.time() + 5
            while logged not in self._log() and time.time() < deadline:
                time.sleep(0.05)
            self.assertIn("loaded terrain", self._log())
            self.assertIn(logged, self._log())
            self.assertNotIn("b'", self._log())
        with self.assertRaises(ff.FootfallError):
            self.s.load_samples(samples, name=b"a\0b")

    def _log(self):
        with open(self.server.log_path or os.path.join(self.server._dir, "footfalld.log"),
                  encoding="utf-8", errors="replace") as f:
            return f.read()

    def test_a_local_server_on_ipv6_loopback(self):
        # LocalServer(host="::1") passed --listen ::1:0, which footfalld refuses: it never
        # started.
        for host in ("::1", "[::1]"):
            with ff.LocalServer(host=host).start() as server:
                with ff.Session.rpc("::1", server.port, timeout=5.0) as s:
                    self.assertIs(s.ping(), True)
                    t = s.load_file(HILLS)
                    self.assertTrue(s.snap(t, [(10, 5, 10)])[0].ok)

    def test_server_killed_then_restarted(self):
        t = self.s.load_samples(flat_grid(), "flat")
        self.assertTrue(self.s.ping())
        self.assertTrue(self.s.snap(t, [(1, 1, 1)])[0].ok)
        self.server.kill()
        for _ in range(3):  # repeated calls on a dead server keep failing cleanly
            with self.assertRaises(ff.FootfallError) as e:
                self.s.snap(t, [(1, 1, 1)])
            self.assertEqual(e.exception.status_name, "unavailable")
            self.assertIn(str(self.server.port), e.exception.message)
        self.assertFalse(self.s.ping())
        self.server.restart()
        self.assertTrue(self.s.ping())
        # The same session works again; its terrain is uploaded again by the client library.
        hold = self.s.snap(t, [(1.1, 1, 2.4)])[0]
        self.assertTrue(hold.ok, hold)
        self.assertEqual(hold.point, (1.0, 0.0, 2.5))

    def test_connection_finds_a_server_restarted_on_its_port(self):
        # The plugins' Connection: after a restart its first command used to fail once ("no
        # footfalld answers"), as the session noticed the broken connection only then.
        c = ff.Connection()
        try:
            self.assertIs(c.get("127.0.0.1", self.server.port, start_local=False).ping(), True)
            self.server.kill()
            self.server.restart()
            s = c.get("127.0.0.1", self.server.port, start_local=False)
            self.assertTrue(s.ping())
            self.assertIsNone(c.local)  # no local server started instead
        finally:
            c.shutdown()

    def test_no_server_is_a_clear_error(self):
        port = self.server.port
        self.server.stop()
        with ff.Session.rpc("127.0.0.1", port, timeout=2.0) as s:
            with self.assertRaises(ff.FootfallError) as e:
                s.load_samples(flat_grid(3), "flat")
            self.assertEqual(e.exception.status_name, "unavailable")
            self.assertFalse(s.ping())

    def test_bad_port_is_rejected(self):
        with self.assertRaises(ff.FootfallError):
            ff.Session.rpc("127.0.0.1", 70000)

    def test_hosts_and_ports_that_are_not_text_and_numbers_raise_footfall_errors(self):
        # (A host of 123 raised AttributeError; "127.0.0.1\0x" reached 127.0.0.1; a port of
        # True was port 1.)
        for host, port in ((123, self.server.port), (b"127.0.0.1", self.server.port),
                           ("127.0.0.1\0x", self.server.port), ("127.0.0.1", True)):
            with self.assertRaises(ff.FootfallError) as e:
                ff.Session.rpc(host, port)
            self.assertEqual(e.exception.status_name, "invalid_argument")
        with ff.Session.rpc("h\u00f4st\ud800.invalid", self.server.port, timeout=2.0) as s:
            self.assertFalse(s.ping())  # an unknown host, not an encoding error
        with ff.Session.rpc(None, self.server.port) as s:
            self.assertTrue(s.ping())  # None is 127.0.0.1
        # A port in the host was looked up as a host named "127.0.0.1:PORT".
        with self.assertRaises(ff.FootfallError) as e:
            ff.Session.rpc("127.0.0.1:%d" % self.server.port, self.server.port)
        self.assertIn("without a port (the port is given apart)", e.exception.message)


class LocalServerTest(unittest.TestCase):
    """LocalServer given a footfalld path that is wrong, as a plugin's preferences may name."""

    def test_wrong_executables_fail_quickly_and_leave_nothing_behind(self):
        # Each failed start left its temporary folder (port file, log) and an open log file.
        with tempfile.TemporaryDirectory() as folder:
            plain = os.path.join(folder, "plain.txt")
            with open(plain, "w") as f:
                f.write("not a program\n")
            silent = os.path.join(folder, "silent.sh")
            with open(silent, "w") as f:
                f.write("#!/bin/sh\nexec sleep 30\n")
            os.chmod(silent, 0o755)
            scratch = os.path.join(folder, "tmp")
            os.mkdir(scratch)
            saved = tempfile.tempdir
            tempfile.tempdir = scratch
            try:
                for exe in (folder, plain, "/bin/sleep", "/bin/true",
                            os.path.join(folder, "missing"), silent):
                    server = ff.LocalServer(executable=exe)
                    began = time.monotonic()
                    with self.assertRaises(ff.ServerError) as e:
                        server.start(timeout=1.0)
                    self.assertLess(time.monotonic() - began, 8.0, exe)
                    self.assertIn(exe, str(e.exception))  # which program failed
                    self.assertNotIn("\n", str(e.exception))  # one line, for a report
                    self.assertFalse(server.running(), exe)
                    self.assertEqual(os.listdir(scratch), [], exe)
            finally:
                tempfile.tempdir = saved


@contextlib.contextmanager
def environment(**values):
    """os.environ with `values` set for the block, as it was after."""
    saved = {name: os.environ.get(name) for name in values}
    os.environ.update(values)
    try:
        yield
    finally:
        for name, value in saved.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value


class LibraryLoadTest(unittest.TestCase):
    """Loading a libfootfall.so that cannot load: the message says why, in one line."""

    def test_wrong_environment_paths_are_errors(self):
        # FOOTFALL_LIB naming a missing file or a folder, or FOOTFALLD naming a file that is
        # not executable, passed over to a library or server found elsewhere, saying nothing
        # (and FOOTFALLD's file was made executable).
        with tempfile.TemporaryDirectory() as folder:
            for wrong, said in ((os.path.join(folder, "missing.so"), "not a file"),
                                (folder, "a directory")):
                with environment(FOOTFALL_LIB=wrong):
                    with self.assertRaises(ff.library.LibraryNotFound) as e:
                        ff.library.find_library()
                    self.assertIn("FOOTFALL_LIB names %s, which is %s" % (wrong, said),
                                  str(e.exception))
            plain = os.path.join(folder, "footfalld")
            with open(plain, "w") as f:
                f.write("#!/bin/sh\n")
            os.chmod(plain, 0o644)
            for wrong, said in ((plain, "not an executable file"), (folder, "a directory"),
                                (os.path.join(folder, "missing"), "not a file")):
                with environment(FOOTFALLD=wrong):
                    with self.assertRaises(ff.ServerError) as e:
                        ff.server.find_footfalld()
                    self.assertIn("FOOTFALLD names %s, which is %s" % (wrong, said),
                                  str(e.exception))
            self.assertEqual(os.stat(plain).st_mode & 0o777, 0o644)  # left as it was

    def test_a_missing_dependency_is_named(self):
        # A zip or install copied to a machine without footfall's runtime libraries said only
        # "cannot load .../libfootfall.so: libOpenMeshCore.so.9.0: cannot open shared object
        # file", as if the library itself were missing.
        with tempfile.TemporaryDirectory() as folder:
            for name, text in (("dep.c", "int footfall_dep(void) { return 1; }\n"),
                               ("lib.c", "int footfall_dep(void);\n"
                                         "int ffc_abi_version(void) { return footfall_dep(); }\n")):
                with open(os.path.join(folder, name), "w") as f:
                    f.write(text)
            cc = os.environ.get("CC", "cc")
            subprocess.run([cc, "-shared", "-fPIC", "-o", os.path.join(folder, "libffdep.so"),
                            os.path.join(folder, "dep.c")], check=True)
            lib = os.path.join(folder, "libfootfall.so")
            subprocess.run([cc, "-shared", "-fPIC", "-o", lib, os.path.join(folder, "lib.c"),
                            "-L" + folder, "-lffdep"], check=True)
            os.unlink(os.path.join(folder, "libffdep.so"))
            with self.assertRaises(ff.library.LibraryNotFound) as e:
                ff.library.Library(lib)
            message = str(e.exception)
            self.assertIn("it needs libffdep.so, which this machine does not have", message)
            self.assertIn("apt-get install libopenmesh1 libtirpc3", message)
            self.assertNotIn("\n", message)
            # A file that is no library at all is said as such, with no dependency named.
            with open(lib, "w") as f:
                f.write("not a library\n")
            with self.assertRaises(ff.library.LibraryNotFound) as e:
                ff.library.Library(lib)
            self.assertIn("cannot load " + lib, str(e.exception))
            self.assertNotIn("it needs", str(e.exception))


class ConnectionTest(unittest.TestCase):
    """Connection, as the plugins keep it between commands, against real footfalld servers."""

    def setUp(self):
        self.server = ff.LocalServer().start()
        gone = ff.LocalServer().start()  # a port where nothing answers
        gone.stop()
        self.dead_port = gone.port
        self.c = ff.Connection()

    def tearDown(self):
        self.c.shutdown()
        self.server.stop()

    def test_a_port_held_by_another_program_is_said_to_be_maybe_not_footfalld(self):
        # An HTTP server's answer reads as a record a gigabyte long: the call waits its timeout.
        import socket
        import threading
        listener = socket.socket()
        listener.bind(("127.0.0.1", 0))
        listener.listen(4)
        port = listener.getsockname()[1]
        accepted = []

        def answer():
            try:
                while True:
                    conn, _ = listener.accept()
                    accepted.append(conn)
                    conn.recv(4096)
                    conn.sendall(b"HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\n\r\n")
            except OSError:
                pass  # the listener closed: the test is over
        thread = threading.Thread(target=answer, daemon=True)
        thread.start()
        try:
            with self.assertRaises(ff.FootfallError) as e:
                self.c.get("127.0.0.1", port, start_local=False, timeout=0.5)
        finally:
            listener.close()
            for conn in accepted:
                conn.close()
        self.assertGreater(len(accepted), 0)
        self.assertIn("footfalld at 127.0.0.1:%d does not answer within 0.5 s: it is there, but "
                      "busy or hung, or the port is another program's" % port,
                      e.exception.message)

    def test_changed_preferences_leave_the_private_server(self):
        # Once a local footfalld was started, every later call went to it, whatever server the
        # preferences named from then on.
        c = self.c
        c.get("127.0.0.1", self.dead_port, start_local=True)
        first = c.local
        self.assertTrue(first is not None and first.running())
        s = c.get("127.0.0.1", self.server.port, start_local=True)
        self.assertEqual(s.description, "rpc 127.0.0.1:%d" % self.server.port)
        self.assertIsNone(c.local)
        self.assertFalse(first.running())  # stopped, not left behind
        # Local servers no longer allowed: the configured server (none) is asked, and the
        # private one is not used.
        c.get("127.0.0.1", self.dead_port, start_local=True)
        second = c.local
        with self.assertRaises(ff.FootfallError) as e:
            c.get("127.0.0.1", self.dead_port, start_local=False)
        self.assertEqual(e.exception.status_name, "unavailable")
        self.assertIn("no footfalld answers at 127.0.0.1:%d" % self.dead_port,
                      e.exception.message)
        self.assertFalse(second.running())
        # Another footfalld to start: a server of that one.
        c.get("127.0.0.1", self.dead_port, start_local=True)
        third = c.local
        c.get("127.0.0.1", self.dead_port, start_local=True, footfalld=ff.find_footfalld())
        self.assertFalse(third.running())
        self.assertTrue(c.local.running())
        self.assertEqual(c.local.executable, ff.find_footfalld())
        # The same preferences keep the same server.
        fourth = c.local
        self.assertIs(c.get("127.0.0.1", self.dead_port, start_local=True,
                            footfalld=ff.find_footfalld()), c.session)
        self.assertIs(c.local, fourth)

    def test_a_hung_local_server_is_stopped_within_the_calls_timeout(self):
        # The connection's own footfalld, hung (SIGSTOP): get() gave it a fixed 5 s to end on
        # SIGTERM before killing it, whatever the timeout asked (8 s for timeout=1).
        c = self.c
        c.get("127.0.0.1", self.dead_port, start_local=True, timeout=1.0)
        hung = c.local
        os.kill(hung.process.pid, signal.SIGSTOP)
        waits = []
        real_stop = ff.LocalServer.stop
        ff.LocalServer.stop = lambda server, timeout=5.0: (waits.append(timeout),
                                                           real_stop(server, timeout))[1]
        try:
            self.assertTrue(c.get("127.0.0.1", self.dead_port, start_local=True,
                                  timeout=1.0).ping())
        finally:
            ff.LocalServer.stop = real_stop
        self.assertEqual(waits, [1.0])
        self.assertFalse(hung.running())  # killed, not left stopped
        self.assertIsNot(c.local, hung)

    def test_a_hung_server_is_reported_as_such_after_one_timeout(self):
        # A stopped footfalld was pinged twice (twice the timeout) and reported as missing: "no
        # footfalld answers ...: start one there".
        os.kill(self.server.process.pid, signal.SIGSTOP)
        pings = []
        real_ping = ff.Session.ping
        ff.Session.ping = lambda session: pings.append(1) or real_ping(session)
        try:
            with self.assertRaises(ff.FootfallError) as e:
                self.c.get("127.0.0.1", self.server.port, start_local=False, timeout=0.5)
        finally:
            ff.Session.ping = real_ping
            os.kill(self.server.process.pid, signal.SIGCONT)
        self.assertEqual(len(pings), 1)
        self.assertIn("footfalld at 127.0.0.1:%d does not answer within 0.5 s: it is there, but "
                      "busy or hung" % self.server.port, e.exception.message)
        self.assertEqual(e.exception.status_name, "unavailable")
        # Awake again, it answers the next command.
        self.assertTrue(self.c.get("127.0.0.1", self.server.port, start_local=False,
                                   timeout=0.5).ping())

    def test_the_timeout_bounds_the_wait_for_a_local_footfalld(self):
        # The wait for a local footfalld to listen was always 10 s, whatever the timeout the
        # plugin's preferences gave: one that started but never listened held the DCC 10 s.
        with tempfile.TemporaryDirectory() as folder:
            stand_in = os.path.join(folder, "never_listens.sh")
            with open(stand_in, "w") as f:
                f.write("#!/bin/sh\nexec sleep 60\n")
            os.chmod(stand_in, 0o755)
            began = time.monotonic()
            with self.assertRaises(ff.FootfallError) as e:
                self.c.get("127.0.0.1", self.dead_port, start_local=True, footfalld=stand_in,
                           timeout=1.0)
            self.assertLess(time.monotonic() - began, 3.0)
            self.assertEqual(e.exception.status_name, "unavailable")
            self.assertIn("%s did not start listening within 1 s" % stand_in, e.exception.message)
            self.assertIsNone(self.c.local)

    def test_a_terrain_is_replaced_once_its_successor_is_loaded(self):
        # Loading a terrain again under the same name unloaded the old one first: a new upload
        # that failed left no terrain at all.
        c = self.c
        s = c.get("127.0.0.1", self.server.port, start_local=False)
        old = c.load_samples("ground", flat_grid())
        with self.assertRaises(ff.FootfallError) as e:
            c.load_file("ground", os.path.join(tempfile.gettempdir(), "no-such-terrain.pts"))
        self.assertEqual(e.exception.status_name, "io_error")
        self.assertEqual(c.terrain("ground"), old)
        self.assertEqual(s.info(old)[0], 21 * 21)
        self.assertTrue(s.snap(c.terrain("ground"), [(1.0, 1.0, 1.0)])[0].ok)
        # Replaced: the new one loaded, then the old one unloaded (the server keeps one).
        ids = [old]
        for height in range(1, 4):
            ids.append(c.load_samples("ground", flat_grid(height=float(height))))
            self.assertEqual(c.terrain("ground"), ids[-1])
            self.assertEqual(s.info(ids[-1])[0], 21 * 21)
            for gone in ids[:-1]:
                with self.assertRaises(ff.FootfallError) as e:
                    s.info(gone)
                self.assertEqual(e.exception.status_name, "unknown_terrain")


class BusyServer:
    """A stand-in for a footfalld busy building others' terrains: it answers the RPC NULL
    procedure and FF_ASK_AGAIN, and every other call FF_UNAVAILABLE ("footfalld is busy"), as
    footfalld answers a load or an upload when its queue is full. Counts the calls it gets."""

    PROG, NULL, ASK_AGAIN, UNAVAILABLE = 0x2F00F007, 0, 16, 8

    def __init__(self):
        import socket
        import threading
        self.listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self.listener.bind(("127.0.0.1", 0))
        self.listener.listen(16)
        self.port = self.listener.getsockname()[1]
        self.calls = []  # procedure numbers, in order
        self._stop = False
        self._thread = threading.Thread(target=self._serve, daemon=True)
        self._thread.start()

    def _serve(self):
        import select
        import struct
        conns, buffers = [], {}
        while not self._stop:
            ready, _, _ = select.select([self.listener] + conns, [], [], 0.05)
            for sock in ready:
                if sock is self.listener:
                    conn, _ = sock.accept()
                    conns.append(conn)
                    buffers[conn] = b""
                    continue
                data = sock.recv(65536)
                if not data:
                    conns.remove(sock)
                    sock.close()
                    continue
                buffers[sock] += data
                while len(buffers[sock]) >= 4:
                    length = struct.unpack(">I", buffers[sock][:4])[0] & 0x7FFFFFFF
                    if len(buffers[sock]) < 4 + length:
                        break
                    record, buffers[sock] = buffers[sock][4:4 + length], buffers[sock][4 + length:]
                    xid, _, _, _, _, proc = struct.unpack(">6I", record[:24])
                    self.calls.append(proc)
                    # REPLY, MSG_ACCEPTED, AUTH_NONE verifier, SUCCESS
                    body = struct.pack(">6I", xid, 1, 0, 0, 0, 0)
                    if proc == self.ASK_AGAIN:
                        body += struct.pack(">2I", 0, 0)  # FF_OK, empty message
                    elif proc != self.NULL:
                        # Every reply but FF_NULL's starts with its status; a message follows in
                        # those the library decodes here (status, [upload or terrain], message).
                        text = b"footfalld is busy: try again"
                        pad = b"\0" * (-len(text) % 4)
                        body += struct.pack(">2I", self.UNAVAILABLE, 0)
                        body += struct.pack(">I", len(text)) + text + pad
                    sock.sendall(struct.pack(">I", 0x80000000 | len(body)) + body)
        for conn in conns:
            conn.close()

    def stop(self):
        self._stop = True
        self._thread.join()
        self.listener.close()


class BusyServerTest(unittest.TestCase):
    def setUp(self):
        self.busy = BusyServer()

    def tearDown(self):
        self.busy.stop()

    def test_a_busy_server_answers_a_ping(self):
        with ff.Session.rpc("127.0.0.1", self.busy.port, timeout=5.0) as s:
            self.assertTrue(s.ping())
        # The ping asks with the NULL procedure: it loads nothing on the server.
        self.assertIn(BusyServer.NULL, self.busy.calls)
        self.assertNotIn(2, self.busy.calls)  # FF_UPLOAD_BEGIN

    def test_connection_uses_a_busy_shared_server_rather_than_starting_its_own(self):
        c = ff.Connection()
        try:
            s = c.get("127.0.0.1", self.busy.port, start_local=True)
            self.assertIsNone(c.local)  # no private footfalld started
            self.assertIn(str(self.busy.port), s.description)
        finally:
            c.shutdown()


class RotationTest(unittest.TestCase):
    """Rotations as Maya's XYZ and ZXY Euler angles (the Maya plugin keys bodies in ZXY)."""

    @staticmethod
    def _matrix_of_euler(e, order="xyz"):
        a, b, c = (math.radians(v) for v in e)
        rx = [[1, 0, 0], [0, math.cos(a), -math.sin(a)], [0, math.sin(a), math.cos(a)]]
        ry = [[math.cos(b), 0, math.sin(b)], [0, 1, 0], [-math.sin(b), 0, math.cos(b)]]
        rz = [[math.cos(c), -math.sin(c), 0], [math.sin(c), math.cos(c), 0], [0, 0, 1]]

        def mul(p, q):
            return [[sum(p[i][k] * q[k][j] for k in range(3)) for j in range(3)]
                    for i in range(3)]
        # Maya's rotate order names the axes in the order they turn: ZXY is Z first, then X,
        # then Y (R = Ry * Rx * Rz).
        by_axis = {"x": rx, "y": ry, "z": rz}
        m = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
        for axis in order:
            m = mul(by_axis[axis], m)
        return m

    @staticmethod
    def _matrix_of_quat(q):
        n = math.sqrt(sum(c * c for c in q))
        x, y, z, w = (c / n for c in q)
        return [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]

    def test_euler_angles_rebuild_the_rotation(self):
        # The plugin's old formulas composed R = Rx * Ry * Rz: off by up to 0.28 for a body
        # turned 40 degrees and pitched 20.
        rng = __import__("random").Random(5)
        quats = [(0.0, math.sin(math.radians(20)), 0.0, math.cos(math.radians(20))),
                 (0.17, 0.33, 0.05, 0.93), (0.0, 0.7071068, 0.0, 0.7071068)]
        quats += [tuple(rng.uniform(-1, 1) for _ in range(4)) for _ in range(200)]
        for q in quats:
            e = ff.rotation.quat_to_euler_xyz(q)
            got, want = self._matrix_of_euler(e), self._matrix_of_quat(q)
            for i in range(3):
                for j in range(3):
                    self.assertAlmostEqual(got[i][j], want[i][j], places=9, msg=str(q))

    def _assert_same_matrix(self, got, want, msg):
        for i in range(3):
            for j in range(3):
                self.assertAlmostEqual(got[i][j], want[i][j], places=9, msg=msg)

    def test_zxy_angles_rebuild_the_rotation(self):
        rng = __import__("random").Random(9)
        quats = [(0.0, math.sin(math.radians(45)), 0.0, math.cos(math.radians(45))),  # yaw 90
                 (0.17, 0.33, 0.05, 0.93)]
        quats += [tuple(rng.uniform(-1, 1) for _ in range(4)) for _ in range(200)]
        for q in quats:
            e = ff.rotation.quat_to_euler_zxy(q)
            self.assertTrue(-90 <= e[0] <= 90, msg=str(e))
            self._assert_same_matrix(self._matrix_of_euler(e, "zxy"), self._matrix_of_quat(q),
                                     str(q))
        # Heading +X is yaw alone, far from gimbal lock.
        e = ff.rotation.quat_to_euler_zxy(quats[0])
        for got, want in zip(e, (0.0, 90.0, 0.0)):
            self.assertAlmostEqual(got, want, places=9)
        # Gimbal lock (pitched 90 degrees): all the turn about the vertical in Y, Z 0.
        for pitch in (90.0, -90.0):
            want = self._matrix_of_euler((pitch, 25.0, 40.0), "zxy")
            # The quaternion of that matrix (trace > 0 here).
            s = 2 * math.sqrt(1 + want[0][0] + want[1][1] + want[2][2])
            q = ((want[2][1] - want[1][2]) / s, (want[0][2] - want[2][0]) / s,
                 (want[1][0] - want[0][1]) / s, s / 4)
            e = ff.rotation.quat_to_euler_zxy(q)
            self.assertEqual((e[0], e[2]), (pitch, 0.0))
            self._assert_same_matrix(self._matrix_of_euler(e, "zxy"), want, str(pitch))

    def test_zxy_unwrap_takes_the_nearest_equivalent(self):
        e = ff.rotation.closest_euler_zxy((0.0, -170.0, 0.0), (0.0, 170.0, 0.0))
        self.assertAlmostEqual(e[1], 190.0)
        e = ff.rotation.closest_euler_zxy((80.0, 0.0, 0.0), (100.0, 180.0, 180.0))
        for got, want in zip(e, (100.0, 180.0, 180.0)):
            self.assertAlmostEqual(got, want)
        self._assert_same_matrix(self._matrix_of_euler(e, "zxy"),
                                 self._matrix_of_euler((80.0, 0.0, 0.0), "zxy"), str(e))

    def test_gimbal_lock_split_nearest_the_neighbour(self):
        # A Z-up body facing -Y is at lock in ZXY: its first keys were (90, 0, 0), the next
        # after a turn (60, 90, 90), and Maya's per-angle interpolation leaned the body up to 10
        # degrees between them. Every rotate order keeps the rotation at lock and nears the
        # neighbouring key.
        rng = __import__("random").Random(3)
        for order in ff.rotation.ROTATE_ORDERS:
            i, j, k = ("xyz".index(a) for a in order)
            for middle in (90.0, -90.0):
                for _ in range(50):
                    e = [0.0, 0.0, 0.0]
                    e[i], e[j], e[k] = rng.uniform(-300, 300), middle, rng.uniform(-300, 300)
                    previous = [0.0, 0.0, 0.0]
                    previous[i], previous[j], previous[k] = (rng.uniform(-300, 300), middle,
                                                             rng.uniform(-300, 300))
                    got = ff.rotation.closest_euler_in_order(e, previous, order)
                    self._assert_same_matrix(self._matrix_of_euler(got, order),
                                             self._matrix_of_euler(e, order), order)
                    d = abs(got[i] - previous[i]) + abs(got[k] - previous[k])
                    s = (1.0 if (j - i) % 3 == 1 else -1.0) * (1.0 if middle > 0 else -1.0)
                    for t in range(-360, 361, 15):
                        for wi in (-360, 0, 360):
                            for wk in (-360, 0, 360):
                                other = (abs(e[i] + t + wi - previous[i]) +
                                         abs(e[k] + s * t + wk - previous[k]))
                                self.assertLessEqual(d, other + 1e-9, msg=order)
        # The first keys at lock split their turn as the first key that is not.
        facing_minus_y = ff.rotation.quat_from_frame((0.0, 0.0, 1.0), (0.0, -1.0, 0.0))
        turned = ff.rotation.quat_from_frame((0.0, 0.0, 1.0), (0.5, -math.sqrt(0.75), 0.0))
        e = ff.rotation.continuous_eulers([facing_minus_y, facing_minus_y, turned], 2)
        self.assertAlmostEqual(abs(e[0][0]), 90.0)
        self.assertNotAlmostEqual(abs(e[2][0]), 90.0)
        for n in (0, 1):  # y and z as the turned key's: the turn is in x alone
            self.assertAlmostEqual(e[n][1], e[2][1], places=6)
            self.assertAlmostEqual(e[n][2], e[2][2], places=6)

    def test_keys_match_the_mel_export(self):
        cli = os.environ.get("FOOTFALL_CLI") or os.path.join(REPO, "build", "client", "cli",
                                                               "footfall")
        with tempfile.TemporaryDirectory() as tmp:
            json_out, mel_out = os.path.join(tmp, "w.json"), os.path.join(tmp, "w.mel")
            subprocess.run([cli, "generate", "--terrain", HILLS, "--character",
                            os.path.join(CHARACTERS, "quadruped.json"), "--start", "20,0,12",
                            "--path", "24,0,12 24,0,6 18,0,6", "--steps", "30",
                            "--out", json_out, "--out", mel_out],
                           check=True, stderr=subprocess.DEVNULL)
            with open(json_out) as f:
                walk = json.load(f)
            with open(mel_out) as f:
                mel = f.read()
        self.assertIn('setAttr ($footfall_node[0] + ".rotateOrder") 2;', mel)  # zxy
        keyed = {}
        for m in __import__("re").finditer(
                r"setKeyframe -t (\S+) -at rotate([XYZ]) -v (\S+) ", mel):
            keyed.setdefault(float(m.group(1)), {})[m.group(2)] = float(m.group(3))
        body = [t for t in walk["tracks"] if t["kind"] == "body"][0]
        self.assertGreater(len(body["keys"]), 20)
        eulers = ff.rotation.continuous_eulers([key["rotation"] for key in body["keys"]], "zxy")
        for key, euler in zip(body["keys"], eulers):
            want = keyed[float(key["frame"])]
            for axis, value in zip("XYZ", euler):
                self.assertAlmostEqual(value, want[axis], places=9)


class MayaKeyWalkTest(unittest.TestCase):
    """footfall_maya.key_walk against a stand-in for maya.cmds that records the calls (there is
    no Maya here): the body turns in rotate order ZXY and is keyed with the ZXY angles, as the
    MEL export keys it."""

    @staticmethod
    @contextlib.contextmanager
    def _footfall_maya(cmds):
        """footfall_maya imported with the module `cmds` standing in for maya.cmds; the modules
        and sys.path are as before afterwards."""
        maya = types.ModuleType("maya")
        maya.cmds = cmds
        if not hasattr(cmds, "keyframe"):
            cmds.keyframe = lambda *args, **kwargs: 0  # no node has keys yet
        if not hasattr(cmds, "upAxis"):
            cmds.upAxis = lambda *args, **kwargs: "y"  # Maya's default
        saved = {name: sys.modules.pop(name, None) for name in ("maya", "maya.cmds",
                                                                "footfall_maya")}
        sys.modules.update({"maya": maya, "maya.cmds": cmds})
        sys.path.insert(0, os.path.join(REPO, "plugins", "maya"))
        try:
            import footfall_maya
            yield footfall_maya
        finally:
            sys.path.pop(0)
            for name, module in saved.items():
                sys.modules.pop(name, None)
                if module is not None:
                    sys.modules[name] = module

    @staticmethod
    def _rig_cmds(attributes, calls):
        """A stand-in for maya.cmds enough for generate_walk on a rig: the key, cut and setAttr
        commands append (name, args, kwargs) to `calls`; setAttr and addAttr keep values in
        `attributes`, by attribute name; a rig attribute's connection is "<attribute>_handle";
        the scene's terrain is "scene-1"."""
        cmds = types.ModuleType("maya.cmds")
        cmds.currentUnit = lambda *args, **kwargs: "deg"
        for name in ("setKeyframe", "cutKey", "undoInfo", "warning", "confirmDialog"):
            setattr(cmds, name, lambda *args, _name=name, **kwargs:
                    calls.append((_name, args, kwargs)))

        def set_attr(plug, *values, **kwargs):
            calls.append(("setAttr", (plug,) + values, kwargs))
            attributes[plug.split(".")[1]] = values[0]

        def add_attr(node, longName, **kwargs):  # noqa: N803 (Maya's name)
            attributes.setdefault(longName, 0.0)
        cmds.setAttr, cmds.addAttr = set_attr, add_attr
        cmds.getAttr = lambda plug, **kwargs: attributes[plug.split(".")[1]]
        cmds.attributeQuery = lambda attr, node, exists: attr in attributes
        cmds.listConnections = lambda plug, **kwargs: [plug.split(".")[1] + "_handle"]
        cmds.fileInfo = lambda *args, **kwargs: ["scene-1"]
        cmds.xform = lambda *args, **kwargs: (
            [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1] if kwargs.get("m")
            else [0.0, 0.0, 0.0]) if kwargs.get("q") else calls.append(("xform", args, kwargs))
        return cmds

    @contextlib.contextmanager
    def _generating(self, cmds, session):
        """footfall_maya over `cmds`, its session `session` and its scene's terrain loaded."""
        with self._footfall_maya(cmds) as footfall_maya:
            footfall_maya._session = lambda: session
            footfall_maya._connection = types.SimpleNamespace(
                terrain=lambda name: 1, has_terrain=lambda name: name == "scene-1")
            yield footfall_maya

    def _key_walk(self, walk, feet, body, keyed_order=None, angle_unit="deg"):
        """The calls key_walk makes; with `keyed_order`, every node has rotation keys and that
        rotateOrder; `angle_unit`: the scene's ("deg" or "rad")."""
        calls = []
        cmds = types.ModuleType("maya.cmds")
        cmds.currentUnit = lambda *args, **kwargs: angle_unit
        for name in ("setAttr", "xform", "setKeyframe"):
            setattr(cmds, name, lambda *args, _name=name, **kwargs:
                    calls.append((_name, args, kwargs)))
        if keyed_order is not None:
            cmds.keyframe = lambda *args, **kwargs: 3
            cmds.getAttr = lambda plug, **kwargs: keyed_order
        with self._footfall_maya(cmds) as footfall_maya:
            footfall_maya.key_walk(walk, feet, body)
        return calls

    def _mesh_samples(self, points, det, separation, to_ui=lambda v: v):
        """footfall_maya._mesh_samples of one triangle at `points` (world, internal units:
        centimetres) under a transform of determinant `det`, in a scene whose UI unit is
        `to_ui` (MDistance.internalToUI)."""
        class Point:
            def __init__(self, x, y, z):
                self.x, self.y, self.z = x, y, z

        class Dag:
            def inclusiveMatrix(self):  # noqa: N802 (Maya's name)
                return types.SimpleNamespace(det3x3=lambda: det)

        class MFnMesh:
            def __init__(self, dag):
                pass

            def getPoints(self, space):  # noqa: N802
                return [Point(*p) for p in points]

            def getTriangles(self):  # noqa: N802
                return [1], [0, 1, 2]  # wound up in the mesh's own space

        om = types.ModuleType("maya.api.OpenMaya")
        om.MSelectionList = lambda: types.SimpleNamespace(add=lambda name: None,
                                                          getDagPath=lambda i: Dag())
        om.MFnMesh = MFnMesh
        om.MSpace = types.SimpleNamespace(kWorld=4)
        om.MDistance = types.SimpleNamespace(internalToUI=to_ui)
        api = types.ModuleType("maya.api")
        api.OpenMaya = om
        saved = {name: sys.modules.pop(name, None) for name in ("maya.api", "maya.api.OpenMaya")}
        sys.modules.update({"maya.api": api, "maya.api.OpenMaya": om})
        try:
            with self._footfall_maya(types.ModuleType("maya.cmds")) as footfall_maya:
                sys.modules["maya"].api = api
                return footfall_maya._mesh_samples("ground", separation)
        finally:
            for name, module in saved.items():
                sys.modules.pop(name, None)
                if module is not None:
                    sys.modules[name] = module

    def test_a_mirrored_mesh_keeps_its_normals_up(self):
        # A terrain mesh under a negative scale had its triangles wound the other way in world
        # space, so every sample's normal pointed down (Maya shows it the right way up).
        samples = sample_rows(self._mesh_samples([(0, 0, 0), (0, 0, 1), (-1, 0, 0)], -1.0,
                                                 0.25))  # mirrored
        self.assertGreater(len(samples), 3)
        for sample in samples:
            self.assertAlmostEqual(sample[4], 1.0, places=9)  # the normal's Y: up

    def test_character_setup_scales_the_character_to_the_scenes_unit(self):
        # Character files give metres and Maya's default scene is in centimetres: the shipped
        # biped stood 0.95 cm tall there. The rig now keeps the character scaled to the scene's
        # unit, and places its body, feet and targets so; a file in the scene's unit is not.
        checked = []
        session = types.SimpleNamespace(  # flat ground at y = 0
            check_character=lambda data, path: checked.append(data),
            snap=lambda terrain, points: [types.SimpleNamespace(
                ok=True, point=(p[0], 0.0, p[2]), normal=(0.0, 1.0, 0.0)) for p in points])
        biped = json.load(open(os.path.join(CHARACTERS, "biped.json")))
        for scene_unit, file_unit, scale in (("cm", "m", 100.0), ("in", "m", 1 / 0.0254),
                                             ("m", "m", 1.0), ("cm", "cm", 1.0),
                                             ("m", "mm", 0.001)):
            calls = []
            cmds = types.ModuleType("maya.cmds")
            # Every other command is recorded, and answers None.
            cmds.__getattr__ = lambda name: (
                lambda *args, _name=name, **kwargs: calls.append((_name, args, kwargs)))
            cmds.currentUnit = lambda unit=scene_unit, **kwargs: (
                unit if kwargs.get("linear") else "deg")
            cmds.upAxis = lambda *args, **kwargs: "y"
            cmds.fileInfo = lambda *args, **kwargs: ["scene-1"]
            cmds.group = lambda **kwargs: "biped_rig"
            cmds.spaceLocator = lambda name: [name]
            cmds.parent = lambda node, parent: [node]
            del checked[:]
            with self._generating(cmds, session) as footfall_maya:
                rig = footfall_maya.character_setup(os.path.join(CHARACTERS, "biped.json"),
                                                    character_unit=file_unit)
            what = (scene_unit, file_unit)
            self.assertEqual(rig, "biped_rig", what)
            placed = {args[0]: kwargs["t"] for name, args, kwargs in calls
                      if name == "xform" and "t" in kwargs}
            self.assertAlmostEqual(placed["biped_body"][1], 0.95 * scale, places=9, msg=what)
            rests = dict(footfall_maya.character.rest_positions(biped))
            for foot, rest in rests.items():
                for i in (0, 2):
                    self.assertAlmostEqual(abs(placed["biped_%s" % foot][i]),
                                           abs(rest[i]) * scale, places=9, msg=what)
                # Its target half a (scaled) step ahead of it.
                self.assertAlmostEqual(placed["biped_%s_target" % foot][2],
                                       placed["biped_%s" % foot][2] + 0.35 * scale, places=9,
                                       msg=what)
            kept = [args for name, args, kwargs in calls
                    if name == "setAttr" and args[0] == "biped_rig.footfallCharacter"]
            self.assertEqual(len(kept), 1, what)
            data = json.loads(kept[0][1])
            self.assertEqual(checked, [data])  # checked as it is kept
            self.assertAlmostEqual(data["step_length"], 0.7 * scale, places=9, msg=what)
            self.assertAlmostEqual(data["reach"], biped["reach"] * scale, places=9, msg=what)
            said = [kwargs.get("amg", "") for name, args, kwargs in calls
                    if name == "inViewMessage"]
            if scale == 1:
                self.assertEqual(said, [], what)
            else:
                self.assertEqual(said, ["footfall: biped scaled from %s to this scene's %s "
                                        "(x %g)" % (file_unit, scene_unit, scale)], what)

    def test_a_mesh_is_sampled_in_the_scenes_linear_unit(self):
        # MFnMesh gives points in centimetres (Maya's internal unit) whatever the scene's
        # unit, while xform places the character in the scene's: in a metre scene the terrain
        # was sent 100 times too large (and sampled at a separation taken as centimetres).
        cm = sample_rows(self._mesh_samples([(0, 0, 0), (0, 0, 200), (200, 0, 0)], 1.0, 50.0))
        m = sample_rows(self._mesh_samples([(0, 0, 0), (0, 0, 200), (200, 0, 0)], 1.0, 0.5,
                                           to_ui=lambda v: v / 100.0))
        self.assertEqual(len(m), len(cm))
        for a, b in zip(m, cm):
            for i in range(3):
                self.assertAlmostEqual(a[i], b[i] / 100.0, places=9)
        self.assertAlmostEqual(max(p[0] for p in m), 2.0, places=9)

    @staticmethod
    def _window_cmds(calls, fields):
        """A stand-in for maya.cmds enough for show(): the window's commands append (name,
        args, kwargs) to `calls`; its text fields with buttons go to `fields` by name (their
        keyword arguments, edited as Maya edits them, and their text queried)."""
        cmds = types.ModuleType("maya.cmds")

        def record(name):
            def call(*args, **kwargs):
                calls.append((name, args, kwargs))
                return "%s%d" % (name, len(calls))
            return call
        for name in ("window", "deleteUI", "columnLayout", "frameLayout", "textFieldGrp",
                     "intFieldGrp", "floatFieldGrp", "checkBoxGrp", "button", "text",
                     "setParent", "showWindow", "warning", "confirmDialog"):
            setattr(cmds, name, record(name))

        def text_field_button_grp(*args, **kwargs):
            if kwargs.get("q"):
                return fields[args[0]].get("text", "")
            if kwargs.get("e"):
                fields[args[0]].update(kwargs)
                return None
            name = "field%d" % len(fields)
            fields[name] = dict(kwargs)
            return name
        cmds.textFieldButtonGrp = text_field_button_grp
        menus = {}  # option menu -> its items' labels, the first chosen (Maya's default)

        def option_menu_grp(*args, **kwargs):
            if kwargs.get("q"):
                return menus[args[0]][0]
            name = "menu%d" % len(menus)
            menus[name] = []
            fields[name] = dict(kwargs, items=menus[name])
            return name
        cmds.optionMenuGrp = option_menu_grp
        cmds.menuItem = lambda label: menus[sorted(menus)[-1]].append(label)
        return cmds

    def test_the_windows_file_buttons_pick_files(self):
        # The "..." buttons of the Point file and Character file fields had no command: a
        # click opened no file dialog, and paths had to be typed.
        calls, fields, dialogs = [], {}, []
        cmds = self._window_cmds(calls, fields)
        cmds.fileDialog2 = lambda **kwargs: dialogs.append(kwargs) or list(self._chosen)
        with self._footfall_maya(cmds) as footfall_maya:
            footfall_maya.show()
            by_label = {f["label"]: f for f in fields.values()}
            self.assertEqual(sorted(by_label), ["Character file", "Character file unit",
                                                "Point file"])
            # Metres first: the shipped character files'.
            self.assertEqual(by_label["Character file unit"]["items"][:2], ["m", "cm"])
            del by_label["Character file unit"]
            for label, chosen in (("Point file", "/data/hills.obj"),
                                  ("Character file", "/data/biped.json")):
                field = by_label[label]
                self._chosen = [chosen]
                field["buttonCommand"]()
                self.assertEqual(field["text"], chosen)
                self.assertEqual(dialogs[-1]["fileMode"], 1)  # one existing file
                self._chosen = []  # cancelled: the field keeps its path
                field["buttonCommand"](False)
                self.assertEqual(field["text"], chosen)
            self.assertIn("*.obj", dialogs[0]["fileFilter"])
            self.assertIn("*.json", dialogs[2]["fileFilter"])
            # Generate Walk with a component selected: attributeQuery raised into Maya.
            cmds.ls = lambda **kwargs: ["pCube1.vtx[0]"]

            def attribute_query(*args, **kwargs):
                raise RuntimeError("Object pCube1.vtx[0] is invalid")
            cmds.attributeQuery = attribute_query
            warnings = []
            cmds.warning = warnings.append
            cmds.confirmDialog = lambda **kwargs: None
            generate = [kw["command"] for name, _, kw in calls
                        if name == "button" and kw.get("label") == "Generate Walk"]
            self.assertEqual(len(generate), 1)
            generate[0]()
            self.assertEqual(warnings, ["footfall: Object pCube1.vtx[0] is invalid"])

    def test_character_setup_takes_the_body_apart_from_the_handles(self):
        # With only the IK handles selected, the first became the body and foot L both (the
        # walk's keys overwrote each other on it); a body selected alone was ignored.
        calls, fields = [], {}
        cmds = self._window_cmds(calls, fields)
        with self._footfall_maya(cmds) as footfall_maya:
            footfall_maya.show()
            by_label = {f["label"]: f for f in fields.values()}
            by_label["Character file"]["text"] = os.path.join(CHARACTERS, "biped.json")
            made = []
            footfall_maya.character_setup = (
                lambda path, ik_handles=None, body=None, character_unit=None:
                made.append((ik_handles, body)) or self.assertEqual(character_unit, "m"))
            setup = [kw["command"] for name, _, kw in calls
                     if name == "button" and kw.get("label", "").startswith("Set Up")]
            self.assertEqual(len(setup), 1)
            handles = {"L": "ik_L", "R": "ik_R"}
            for selected, expected in ((["ik_L", "ik_R"], (handles, None)),
                                       (["hips"], (None, "hips")),
                                       (["hips", "ik_L", "ik_R"], (handles, "hips")),
                                       (["ik_R", "hips", "ik_L"], (handles, "hips")),
                                       ([], (None, None))):
                cmds.ls = lambda **kwargs: list(selected)
                setup[0]()
                self.assertEqual(made[-1], expected, selected)
            self.assertEqual([c for c in calls if c[0] == "warning"], [])

    def test_a_z_up_scene_is_refused_with_what_to_set(self):
        # In a Z-up scene the body was placed sideways (Y up) and Generate Walk stopped at once
        # with "ground leans 84.3 deg".
        calls = []
        cmds = types.ModuleType("maya.cmds")
        for name in ("warning", "confirmDialog", "xform", "spaceLocator", "group", "setAttr"):
            setattr(cmds, name, lambda *args, _name=name, **kwargs:
                    calls.append((_name, args, kwargs)))
        cmds.upAxis = lambda *args, **kwargs: "z"
        with self._footfall_maya(cmds) as footfall_maya:
            for run in (lambda: footfall_maya.terrain_setup(0.1),
                        lambda: footfall_maya.character_setup(
                            os.path.join(CHARACTERS, "biped.json")),
                        lambda: footfall_maya.generate_walk("rig1")):
                del calls[:]
                self.assertIsNone(run())
                self.assertEqual([c[0] for c in calls], ["warning", "confirmDialog"])
                self.assertIn("this scene is Z-up", calls[0][1][0])
                self.assertIn("Up axis to Y", calls[0][1][0])

    def test_import_of_tracks_without_keys_changes_nothing(self):
        # Tracks of the rig without keys (alone, or beside another's keyed track) cut the rig's
        # keys from the walk's first frame (frame 0 when no track had a key), and with no rig
        # made their locators, before anything was keyed.
        calls = []
        cmds = types.ModuleType("maya.cmds")
        for name in ("setAttr", "xform", "setKeyframe", "cutKey", "spaceLocator", "warning",
                     "confirmDialog"):
            setattr(cmds, name, lambda *args, _name=name, **kwargs:
                    calls.append((_name, args, kwargs)) or ["made"])
        with open(os.path.join(CHARACTERS, "biped.json")) as f:
            character_text = f.read()
        cmds.getAttr = lambda *args, **kwargs: character_text
        cmds.attributeQuery = lambda *args, **kwargs: True
        cmds.listConnections = lambda plug, **kwargs: [plug.split(".")[1] + "_target"]
        folder = tempfile.mkdtemp()
        try:
            with self._footfall_maya(cmds) as footfall_maya:
                for tracks in ([{"name": "L", "kind": "foot", "keys": []}],
                               [{"name": "L", "kind": "foot", "keys": []},
                                {"name": "body", "kind": "body", "keys": []},
                                {"name": "X1", "kind": "foot",
                                 "keys": [{"frame": 1, "position": [0, 0, 0]}]}],
                               # another character's walk: its body track alone matched, and
                               # the rig's feet were cut
                               [{"name": n, "kind": "foot",
                                 "keys": [{"frame": 1, "position": [0, 0, 0]}]}
                                for n in ("LF", "RF", "LH", "RH")] +
                               [{"name": "body", "kind": "body",
                                 "keys": [{"frame": 1, "position": [0, 1, 0],
                                           "rotation": [0, 0, 0, 1]}]}]):
                    path = os.path.join(folder, "walk.json")
                    with open(path, "w") as f:
                        json.dump({"tracks": tracks}, f)
                    for rig in ("biped_rig", None) if len(tracks) == 1 else ("biped_rig",):
                        del calls[:]
                        self.assertIsNone(footfall_maya.import_walk(path, rig))
                        made = [c[0] for c in calls if c[0] not in ("warning", "confirmDialog")]
                        self.assertEqual(made, [], (tracks, rig))
                        self.assertIn("warning", [c[0] for c in calls])
        finally:
            for name in os.listdir(folder):
                os.unlink(os.path.join(folder, name))
            os.rmdir(folder)

    def test_generate_walk_keeps_the_users_keys_after_both_walks(self):
        # Generate Walk cut every translate and rotate key from the start frame on (to frame
        # 1e9), the user's keys long after the walk with the previous walk's.
        with open(os.path.join(CHARACTERS, "biped.json")) as f:
            character_text = f.read()

        def walk_of(steps):  # 12 frames a step from frame 1, as the biped's file
            keys = [{"frame": 1 + 12 * i, "position": [0.0, 0.0, 0.7 * i]}
                    for i in range(steps + 1)]
            return json.dumps({"tracks": [{"name": "L", "kind": "foot", "keys": keys}]})

        class FakeSession:
            def generate_json(self, terrain, request):
                return 0, walk_of(request["steps"]), None

            def generate_json_with_notes(self, terrain, request):
                return self.generate_json(terrain, request) + ([],)

        def run(attributes, steps):
            calls = []
            with self._generating(self._rig_cmds(attributes, calls),
                                  FakeSession()) as footfall_maya:
                self.assertEqual(footfall_maya.generate_walk("biped_rig", steps, 1, chunk_steps=3),
                                 steps)
            return [c[2]["time"] for c in calls if c[0] == "cutKey"]

        attributes = {"footfallCharacter": character_text, "footfallFoot0": None,
                      "footfallWalkEnd": -1e9}  # a rig Character Setup made
        cuts = run(attributes, 8)  # no walk before: only the walk's own frames
        self.assertEqual(max(c[1] for c in cuts), 97)
        self.assertEqual(attributes["footfallWalkEnd"], 97)
        cuts = run(attributes, 4)  # shorter: the longer walk's keys go, not those after it
        self.assertEqual(cuts[0], (1, 97))
        self.assertEqual(max(c[1] for c in cuts), 97)
        self.assertEqual(attributes["footfallWalkEnd"], 49)
        del attributes["footfallWalkEnd"]  # a rig of an older version: its end is unknown
        self.assertEqual(run(attributes, 4)[0], (1, 1e9))

    def test_each_scene_has_its_own_terrain(self):
        # One terrain name served every scene: after File > New (or opening another file),
        # Character Setup and Generate Walk used the previous scene's terrain without a word,
        # and it stayed loaded.
        file_info = {}
        errors = []
        cmds = types.ModuleType("maya.cmds")

        def info(key, value=None, query=False):
            if query:
                return [file_info[key]] if key in file_info else []
            file_info[key] = value
        cmds.fileInfo = info
        cmds.warning = lambda message: errors.append(message)
        cmds.confirmDialog = lambda **kwargs: None
        cmds.inViewMessage = lambda **kwargs: None
        cmds.getAttr = lambda *args, **kwargs: "{}"
        loaded = {}

        class FakeConnection:
            def load_file(self, name, path, separation):
                loaded[name] = len(loaded) + 1
                return loaded[name]

            def terrain(self, name):
                return loaded[name]

            def has_terrain(self, name):
                return name in loaded

            def terrain_names(self):
                return list(loaded)

            def unload(self, name):
                loaded.pop(name, None)
        session = types.SimpleNamespace(info=lambda terrain: (100, None))
        with self._footfall_maya(cmds) as footfall_maya:
            footfall_maya._connection = FakeConnection()
            footfall_maya._session = lambda: session
            self.assertEqual(footfall_maya.terrain_setup(0.25, "hills.pts"), 100)
            first = file_info["footfallTerrain"]
            self.assertEqual(list(loaded), [first])
            self.assertEqual(footfall_maya.terrain_setup(0.25, "hills.pts"), 100)  # replaced
            self.assertEqual(list(loaded), [first])
            file_info.clear()  # File > New
            for call in (lambda: footfall_maya.generate_walk("biped_rig"),
                         lambda: footfall_maya.character_setup(
                             os.path.join(CHARACTERS, "biped.json"))):
                del errors[:]
                self.assertIsNone(call())
                self.assertEqual(errors, ["footfall: no terrain in this scene: run Terrain "
                                          "Setup first"])
            self.assertEqual(footfall_maya.terrain_setup(0.25, "hills.pts"), 100)
            self.assertNotEqual(file_info["footfallTerrain"], first)
            self.assertEqual(list(loaded), [file_info["footfallTerrain"]])  # the old one gone
            file_info["footfallTerrain"] = first  # a file of an unloaded terrain opened
            del errors[:]
            self.assertIsNone(footfall_maya.generate_walk("biped_rig"))
            self.assertIn("not loaded in this Maya session: run Terrain Setup again", errors[0])

    def test_import_is_one_undo_chunk(self):
        # Import set every key as an undo step of its own: one undo took back one key of a
        # walk of thousands (Generate Walk and Character Setup were one chunk each).
        calls = []
        cmds = types.ModuleType("maya.cmds")
        cmds.currentUnit = lambda *args, **kwargs: "deg"
        for name in ("setAttr", "addAttr", "xform", "setKeyframe", "cutKey", "undoInfo",
                     "warning", "confirmDialog"):
            setattr(cmds, name, lambda *args, _name=name, **kwargs:
                    calls.append((_name, args, kwargs)))
        cmds.spaceLocator = lambda name: calls.append(("spaceLocator", (), {})) or [name]
        with open(os.path.join(CHARACTERS, "biped.json")) as f:
            character_text = f.read()
        cmds.getAttr = lambda *args, **kwargs: character_text
        cmds.attributeQuery = lambda attr, node, exists: attr != "footfallWalkEnd"
        cmds.listConnections = lambda plug, **kwargs: [plug.split(".")[1] + "_target"]
        walk = {"tracks": [{"name": "L", "kind": "foot",
                            "keys": [{"frame": f, "position": [0, 0, 0.1 * f]}
                                     for f in (1, 2, 3)]},
                           {"name": "body", "kind": "body",
                            "keys": [{"frame": 1, "position": [0, 1, 0],
                                      "rotation": [0, 0, 0, 1]}]}]}
        folder = tempfile.mkdtemp()
        path = os.path.join(folder, "walk.json")
        try:
            with open(path, "w") as f:
                json.dump(walk, f)
            with self._footfall_maya(cmds) as footfall_maya:
                for rig in (None, "biped_rig"):
                    del calls[:]
                    self.assertEqual(footfall_maya.import_walk(path, rig), 4, rig)
                    names = [c[0] for c in calls]
                    self.assertEqual(calls[0], ("undoInfo", (), {
                        "openChunk": True, "chunkName": "footfall import walk"}), rig)
                    self.assertEqual(calls[-1], ("undoInfo", (), {"closeChunk": True}), rig)
                    self.assertEqual(names.count("undoInfo"), 2, rig)
                    self.assertIn("setKeyframe", names)
        finally:
            os.unlink(path)
            os.rmdir(folder)

    def test_the_unit_lists_are_the_command_lines(self):
        # The walk units were listed in four places (the library, this package, the Maya and
        # Blender menus); the menus now take UNIT_MENU, and this package's lists must name
        # what `footfall generate --unit` accepts, in its order.
        cli = os.environ.get("FOOTFALL_CLI") or os.path.join(REPO, "build", "client", "cli",
                                                               "footfall")
        run = subprocess.run([cli, "generate", "--terrain", HILLS, "--character",
                              os.path.join(CHARACTERS, "biped.json"), "--unit", "furlong",
                              "--out", os.path.join(tempfile.gettempdir(), "never.json")],
                             capture_output=True, text=True)
        self.assertNotEqual(run.returncode, 0)
        listed = re.search(r"--unit: expected (.*)", run.stderr)
        self.assertIsNotNone(listed, run.stderr)
        names = re.split(r", | or ", listed.group(1).strip())
        self.assertEqual(tuple(names), ff.character.WALK_UNITS)
        self.assertEqual(sorted(ff.character.UNIT_MENU), sorted(ff.character.WALK_UNITS))
        self.assertEqual(ff.character.UNIT_MENU[0], "m")
        for unit in ff.character.WALK_UNITS:
            self.assertIn(unit, ff.character.METRES_PER_UNIT)

    def test_the_unit_factors_are_the_command_lines(self):
        # The factors are written twice too (linear_units.cpp and METRES_PER_UNIT). A walk
        # made with --unit U says its lengths in U in its JSON and in metres in its glTF (the
        # foot nodes' extras): walk_in_unit(json, "m") must give the glTF's numbers.
        cli = os.environ.get("FOOTFALL_CLI") or os.path.join(REPO, "build", "client", "cli",
                                                               "footfall")
        folder = tempfile.mkdtemp()
        try:
            for unit in ff.character.WALK_UNITS:
                walk_path = os.path.join(folder, unit + ".json")
                gltf_path = os.path.join(folder, unit + ".gltf")
                run = subprocess.run([cli, "generate", "--terrain", HILLS, "--character",
                                      os.path.join(CHARACTERS, "biped.json"), "--steps", "1",
                                      "--unit", unit, "--out", walk_path, "--out", gltf_path],
                                     capture_output=True, text=True)
                self.assertEqual(run.returncode, 0, run.stderr)
                with open(walk_path) as f:
                    in_metres = ff.character.walk_in_unit(json.load(f), "m")
                with open(gltf_path) as f:
                    nodes = json.load(f)["nodes"]
                gltf_lengths = {(n["extras"]["track"], key): n["extras"][key]
                                for n in nodes if "extras" in n and "track" in n["extras"]
                                for key in ("foot_length", "foot_width") if key in n["extras"]}
                json_lengths = {(t["name"], key): t[key] for t in in_metres["tracks"]
                                for key in ("foot_length", "foot_width") if key in t}
                self.assertEqual(len(json_lengths), 4, unit)  # the biped's two feet
                self.assertEqual(sorted(gltf_lengths), sorted(json_lengths), unit)
                for name, length in json_lengths.items():
                    self.assertAlmostEqual(gltf_lengths[name] / length, 1.0, places=12,
                                           msg="%s %s" % (unit, name))
        finally:
            for name in os.listdir(folder):
                os.unlink(os.path.join(folder, name))
            os.rmdir(folder)

    def test_import_keys_a_walk_that_says_its_unit_in_the_scenes(self):
        # footfall generate --unit m writes "unit": "m": in Maya's default centimetre scene its
        # keys go in 100 times larger; a walk without a unit is keyed as it is.
        calls = []
        cmds = types.ModuleType("maya.cmds")
        cmds.currentUnit = lambda *args, **kwargs: "cm" if kwargs.get("linear") else "deg"
        for name in ("setAttr", "addAttr", "setKeyframe", "cutKey", "undoInfo", "warning",
                     "confirmDialog"):
            setattr(cmds, name, lambda *args, _name=name, **kwargs: None)
        cmds.xform = lambda *args, **kwargs: calls.append(kwargs.get("t"))
        cmds.spaceLocator = lambda name: [name]
        walk = {"format": "footfall-walk", "version": 1, "fps": 24,
                "tracks": [{"name": "L", "kind": "foot", "foot_length": 0.25, "foot_width": 0.1,
                            "keys": [{"frame": f, "position": [0.5, 0, 0.1 * f]}
                                     for f in (1, 2, 3)]}]}
        folder = tempfile.mkdtemp()
        path = os.path.join(folder, "walk.json")
        try:
            with self._footfall_maya(cmds) as footfall_maya:
                for unit, factor in ((None, 1.0), ("m", 100.0), ("cm", 1.0), ("in", 2.54)):
                    with open(path, "w") as f:
                        json.dump(dict(walk, unit=unit) if unit else walk, f)
                    del calls[:]
                    self.assertEqual(footfall_maya.import_walk(path), 3, unit)
                    keyed = [t for t in calls if t is not None]
                    self.assertEqual(len(keyed), 3, unit)
                    for f, t in zip((1, 2, 3), keyed):
                        for got, want in zip(t, (0.5 * factor, 0.0, 0.1 * f * factor)):
                            self.assertAlmostEqual(got, want, places=9, msg=unit)
                with open(path, "w") as f:
                    json.dump(dict(walk, unit="furlong"), f)
                warnings = []
                cmds.warning = warnings.append
                self.assertIsNone(footfall_maya.import_walk(path))
                self.assertEqual(len(warnings), 1)
                self.assertIn("unit: expected one of mm, cm, m, km, in, ft, yd, mi", warnings[0])
        finally:
            os.unlink(path)
            os.rmdir(folder)
        # walk_in_unit itself: the walk given is left as it was.
        in_m = dict(walk, unit="m")
        in_mm = ff.character.walk_in_unit(in_m, "mm")
        self.assertEqual(in_mm["unit"], "mm")
        self.assertAlmostEqual(in_mm["tracks"][0]["foot_length"], 250.0, places=9)
        self.assertAlmostEqual(in_mm["tracks"][0]["foot_width"], 100.0, places=9)
        self.assertEqual(in_m["tracks"][0]["keys"][0]["position"], [0.5, 0, 0.1])

    def test_rotations_of_any_length_are_turned_as_unit_quaternions(self):
        # The walk reader keeps rotations as written (non-zero); the viewer and exporters scale
        # them to unit length. Blender keyed [0, 2, 0, 2] as 49 degrees (its matrices take the
        # quaternion as unit), Maya divided by a norm that underflowed (1e-200: ZeroDivisionError)
        # or overflowed (1e200: the identity).
        import importlib.util
        spec = importlib.util.spec_from_file_location(
            "footfall_blender_axes", os.path.join(REPO, "plugins", "blender", "footfall_blender",
                                                  "axes.py"))
        axes = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(axes)
        raw = (0.17, 0.33, 0.05, 0.93)  # a turn of 40 degrees, pitched and rolled a little
        n = math.sqrt(sum(c * c for c in raw))
        unit = tuple(c / n for c in raw)
        want = axes.quat_from_ff(unit)
        self.assertAlmostEqual(sum(c * c for c in want), 1.0, places=15)
        want_zxy = ff.rotation.quat_to_euler_zxy(unit)
        want_xyz = ff.rotation.quat_to_euler_xyz(unit)
        for scale in (2.0, 100.0, 1e-200, 1e200, 1e-310):
            q = tuple(c * scale for c in raw)
            for got, expected in ((axes.quat_from_ff(q), want),
                                  (ff.rotation.quat_to_euler_zxy(q), want_zxy),
                                  (ff.rotation.quat_to_euler_xyz(q), want_xyz)):
                for a, b in zip(got, expected):
                    self.assertAlmostEqual(a, b, places=9, msg=(scale, got, expected))
        for bad in ((0, 0, 0, 0), (0, float("nan"), 0, 1), (0, float("inf"), 0, 1)):
            with self.assertRaises(ValueError):
                axes.quat_from_ff(bad)
            with self.assertRaises(ValueError):
                ff.rotation.quat_to_euler_zxy(bad)
        # A zero rotation is refused before anything is keyed, as the walk reader refuses it.
        with self.assertRaises(ValueError) as e:
            ff.character.check_walk({"tracks": [{"name": "b", "kind": "body", "keys": [
                {"frame": 1, "position": [0, 0, 0], "rotation": [0, 0, 0, 0]}]}]}, "w.json")
        self.assertIn("tracks[0].keys[0]: expected \"rotation\"", str(e.exception))

    def test_body_turns_in_rotate_order_zxy(self):
        # Tilted 4 degrees on a slope, turning 2 degrees a key through heading +X (yaw 90: gimbal
        # lock in XYZ, where the channels swung by tens of degrees a key).
        tilt = (math.sin(math.radians(2)), 0.0, 0.0, math.cos(math.radians(2)))

        def yawed(deg):
            h = math.radians(deg) / 2
            a, b = tilt, (0.0, math.sin(h), 0.0, math.cos(h))  # a * b
            return (a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1],
                    a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0],
                    a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3],
                    a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2])
        keys = [{"frame": 1 + i, "position": [0.0, 1.0, 0.1 * i], "rotation": yawed(70 + 2 * i)}
                for i in range(21)]
        walk = {"tracks": [{"name": "body", "kind": "body", "keys": keys},
                           {"name": "L", "kind": "foot",
                            "keys": [{"frame": 1, "position": [0.1, 0.0, 0.0]}]}]}
        calls = self._key_walk(walk, {"L": "footL"}, "hips")
        self.assertEqual([c for c in calls if c[0] == "setAttr"],
                         [("setAttr", ("hips.rotateOrder", 2), {})])
        rotations = [c[2]["ro"] for c in calls if c[0] == "xform" and "ro" in c[2]]
        self.assertLess(calls.index(("setAttr", ("hips.rotateOrder", 2), {})),
                        [i for i, c in enumerate(calls) if "ro" in c[2]][0])
        self.assertEqual(len(rotations), len(keys))
        previous = None
        self.assertFalse([c for c in calls if c[1][:1] == ("footL",) and "ro" in c[2]])
        for key, euler in zip(keys, rotations):
            # The angles rebuild the key's rotation in ZXY order, with no jump between keys.
            got = RotationTest._matrix_of_euler(euler, "zxy")
            want = RotationTest._matrix_of_quat(key["rotation"])
            for i in range(3):
                for j in range(3):
                    self.assertAlmostEqual(got[i][j], want[i][j], places=9)
            if previous is not None:
                for a, b in zip(euler, previous):
                    self.assertLess(abs(a - b), 3.0, msg="%s after %s" % (euler, previous))
            previous = euler

    def test_foot_rotations_turn_the_handles_in_rotate_order_zxy(self):
        # A walk generated with foot rotations: each handle whose every key has one is keyed
        # turned, in ZXY as the body (and as the MEL export's --foot-rotations); a handle
        # without them keeps its own rotation.
        def tilted(deg):
            h = math.radians(deg) / 2
            return (math.sin(h), 0.0, 0.0, math.cos(h))
        turned = [{"frame": 1 + i, "phase": "end", "position": [0.1, 0.0, 0.1 * i],
                   "normal": [0.0, 1.0, 0.0], "rotation": tilted(5 * i)} for i in range(4)]
        plain = [{"frame": 1 + i, "phase": "end", "position": [-0.1, 0.0, 0.1 * i],
                  "normal": [0.0, 1.0, 0.0]} for i in range(4)]
        walk = {"tracks": [{"name": "L", "kind": "foot", "keys": turned},
                           {"name": "R", "kind": "foot", "keys": plain}]}
        calls = self._key_walk(walk, {"L": "footL", "R": "footR"}, None)
        self.assertEqual([c for c in calls if c[0] == "setAttr"],
                         [("setAttr", ("footL.rotateOrder", 2), {})])
        rotations = [c for c in calls if c[0] == "xform" and "ro" in c[2]]
        self.assertEqual([c[1] for c in rotations], [("footL",)] * len(turned))
        self.assertEqual(len([c for c in calls if c[0] == "setKeyframe" and
                              c[2].get("attribute") == "rotate"]), len(turned))
        for key, call in zip(turned, rotations):
            got = RotationTest._matrix_of_euler(call[2]["ro"], "zxy")
            want = RotationTest._matrix_of_quat(key["rotation"])
            for i in range(3):
                for j in range(3):
                    self.assertAlmostEqual(got[i][j], want[i][j], places=9)

    def test_generate_walk_asks_for_foot_rotations(self):
        requests = []

        class FakeSession:
            def generate_json_with_notes(self, terrain, request):
                requests.append(dict(request))
                keys = [{"frame": 1, "phase": "end", "position": [0.0, 0.0, 0.0],
                         "normal": [0.0, 1.0, 0.0], "rotation": [0.0, 0.0, 0.0, 1.0]}]
                return 0, json.dumps({"tracks": [{"name": "L", "kind": "foot",
                                                  "keys": keys}]}), None, []
        with open(os.path.join(CHARACTERS, "biped.json")) as f:
            attributes = {"footfallCharacter": f.read(), "footfallFoot0": None}
        calls = []
        with self._generating(self._rig_cmds(attributes, calls), FakeSession()) as footfall_maya:
            rotate_cuts = []
            for turn in (False, True, False):
                del calls[:]
                footfall_maya.generate_walk("biped_rig", 2, 1, foot_rotations=turn)
                rotate_cuts.append([sorted(c[1][0]) for c in calls
                                    if c[0] == "cutKey" and c[2]["attribute"] == "rotate"])
                if turn:
                    # The handle is keyed turned (the walk's foot keys have rotations).
                    self.assertIn(("setAttr", ("footfallFoot0_handle.rotateOrder", 2), {}),
                                  calls)
        self.assertNotIn("foot_rotations", requests[0])
        self.assertIs(requests[2]["foot_rotations"], True)
        # Rotate keys are cut on the body, and on the handles only where this walk or the one
        # before turned them: an animator's own handle rotations stay otherwise.
        body = ["footfallBody_handle"]
        both = body + ["footfallFoot0_handle", "footfallFoot_R_handle"]
        self.assertEqual(rotate_cuts[0], [body, body])
        self.assertEqual(rotate_cuts[1], [both, both])
        self.assertEqual(rotate_cuts[2], [both, body])

    def test_rotations_are_keyed_in_the_scenes_angle_unit(self):
        # xform takes the scene's angle unit: in a scene set to radians, degrees turned the
        # body 57.3 times too far.
        keys = [{"frame": 1 + i, "position": [0.0, 1.0, 0.1 * i],
                 "rotation": (0.0, math.sin(0.1 * i), 0.0, math.cos(0.1 * i))}
                for i in range(1, 5)]
        walk = {"tracks": [{"name": "body", "kind": "body", "keys": keys}]}

        def rotations(unit):
            calls = self._key_walk(walk, {}, "hips", angle_unit=unit)
            return [c[2]["ro"] for c in calls if c[0] == "xform" and "ro" in c[2]]
        degrees, radians = rotations("deg"), rotations("rad")
        self.assertEqual(len(degrees), len(keys))
        for i, (d, r) in enumerate(zip(degrees, radians)):
            self.assertAlmostEqual(d[1], 0.2 * (i + 1) * 180 / math.pi, places=9)  # yaw, degrees
            for a, b in zip(d, r):
                self.assertAlmostEqual(math.radians(a), b, places=12)

    def test_set_up_nodes_are_turned_in_the_scenes_angle_unit(self):
        # Character Setup turned the rig and the central locators in degrees whatever the
        # scene's unit: in a scene set to radians, 57.3 times too far, and the walk's heading,
        # read back from the rig, went off by anything up to 180 degrees.
        def turned(unit):
            calls = []
            cmds = types.ModuleType("maya.cmds")
            cmds.currentUnit = lambda *args, **kwargs: unit
            cmds.xform = lambda *args, **kwargs: calls.append(kwargs["ro"])
            with self._footfall_maya(cmds) as footfall_maya:
                footfall_maya._orient("rig", (0.0, 1.0, 0.0), (1.0, 0.0, 0.0))  # facing +X
            return calls[0]
        degrees, radians = turned("deg"), turned("rad")
        self.assertAlmostEqual(degrees[1], 90.0, places=9)
        for d, r in zip(degrees, radians):
            self.assertAlmostEqual(math.radians(d), r, places=12)

    def test_a_body_with_rotation_keys_keeps_its_rotate_order(self):
        # Generate Walk set a picked body's rotateOrder to ZXY without converting its keys: a
        # pose the user keyed before the walk turned (Maya does not convert keys).
        keys = [{"frame": 1 + i, "position": [0.0, 1.0, 0.1 * i],
                 "rotation": ff.rotation.quat_from_frame(
                     (0.2, 1.0, 0.1 * i), (math.cos(0.3 * i), 0.0, math.sin(0.3 * i)))}
                for i in range(25)]
        walk = {"tracks": [{"name": "body", "kind": "body", "keys": keys}]}
        for order, name in enumerate(ff.rotation.ROTATE_ORDERS):
            calls = self._key_walk(walk, {}, "hips", keyed_order=order)
            self.assertEqual([c for c in calls if c[0] == "setAttr"], [], name)
            rotations = [c[2]["ro"] for c in calls if c[0] == "xform" and "ro" in c[2]]
            self.assertEqual(len(rotations), len(keys))
            previous = None
            for key, euler in zip(keys, rotations):
                got = RotationTest._matrix_of_euler(euler, name)
                want = RotationTest._matrix_of_quat(key["rotation"])
                for i in range(3):
                    for j in range(3):
                        self.assertAlmostEqual(got[i][j], want[i][j], places=9, msg=name)
                if previous is not None:  # unwrapped: no angle jumps by 180 or more
                    self.assertLess(max(abs(a - b) for a, b in zip(euler, previous)), 180.0,
                                    msg="%s: %s after %s" % (name, euler, previous))
                previous = euler

    def test_keys_have_linear_tangents(self):
        # As the MEL export: Maya's default tangent (auto or spline) overshoots between a foot's
        # start, mid and end keys, dipping it into the ground.
        keys = [{"frame": f, "position": [0.0, 1.0, 0.1 * f], "rotation": (0.0, 0.0, 0.0, 1.0)}
                for f in (1, 7, 13)]
        walk = {"tracks": [{"name": "body", "kind": "body", "keys": keys},
                           {"name": "L", "kind": "foot",
                            "keys": [{"frame": 1, "position": [0.1, 0.0, 0.0]},
                                     {"frame": 4, "position": [0.1, 0.2, 0.1]}]}]}
        calls = self._key_walk(walk, {"L": "footL"}, "hips")
        keyed = [c for c in calls if c[0] == "setKeyframe"]
        self.assertEqual(len(keyed), 3 * 2 + 2)
        for call in keyed:
            self.assertEqual(call[2].get("inTangentType"), "linear", msg=str(call))
            self.assertEqual(call[2].get("outTangentType"), "linear", msg=str(call))


class NotesTest(unittest.TestCase):
    """A walk's notes (what `footfall generate` prints as "note:" lines, which the walk JSON
    does not carry) through ffc_generate_with_notes, the Session and the Maya plugin: the
    plugins never showed them."""

    def setUp(self):
        self.s = ff.Session.embedded()
        self.t = self.s.load_samples(flat_grid(), "flat")  # 10 x 10 m, y = 0
        with open(os.path.join(CHARACTERS, "biped.json")) as f:
            self.biped = json.load(f)  # step_length 0.7, reach 1.2

    def tearDown(self):
        self.s.close()

    def request(self, **fields):
        request = {"character": self.biped, "start": [5.0, 0.0, 5.0],
                   "heading": [0.0, 0.0, 1.0], "steps": 2, "start_frame": 1}
        request.update(fields)
        return request

    # A start 20 m off the terrain's edge (it snaps to (5, 0, 0)), and a walk of 200 steps
    # that stops at the far edge.
    FAR = [5.0, 0.0, -20.0]

    def _c_generate(self, request, notes=True):
        """ffc_generate_with_notes itself: (status, walk text or None, notes text or None), the
        out pointers set to garbage first (the function must overwrite them)."""
        lib = self.s._lib.lib
        # Declared (an undeclared call would pass the session pointer as a C int: a crash).
        self.assertIsNotNone(lib.ffc_generate_with_notes.argtypes)
        walk, text = ctypes.c_void_p(1), ctypes.c_void_p(1)
        status = lib.ffc_generate_with_notes(self.s._h, self.t, json.dumps(request).encode(),
                                             ctypes.byref(walk),
                                             ctypes.byref(text) if notes else None)
        out = []
        for p in (walk, text) if notes else (walk,):
            out.append(None if not p.value else ctypes.string_at(p.value).decode("utf-8"))
            if p.value:
                lib.ffc_free_string(p.value)
        return (status,) + tuple(out) + ((None,) if not notes else ())

    def test_the_c_abi_gives_the_notes_with_the_walk(self):
        self.assertTrue(self.s._lib.has("ffc_generate_with_notes"))
        plain = self._c_generate(self.request())
        self.assertEqual(plain[0], 0)
        self.assertEqual(plain[2], "")  # no notes: an empty text, not NULL
        self.assertEqual(plain[1], self.s.generate_json(self.t, self.request())[1])
        far = self._c_generate(self.request(start=self.FAR))
        self.assertEqual(far[0], 0)
        self.assertEqual(far[1], self.s.generate_json(self.t, self.request(start=self.FAR))[1])
        self.assertTrue(far[2].endswith("\n") and far[2].count("\n") == 1, far[2])
        self.assertIn("snaps to the terrain's sample nearest it", far[2])
        self.assertIn("20 away", far[2])
        long_step = self._c_generate(self.request(character=dict(self.biped, step_length=5.0)))
        self.assertEqual(long_step[0], 0)
        self.assertIn("step_length 5 is longer than reach 1.2", long_step[2])
        both = self._c_generate(self.request(start=self.FAR,
                                             character=dict(self.biped, step_length=5.0)))
        lines = both[2].split("\n")
        self.assertEqual(len(lines), 3)  # two notes, each ending in a line break
        self.assertIn("snaps to the terrain", lines[0])  # in the command line's order
        self.assertIn("step_length", lines[1])
        # A walk that stops early: its keys, and its notes too.
        stopped = self._c_generate(self.request(start=self.FAR, steps=200))
        self.assertEqual(stopped[0], 1)  # no_foothold
        self.assertIn('"stopped"', stopped[1])
        self.assertIn("snaps to the terrain", stopped[2])
        # No notes wanted: a NULL notes pointer.
        self.assertEqual(self._c_generate(self.request(start=self.FAR), notes=False)[:2], far[:2])
        # A refused request: both out pointers NULL.
        self.assertEqual(self._c_generate(self.request(steps=-1))[1:], (None, None))
        self.assertEqual(self._c_generate({"steps": 2})[1:], (None, None))

    def test_the_session_passes_the_notes_on(self):
        status, walk, message, notes = self.s.generate_json_with_notes(
            self.t, self.request(start=self.FAR))
        self.assertEqual((status, message), (0, ""))
        self.assertEqual(len(notes), 1)
        self.assertIn("snaps to the terrain", notes[0])
        self.assertEqual(self.s.generate_json(self.t, self.request(start=self.FAR)),
                         (status, walk, message))
        self.assertEqual(self.s.generate_json_with_notes(self.t, self.request())[3], [])
        self.assertEqual(self.s.generate_json_with_notes(self.t, self.request(steps=-1))[3], [])
        self.s.generate(self.t, self.request(start=self.FAR))
        self.assertEqual(self.s.last_notes, notes)
        self.s.generate(self.t, self.request(start=self.FAR, steps=6), chunk_steps=2)
        self.assertEqual(self.s.last_notes, notes)
        self.s.generate(self.t, self.request())
        self.assertEqual(self.s.last_notes, [])
        for chunk in (0, 50):
            with self.assertRaises(ff.WalkStopped) as e:
                self.s.generate(self.t, self.request(start=self.FAR, steps=200), chunk_steps=chunk)
            self.assertEqual(e.exception.notes, notes)
            self.assertEqual(self.s.last_notes, notes)
            self.assertTrue(e.exception.walk["stopped"])

    def test_maya_shows_the_notes_and_the_stop_and_keeps_the_keys(self):
        # The Maya plugin through a stand-in for maya.cmds and API 2.0's MGlobal, over the real
        # library: the notes are warnings, the stop an error naming the keys kept.
        calls, warnings, errors = [], [], []
        attributes = {"footfallCharacter": json.dumps(self.biped), "footfallFoot0": None,
                      "footfallFoot1": None, "footfallWalkEnd": -1e9}
        cmds = types.ModuleType("maya.cmds")
        cmds.currentUnit = lambda *args, **kwargs: "deg"
        for name in ("setKeyframe", "cutKey", "undoInfo", "progressBar"):
            setattr(cmds, name, lambda *args, _name=name, **kwargs:
                    calls.append((_name, args, kwargs)))
        cmds.warning = errors.append
        cmds.confirmDialog = lambda **kwargs: None

        def set_attr(plug, *values, **kwargs):
            attributes[plug.split(".")[1]] = values[0]
        cmds.setAttr = set_attr
        cmds.addAttr = lambda node, longName, **kwargs: attributes.setdefault(longName, 0.0)
        cmds.getAttr = lambda plug, **kwargs: attributes[plug.split(".")[1]]
        cmds.attributeQuery = lambda attr, node, exists: attr in attributes
        cmds.listConnections = lambda plug, **kwargs: {
            "footfallFoot0": ["ik_L"], "footfallFoot1": ["ik_R"]}.get(plug.split(".")[1], [])
        cmds.fileInfo = lambda *args, **kwargs: ["scene-1"]
        place = {"start": self.FAR}

        def xform(*args, **kwargs):
            if kwargs.get("q"):
                return ([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1] if kwargs.get("m")
                        else list(place["start"]))
        cmds.xform = xform
        om = types.ModuleType("maya.api.OpenMaya")
        om.MGlobal = types.SimpleNamespace(displayWarning=warnings.append)
        api = types.ModuleType("maya.api")
        api.OpenMaya = om
        saved = {name: sys.modules.pop(name, None) for name in ("maya.api", "maya.api.OpenMaya")}
        sys.modules.update({"maya.api": api, "maya.api.OpenMaya": om})
        try:
            with self._maya(cmds, api) as footfall_maya:
                footfall_maya._session = lambda: self.s
                footfall_maya._connection = types.SimpleNamespace(
                    terrain=lambda name: self.t, has_terrain=lambda name: name == "scene-1")
                self.assertEqual(footfall_maya.generate_walk("biped_rig", 4, 1, chunk_steps=2), 4)
                self.assertEqual(errors, [])
                self.assertEqual(len(warnings), 1, warnings)
                self.assertTrue(warnings[0].startswith("footfall: note: the start "), warnings)
                self.assertIn("snaps to the terrain", warnings[0])
                # From the middle, 200 steps: it stops at the edge of the terrain.
                del warnings[:]
                place["start"] = [5.0, 0.0, 5.0]
                del calls[:]
                self.assertIsNone(footfall_maya.generate_walk("biped_rig", 200, 1,
                                                              chunk_steps=50))
                self.assertEqual(warnings, [])  # no note for a start on the terrain
                self.assertEqual(len(errors), 1, errors)
                with self.assertRaises(ff.WalkStopped) as e:
                    self.s.generate(self.t, self.request(start=[5.0, 0.0, 5.0], steps=200))
                kept = sum(len(t["keys"]) for t in e.exception.walk["tracks"]
                           if t["kind"] == "foot")
                self.assertIn(e.exception.message, errors[0])
                self.assertIn("(no_foothold)", errors[0])
                self.assertIn("; %d keys made before it were kept" % kept, errors[0])
                keyed = [c for c in calls if c[0] == "setKeyframe"]
                last = max(c[2]["time"] for c in keyed)
                self.assertEqual(last, max(k["frame"] for t in e.exception.walk["tracks"]
                                           for k in t["keys"]))
        finally:
            for name, module in saved.items():
                sys.modules.pop(name, None)
                if module is not None:
                    sys.modules[name] = module

    @contextlib.contextmanager
    def _maya(self, cmds, api):
        with MayaKeyWalkTest._footfall_maya(cmds) as footfall_maya:
            sys.modules["maya"].api = api
            yield footfall_maya


class GenerateTest(unittest.TestCase):
    """ffc_generate over RPC gives the same walk JSON as `footfall generate`."""

    @classmethod
    def setUpClass(cls):
        cls.cli = os.environ.get("FOOTFALL_CLI") or os.path.join(REPO, "build", "client", "cli",
                                                                   "footfall")
        cls.server = ff.LocalServer().start()
        cls.character = os.path.join(CHARACTERS, "biped.json")  # hills: 0.25 m samples

    @classmethod
    def tearDownClass(cls):
        cls.server.stop()

    def _generate_both(self, request, flags):
        """The walk of `request` through ffc_generate over RPC, and `footfall generate` with
        `flags` on the same terrain and character."""
        with ff.Session.rpc("127.0.0.1", self.server.port) as s:
            t = s.load_file(HILLS)
            walk = s.generate(t, dict(request, character_file=self.character))
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "walk.json")
            subprocess.run([self.cli, "generate", "--terrain", HILLS, "--character",
                            self.character] + flags + ["--out", out], check=True)
            with open(out) as f:
                return walk, json.load(f)

    def test_a_character_file_name_that_is_not_utf8_is_said(self):
        # JSON cannot carry it: the library answered "malformed JSON: ... surrogate U+DC00".
        with tempfile.TemporaryDirectory() as folder, ff.Session.embedded() as s:
            path = os.path.join(os.fsencode(folder), b"biped\xff.json")
            with open(self.character, "rb") as f, open(path, "wb") as out:
                out.write(f.read())
            t = s.load_file(HILLS)
            with self.assertRaises(ff.FootfallError) as e:
                s.generate(t, {"character_file": os.fsdecode(path), "steps": 2})
            self.assertEqual(e.exception.status_name, "invalid_argument")
            self.assertIn("the name is not UTF-8, which a JSON request cannot carry",
                          str(e.exception))

    def test_generate_matches_cli(self):
        self.assertTrue(os.path.isfile(self.character), self.character)
        walk, expected = self._generate_both(
            {"start": [20.0, 0.0, 12.0], "heading": [0.0, 0.0, 1.0], "steps": 6,
             "start_frame": 1},
            ["--start", "20,0,12", "--heading", "0,0,1", "--steps", "6", "--start-frame", "1"])
        self.assertEqual(walk, expected)
        feet = [tr for tr in walk["tracks"] if tr["kind"] == "foot"]
        self.assertEqual(len(feet), 2)
        for track in feet:
            for key in track["keys"]:
                self.assertTrue(all(math.isfinite(v) for v in key["position"]))

    def test_generate_crowd_spacing_matches_cli(self):
        walk, expected = self._generate_both(
            {"start": [20.0, 0.0, 12.0], "steps": 3, "crowd": 4, "crowd_spacing": 1.5},
            ["--start", "20,0,12", "--steps", "3", "--crowd", "4", "--crowd-spacing", "1.5"])
        self.assertEqual(walk, expected)
        bodies = [tr for tr in walk["tracks"] if tr["kind"] == "body"]
        self.assertEqual(len(bodies), 4)

    def test_a_walk_in_chunks_keeps_its_steps_when_the_server_dies(self):
        # A server gone in the middle of a walk lost every step made, with a message naming no
        # step: asked for in chunks, the steps made before the failure are kept.
        request = {"character_file": self.character, "start": [20.0, 0.0, 12.0],
                   "heading": [0.0, 0.0, 1.0], "steps": 10, "start_frame": 1}
        with ff.Session.rpc("127.0.0.1", self.server.port) as s:
            t = s.load_file(HILLS)
            whole = s.generate(t, request)
            done = []
            self.assertEqual(s.generate(t, request, chunk_steps=3,
                                        progress=lambda d, n: done.append((d, n))), whole)
            self.assertEqual(done, [(3, 10), (6, 10), (9, 10), (10, 10)])
            four = s.generate(t, dict(request, steps=4))
        dying = ff.LocalServer().start()
        try:
            with ff.Session.rpc("127.0.0.1", dying.port, timeout=5.0) as s:
                t = s.load_file(HILLS)

                def kill_after_second_chunk(done, total):
                    if done == 4:
                        dying.kill()
                with self.assertRaises(ff.WalkStopped) as e:
                    s.generate(t, request, chunk_steps=2, progress=kill_after_second_chunk)
                self.assertEqual(e.exception.status_name, "unavailable")
                self.assertIn("(generating steps 5 to 6); walk stopped, keys up to step 4 kept",
                              e.exception.message)
                self.assertEqual(e.exception.walk, four)
                # In one call, nothing is kept, and the message says so.
                with self.assertRaises(ff.FootfallError) as e:
                    s.generate(t, request)
                self.assertNotIsInstance(e.exception, ff.WalkStopped)
                self.assertEqual(e.exception.status_name, "unavailable")
                self.assertIn("no key of the walk was kept", e.exception.message)
        finally:
            dying.stop()

    def test_a_server_that_dies_mid_walk_is_told_from_a_cliff(self):
        # A footfalld killed during a one-call walk gave WalkStopped 'no_foothold', as a stop at
        # the terrain would: now 'unavailable' (ffc_walk_stop), with the keys so far.
        import threading
        flat = [(x * 0.1, 0.0, z * 0.1, 0.0, 1.0, 0.0) for z in range(401) for x in range(401)]
        loop = [[35.0, 0.0, 5.0], [35.0, 0.0, 35.0], [5.0, 0.0, 35.0], [5.0, 0.0, 5.0]] * 40
        request = {"character_file": self.character, "start": [5.0, 0.0, 5.0], "path": loop,
                   "steps": 20000, "crowd": 16}
        dying = ff.LocalServer().start()
        try:
            with ff.Session.rpc("127.0.0.1", dying.port, timeout=5.0) as s:
                t = s.load_samples(flat, "flat")
                killer = threading.Timer(0.5, dying.kill)  # the walk takes some seconds
                killer.start()
                try:
                    with self.assertRaises(ff.WalkStopped) as e:
                        s.generate(t, request)
                finally:
                    killer.join()
                self.assertEqual(e.exception.status_name, "unavailable")
                self.assertIn("footfalld at 127.0.0.1:%d" % dying.port, e.exception.message)
                bodies = [tr for tr in e.exception.walk["tracks"] if tr["kind"] == "body"]
                self.assertEqual(len(bodies), 16)
                self.assertTrue(all(len(b["keys"]) > 1 for b in bodies))
        finally:
            dying.stop()
        # A walk stopped by the terrain is still 'no_foothold'.
        with ff.Session.rpc("127.0.0.1", self.server.port) as s:
            t = s.load_file(HILLS)
            with self.assertRaises(ff.WalkStopped) as e:
                s.generate(t, {"character_file": self.character, "start": [20.0, 0.0, 12.0],
                               "heading": [1.0, 0.0, 0.0], "steps": 400})
            self.assertEqual(e.exception.status_name, "no_foothold")

    def test_notes_are_the_command_lines(self):
        # A start 10 m beyond the hills' edge: the command line prints a note, and the session
        # gives the same one.
        with ff.Session.rpc("127.0.0.1", self.server.port) as s:
            t = s.load_file(HILLS)
            count, bounds = s.info(t)
            start = [bounds[3] + 10.0, 0.0, (bounds[2] + bounds[5]) / 2]
            status, _, _, notes = s.generate_json_with_notes(
                t, {"character_file": self.character, "start": start, "steps": 2})
        self.assertEqual(status, 0)
        flag = ",".join(repr(v) for v in start)
        with tempfile.TemporaryDirectory() as tmp:
            run = subprocess.run([self.cli, "generate", "--terrain", HILLS, "--character",
                                  self.character, "--start", flag, "--steps", "2", "--out",
                                  os.path.join(tmp, "walk.json")],
                                 check=True, stderr=subprocess.PIPE, universal_newlines=True)
        printed = [line[len("footfall generate: note: "):] for line in run.stderr.splitlines()
                   if line.startswith("footfall generate: note: ")]
        self.assertEqual(len(printed), 1, run.stderr)
        # The same note, but for how the start is named: "--start" there, the request's here.
        self.assertEqual(notes[0].split(") snaps")[1], printed[0].split(") snaps")[1])

    def test_generate_bad_request_raises(self):
        with ff.Session.rpc("127.0.0.1", self.server.port) as s:
            t = s.load_file(HILLS)
            with self.assertRaises(ff.FootfallError) as e:
                s.generate(t, "{not json")
            self.assertIn(e.exception.status_name, ("invalid_argument", "parse_error"))


if __name__ == "__main__":
    unittest.main()
