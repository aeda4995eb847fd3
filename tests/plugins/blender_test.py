"""The Blender add-on in real Blender, headless, against a real footfalld:

  blender -b --factory-startup -noaudio --python-exit-code 1 --python tests/plugins/blender_test.py \
      -- --addon-zip build/plugins/footfall_blender.zip --work-dir /tmp/ffb

Installs the add-on from its zip, builds uneven terrain and a hexapod (new empties) and a biped
(an armature with IK to picked empties), runs Terrain Setup, Character Setup and Generate Walk,
and checks the keys against `footfall generate` run on the same samples; imports a CLI walk;
kills the server in the middle of a walk. Needs FOOTFALL_CLI (or build/client/cli/footfall),
FOOTFALLD and data/characters/{hexapod,biped}.json.
"""

import argparse
import ctypes
import json
import math
import os
import random
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import time
import unittest
from array import array

import addon_utils
import bpy
from mathutils import Euler, Matrix, Quaternion, Vector, kdtree

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(REPO, "plugins", "python"))  # the shared package, for the server

import footfall_client as ff  # noqa: E402

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
ap = argparse.ArgumentParser()
ap.add_argument("--addon-zip", required=True)
ap.add_argument("--work-dir", required=True)
ARGS = ap.parse_args(argv)
CLI = os.environ.get("FOOTFALL_CLI") or os.path.join(REPO, "build", "client", "cli", "footfall")
CHARACTERS = os.environ.get("FOOTFALL_CHARACTERS") or os.path.join(REPO, "data", "characters")
TOL = 1e-4  # Blender keeps key values as 32-bit floats


def to_ff(v):
    return (v[0], v[2], -v[1])


def from_ff(v):
    return (v[0], -v[2], v[1])


def sample_rows(flat):
    """The add-on's samples (mesh_samples: one array('d'), 6 doubles a sample) as a list of
    (x, y, z, nx, ny, nz) tuples."""
    if not (isinstance(flat, array) and flat.typecode == "d" and len(flat) % 6 == 0):
        raise AssertionError("expected an array('d') of whole samples, got a %s of %d"
                             % (type(flat).__name__, len(flat)))
    return list(zip(*[iter(flat)] * 6))


def csv(v):
    return ",".join(repr(float(c)) for c in v)


def run_cli(*args):
    result = subprocess.run([CLI] + [str(a) for a in args], capture_output=True, text=True)
    if result.returncode != 0:
        raise AssertionError("footfall %s failed (%d): %s" % (" ".join(map(str, args)),
                                                              result.returncode, result.stderr))
    return result


def fcurve_keys(obj, path, count):
    """{frame: tuple of `count` values} from obj's action for data path `path`."""
    action = obj.animation_data.action if obj.animation_data else None
    if action is None:
        return {}
    out = {}
    for i in range(count):
        fc = action.fcurves.find(path, index=i)
        if fc is None:
            continue
        for kp in fc.keyframe_points:
            out.setdefault(kp.co[0], [None] * count)[i] = kp.co[1]
    return {f: tuple(v) for f, v in out.items()}


def body_rotation_keys(obj):
    """{frame: quaternion} from obj's rotation keys in the path of its rotation mode."""
    mode = obj.rotation_mode
    if mode == "QUATERNION":
        return {f: Quaternion(v) for f, v in fcurve_keys(obj, "rotation_quaternion", 4).items()}
    if mode == "AXIS_ANGLE":
        return {f: Quaternion(v[1:], v[0])
                for f, v in fcurve_keys(obj, "rotation_axis_angle", 4).items()}
    return {f: Euler(v, mode).to_quaternion()
            for f, v in fcurve_keys(obj, "rotation_euler", 3).items()}


def new_empty(name, parent=None, location=None):
    """An empty linked to the current scene, under `parent`, at `location` (local)."""
    obj = bpy.data.objects.new(name, None)
    bpy.context.scene.collection.objects.link(obj)
    obj.parent = parent
    if location is not None:
        obj.location = location
    return obj


def rig_feet_body(name):
    """The rig root `name`, its {foot name: IK target} and its body."""
    rig = bpy.data.objects[name]
    return rig, {f.name: f.target for f in rig.footfall_rig.feet}, rig.footfall_rig.body


def run_reporting(operator, **kwargs):
    """(result, error, reports): the operator's result (None when it raised), the RuntimeError
    it raised (or None), and the reports Blender printed for it ("Warning: ...", one a line),
    as an animator reads them in the Info editor."""
    libc = ctypes.CDLL(None)
    sys.stdout.flush()
    libc.fflush(None)
    saved = os.dup(1)
    result = error = None
    with tempfile.TemporaryFile() as f:
        os.dup2(f.fileno(), 1)
        try:
            result = operator(**kwargs)
        except RuntimeError as e:
            error = e
        finally:
            sys.stdout.flush()
            libc.fflush(None)
            os.dup2(saved, 1)
            os.close(saved)
        f.seek(0)
        reports = f.read().decode("utf-8", "replace").splitlines()
    return result, error, reports


def clear_animation(objects):
    for obj in objects:
        if obj.animation_data:
            obj.animation_data_clear()


class BlenderAddonTest(unittest.TestCase):
    """One scene, built up step by step: the tests run in their numbered order."""

    @classmethod
    def setUpClass(cls):
        os.makedirs(ARGS.work_dir, exist_ok=True)
        for path in (CLI, os.path.join(CHARACTERS, "hexapod.json"),
                     os.path.join(CHARACTERS, "biped.json")):
            if not os.path.isfile(path):
                raise RuntimeError("missing %s" % path)
        bpy.ops.preferences.addon_install(filepath=ARGS.addon_zip, overwrite=True)
        mod = addon_utils.enable("footfall_blender", default_set=True, handle_error=None)
        if mod is None:
            raise RuntimeError("the add-on did not enable")
        import footfall_blender.operators as ops
        cls.ops = ops
        cls.server = ff.LocalServer().start()
        prefs = bpy.context.preferences.addons["footfall_blender"].preferences
        prefs.host, prefs.port, prefs.start_local = "127.0.0.1", cls.server.port, False
        cls.prefs = prefs
        for obj in list(bpy.data.objects):
            bpy.data.objects.remove(obj)
        cls.pts = os.path.join(ARGS.work_dir, "terrain.pts")

    @classmethod
    def tearDownClass(cls):
        cls.ops.chunk_hook = None
        addon_utils.disable("footfall_blender", default_set=True)
        cls.server.stop()

    # -- helpers --------------------------------------------------------------------------------

    def select(self, objects, active):
        for o in bpy.context.view_layer.objects:
            o.select_set(False)
        for o in objects:
            o.select_set(True)
        bpy.context.view_layer.objects.active = active

    def biped_walk_setup(self, steps):
        """The biped rig selected and set to walk `steps` steps from frame 1: the rig, its foot
        targets by name, its body and the scene's footfall settings."""
        rig = bpy.data.objects["biped_rig"]
        feet = {f.name: f.target for f in rig.footfall_rig.feet}
        settings = bpy.context.scene.footfall
        settings.rig, settings.steps, settings.start_frame = rig, steps, 1
        self.select([rig], rig)
        return rig, feet, rig.footfall_rig.body, settings

    def samples_tree(self):
        if not hasattr(type(self), "_tree"):
            pts = []
            with open(self.pts) as f:
                for line in f:
                    if line.strip() and not line.startswith("#"):
                        pts.append(tuple(float(v) for v in line.split()[:3]))
            tree = kdtree.KDTree(len(pts))
            for i, p in enumerate(pts):
                tree.insert(p, i)
            tree.balance()
            type(self)._tree, type(self)._count = tree, len(pts)
        return type(self)._tree

    def cli_walk(self, rig, steps, name, *flags):
        out = os.path.join(ARGS.work_dir, name + ".json")
        mw = rig.matrix_world
        run_cli("generate", "--terrain", self.pts, "--character", rig.footfall_rig.character_path,
                "--start", csv(to_ff(mw.translation)),
                "--heading", csv(to_ff(mw.to_3x3() @ Vector((0, -1, 0)))),
                "--steps", steps, "--start-frame", bpy.context.scene.footfall.start_frame,
                "--server", "127.0.0.1:%d" % self.server.port, "--unit", "m", "--out", out, *flags)
        with open(out) as f:
            return json.load(f), out

    def assert_keys_equal_walk(self, walk, feet, body, scale=1.0):
        """The objects' keys are exactly the walk's tracks (frames, positions, rotations: the
        body's, and the feet's where the walk has them), in a scene of Unit Scale `scale`
        (positions divided by it)."""
        for track in walk["tracks"]:
            is_body = track["kind"] == "body"
            obj = body if is_body else feet[track["name"]]
            rotated = all("rotation" in k for k in track["keys"])
            keys = fcurve_keys(obj, "location", 3)
            frames = sorted({k["frame"] for k in track["keys"]})
            self.assertEqual(sorted(keys), [float(f) for f in frames], track["name"])
            for k in track["keys"]:
                got = keys[float(k["frame"])]
                want = [c / scale for c in from_ff(k["position"])]
                for g, w in zip(got, want):
                    self.assertAlmostEqual(g, w, delta=TOL * max(1.0, abs(w)),
                                           msg="%s frame %s" % (track["name"], k["frame"]))
            if rotated:
                rots = body_rotation_keys(obj)
                for k in track["keys"]:
                    x, y, z, w = k["rotation"]
                    want = (w, x, -z, y)
                    got = rots[float(k["frame"])]
                    same = all(abs(g - v) < TOL for g, v in zip(got, want))
                    flipped = all(abs(g + v) < TOL for g, v in zip(got, want))
                    self.assertTrue(same or flipped, "%s rotation at %s: %s vs %s"
                                    % (track["name"], k["frame"], got, want))

    def assert_feet_on_terrain(self, walk):
        tree = self.samples_tree()
        n = 0
        for track in walk["tracks"]:
            if track["kind"] != "foot":
                continue
            for k in track["keys"]:
                if k.get("phase") in ("start", "end"):
                    _, _, dist = tree.find(k["position"])
                    self.assertLess(dist, 1e-6, "%s %s" % (track["name"], k))
                    n += 1
        self.assertGreater(n, 0)

    # -- the scene ------------------------------------------------------------------------------

    def test_1_terrain_setup(self):
        # 10 x 10 m of hills, resampled every 5 cm (the hexapod's feet are 12 cm apart).
        bpy.ops.mesh.primitive_grid_add(x_subdivisions=50, y_subdivisions=50, size=10)
        terrain = bpy.context.active_object
        terrain.name = "terrain"
        for v in terrain.data.vertices:
            x, y = v.co.x, v.co.y
            v.co.z = 0.3 * math.sin(0.9 * x) * math.cos(0.7 * y) + 0.03 * x
        self.select([terrain], terrain)
        scene = bpy.context.scene.footfall
        scene.terrain_source, scene.separation = "MESH", 0.05
        self.assertEqual(bpy.ops.footfall.terrain_setup(save_points=self.pts), {"FINISHED"})
        self.samples_tree()
        self.assertEqual(scene.sample_count, self._count)
        self.assertGreater(scene.sample_count, 200 * 200)
        self.assertEqual(scene.terrain_name, "terrain")

    def test_1a_terrain_setup_sends_the_pure_python_samples(self):
        # The add-on resamples with numpy in Blender: the samples Terrain Setup sent (and saved
        # in test_1) are the pure-Python loops' for the same mesh, every double to the bit.
        self.assertIsNotNone(self.ops.sampling._numpy, "the add-on's sampling lacks numpy")
        terrain = bpy.data.objects["terrain"]
        scene = bpy.context.scene
        separation = scene.footfall.separation * self.ops.unit_scale(scene)
        points, tris = self.ops.mesh_triangles(bpy.context, terrain)
        normals = ff.sampling.corner_normals(points, tris, pure=True)
        want = ff.sampling.sample_triangles(points, tris, separation, corner_normals=normals,
                                            pure=True)
        path = os.path.join(ARGS.work_dir, "terrain_pure.pts")
        ff.sampling.write_point_file(path, want)
        with open(self.pts) as sent, open(path) as pure:
            self.assertEqual(sent.readlines()[1:], pure.readlines()[1:])  # (repr: every bit)
        self.assertEqual(packed(sample_rows(self.ops.mesh_samples(bpy.context, terrain,
                                                                  separation))),
                         packed(want))

    def test_1b_instances_on_the_terrain_mesh_are_sampled(self):
        # A Geometry Nodes modifier's instances (a box put on a point of the ground by Instance
        # on Points) were left out of the samples, though the viewport shows them.
        bpy.ops.mesh.primitive_grid_add(x_subdivisions=10, y_subdivisions=10, size=4,
                                        location=(20.0, 0.0, 0.0))
        ground = bpy.context.active_object
        tree = bpy.data.node_groups.new("footfall_test_box", "GeometryNodeTree")
        tree.inputs.new("NodeSocketGeometry", "Geometry")
        tree.outputs.new("NodeSocketGeometry", "Geometry")
        nodes, links = tree.nodes, tree.links
        inputs, outputs = nodes.new("NodeGroupInput"), nodes.new("NodeGroupOutput")
        point = nodes.new("GeometryNodeMeshLine")
        point.inputs["Count"].default_value = 1
        point.inputs["Start Location"].default_value = (0.0, 0.0, 0.5)
        box = nodes.new("GeometryNodeMeshCube")
        box.inputs["Size"].default_value = (1.0, 1.0, 1.0)
        instance = nodes.new("GeometryNodeInstanceOnPoints")
        join = nodes.new("GeometryNodeJoinGeometry")
        links.new(point.outputs["Mesh"], instance.inputs["Points"])
        links.new(box.outputs["Mesh"], instance.inputs["Instance"])
        links.new(inputs.outputs[0], join.inputs[0])
        links.new(instance.outputs["Instances"], join.inputs[0])
        links.new(join.outputs[0], outputs.inputs[0])
        ground.modifiers.new("box", "NODES").node_group = tree
        try:
            bpy.context.view_layer.update()
            instanced = sample_rows(self.ops.mesh_samples(bpy.context, ground, 0.1))
            realize = nodes.new("GeometryNodeRealizeInstances")
            links.new(join.outputs[0], realize.inputs[0])
            links.new(realize.outputs[0], outputs.inputs[0])
            bpy.context.view_layer.update()
            realized = sample_rows(self.ops.mesh_samples(bpy.context, ground, 0.1))
            self.assertEqual(len(instanced), len(realized))
            self.assertAlmostEqual(max(s[1] for s in instanced), 1.0, delta=1e-6)  # the box top
        finally:
            bpy.data.objects.remove(ground)
            bpy.data.node_groups.remove(tree)

    def test_1b2_an_instancer_the_viewport_hides_is_no_terrain(self):
        # A plane instancing a box on its face, with Show Instancer off in the viewport: its own
        # face was sampled too, and feet snapped onto a plane nobody sees.
        bpy.ops.mesh.primitive_plane_add(size=4, location=(30.0, 0.0, 0.0))
        plane = bpy.context.active_object
        bpy.ops.mesh.primitive_cube_add(size=1, location=(30.0, 0.0, 0.5))
        box = bpy.context.active_object
        box.parent = plane
        box.matrix_parent_inverse = plane.matrix_world.inverted()
        plane.instance_type = "FACES"
        try:
            bpy.context.view_layer.update()
            shown = sample_rows(self.ops.mesh_samples(bpy.context, plane, 0.1))
            plane.show_instancer_for_viewport = False
            bpy.context.view_layer.update()
            hidden = sample_rows(self.ops.mesh_samples(bpy.context, plane, 0.1))
            self.assertGreater(len(hidden), 0)  # the box
            self.assertLess(len(hidden), 0.6 * len(shown))
            # Nothing on the plane outside the box's footprint (footfall x = Blender x).
            self.assertFalse([s for s in hidden if abs(s[0] - 30.0) > 0.6], hidden[:3])
        finally:
            bpy.data.objects.remove(box)
            bpy.data.objects.remove(plane)

    def test_1d_objects_that_make_faces_are_terrains(self):
        # Terrain Setup took meshes alone: a collection instance (a linked set), an extruded
        # curve or text was "select a mesh". Now any object whose faces the viewport shows is
        # sampled, a collection instance as the meshes it instances, where it puts them; one
        # without faces (an empty) is a report that changes nothing.
        scene = bpy.context.scene.footfall
        made = []
        setups = bpy.data.collections.new("footfall_test_set")
        try:
            bpy.ops.mesh.primitive_grid_add(x_subdivisions=8, y_subdivisions=8, size=3)
            ground = bpy.context.active_object
            made.append(ground)
            for v in ground.data.vertices:
                v.co.z = 0.2 * math.sin(v.co.x) + 0.1 * v.co.y
            ground.location = (0.5, -0.25, 0.1)
            for c in ground.users_collection:
                c.objects.unlink(ground)
            setups.objects.link(ground)
            instance = new_empty("footfall_test_set_instance", location=(30.0, 5.0, 1.0))
            made.append(instance)
            instance.instance_type, instance.instance_collection = "COLLECTION", setups
            instance.rotation_euler = (0.0, 0.0, math.radians(30))
            instance.scale = (2.0, 2.0, 2.0)
            # The same mesh placed where the instance shows it, as a mesh of the scene.
            reference = bpy.data.objects.new("footfall_test_set_reference", ground.data)
            made.append(reference)
            bpy.context.scene.collection.objects.link(reference)
            bpy.context.view_layer.update()
            reference.matrix_world = instance.matrix_world @ ground.matrix_world
            bpy.context.view_layer.update()
            want = sorted(sample_rows(self.ops.mesh_samples(bpy.context, reference, 0.2)))
            self.select([instance], instance)
            scene.terrain_source, scene.separation = "MESH", 0.2
            out = os.path.join(ARGS.work_dir, "set_instance.pts")
            self.assertEqual(bpy.ops.footfall.terrain_setup(save_points=out), {"FINISHED"})
            self.assertEqual(scene.sample_count, len(want))
            self.assertEqual(scene.terrain_name, instance.name)
            got = sorted(sample_rows(self.ops.mesh_samples(bpy.context, instance, 0.2)))
            self.assertEqual(len(got), len(want))
            for g, w in zip(got, want):
                for a, b in zip(g, w):
                    self.assertAlmostEqual(a, b, delta=1e-5)
            # An extruded curve.
            bpy.ops.curve.primitive_bezier_curve_add(location=(40.0, 0.0, 0.0))
            curve = bpy.context.active_object
            made.append(curve)
            curve.data.extrude = 0.5
            self.select([curve], curve)
            self.assertEqual(bpy.ops.footfall.terrain_setup(), {"FINISHED"})
            self.assertGreater(scene.sample_count, 0)
            # No faces: a report, and the scene's terrain as it was.
            key, count = scene.terrain_key, scene.sample_count
            empty = new_empty("footfall_test_plain_empty")
            made.append(empty)
            self.select([empty], empty)
            with self.assertRaises(RuntimeError) as e:
                bpy.ops.footfall.terrain_setup()
            self.assertIn("footfall_test_plain_empty has no faces to walk on: select a mesh",
                          str(e.exception))
            self.assertEqual((scene.terrain_key, scene.sample_count), (key, count))
            # Faces of no area (scaled to 0 on an axis): a report naming the object (it was
            # "blender: no samples").
            bpy.ops.mesh.primitive_plane_add(size=4.0, location=(60.0, 0.0, 0.0))
            flat = bpy.context.active_object
            made.append(flat)
            flat.scale = (0.0, 1.0, 1.0)
            bpy.context.view_layer.update()
            self.select([flat], flat)
            with self.assertRaises(RuntimeError) as e:
                bpy.ops.footfall.terrain_setup()
            self.assertIn("%s has faces of no area to walk on" % flat.name, str(e.exception))
            self.assertEqual((scene.terrain_key, scene.sample_count), (key, count))
        finally:
            curves = [o.data for o in made if o.type == "CURVE"]
            for obj in made:
                bpy.data.objects.remove(obj)
            for data in curves:
                bpy.data.curves.remove(data)
            bpy.data.collections.remove(setups)
            # The hills again, for the tests after this one.
            terrain = bpy.data.objects["terrain"]
            self.select([terrain], terrain)
            scene.terrain_source, scene.separation = "MESH", 0.05
            self.assertEqual(bpy.ops.footfall.terrain_setup(), {"FINISHED"})
            self.assertEqual(scene.sample_count, self._count)

    def test_1c_a_closed_path_curve_ends_at_its_start(self):
        # A cyclic spline's path lost its closing segment: the walk ended a segment short.
        corners = [(0, 0, 0), (2, 0, 0), (2, 2, 0)]
        moved = [(x + 1, y, z) for x, y, z in corners]
        for cyclic, want in ((True, moved + moved[:1]), (False, moved)):
            data = bpy.data.curves.new("loop_path", "CURVE")
            spline = data.splines.new("POLY")
            spline.points.add(len(corners) - 1)
            for p, c in zip(spline.points, corners):
                p.co = c + (1,)
            spline.use_cyclic_u = cyclic
            obj = bpy.data.objects.new("loop_path", data)
            bpy.context.scene.collection.objects.link(obj)
            obj.location = (1, 0, 0)
            bpy.context.view_layer.update()
            try:
                pts = [tuple(p) for p in self.ops.curve_points(bpy.context, obj)]
            finally:
                bpy.data.objects.remove(obj)
                bpy.data.curves.remove(data)
            self.assertEqual(pts, want, "cyclic" if cyclic else "open")

    def test_2_bad_selection_is_a_report(self):
        self.select([], None)
        with self.assertRaises(RuntimeError) as e:
            bpy.ops.footfall.terrain_setup()
        self.assertIn("select a mesh", str(e.exception))

    def test_2b_a_footfalld_that_never_listens_fails_within_the_timeout(self):
        # The add-on waited 10 s for a local footfalld to listen, whatever its Timeout
        # preference: a footfalld that started but never listened froze Blender for 10 s.
        stand_in = os.path.join(ARGS.work_dir, "never_listens.sh")
        with open(stand_in, "w") as f:
            f.write("#!/bin/sh\nexec sleep 60\n")
        os.chmod(stand_in, 0o755)
        with socket.socket() as s:  # a port where nothing answers
            s.bind(("127.0.0.1", 0))
            dead_port = s.getsockname()[1]
        prefs = self.prefs
        saved = (prefs.port, prefs.start_local, prefs.footfalld, prefs.timeout)
        prefs.port, prefs.start_local, prefs.footfalld, prefs.timeout = \
            dead_port, True, stand_in, 1.0
        self.select([], None)
        try:
            began = time.monotonic()
            with self.assertRaises(RuntimeError) as e:
                bpy.ops.footfall.terrain_setup()
            took = time.monotonic() - began
        finally:
            prefs.port, prefs.start_local, prefs.footfalld, prefs.timeout = saved
        print("a footfalld that never listens: reported after %.2f s (timeout 1 s)" % took)
        self.assertLess(took, 3.0)
        self.assertIn("no footfalld answers at 127.0.0.1:%d and a local one could not be "
                      "started: %s did not start listening within 1 s" % (dead_port, stand_in),
                      str(e.exception))
        self.assertIsNone(self.ops._connection.local)  # the stand-in stopped, not left behind
        # The configured server again: the next command goes to it.
        self.assertTrue(self.ops.session(bpy.context).ping())

    def test_3_hexapod_setup_creates_empties(self):
        bpy.context.scene.cursor.location = (-3.0, 3.0, 0.0)
        result = bpy.ops.footfall.character_setup(
            character_file=os.path.join(CHARACTERS, "hexapod.json"), mode="CREATE", name="hexapod")
        self.assertEqual(result, {"FINISHED"})
        rig = bpy.data.objects["hexapod_rig"]
        self.assertTrue(rig.footfall_rig.is_rig)
        feet = {f.name: f.target for f in rig.footfall_rig.feet}
        self.assertEqual(len(feet), 6)
        tree = self.samples_tree()
        for name, obj in feet.items():
            _, _, dist = tree.find(to_ff(obj.matrix_world.translation))
            self.assertLess(dist, 1e-5, name)
        targets = [o for o in bpy.data.objects if o.name.startswith("hexapod_") and
                   o.name.endswith("_target")]
        centres = [o for o in bpy.data.objects if o.name.startswith("hexapod_") and
                   o.name.endswith("_center")]
        self.assertEqual(len(targets), 6)
        self.assertEqual(len(centres), len(json.load(open(os.path.join(CHARACTERS, "hexapod.json")))
                                           .get("pairs", [0, 0, 0])))
        for t in targets:
            self.assertIn(t.parent, centres)

    def test_3aa_a_character_file_in_centimetres_is_set_up_at_its_size(self):
        # The add-on took character files for metres: one in centimetres stood 100 times too
        # tall. Its unit, given on the operator or in the panel, scales it to metres.
        metres = ff.character.load(os.path.join(CHARACTERS, "biped.json"))
        cm_file = os.path.join(ARGS.work_dir, "biped_cm.json")
        with open(cm_file, "w") as f:
            json.dump(ff.character.scaled(metres, 100.0), f)
        settings = bpy.context.scene.footfall
        bpy.context.scene.cursor.location = (0.5, 2.5, 0.0)
        try:
            for name, given, panel in (("cm_op", "cm", "m"), ("cm_panel", "", "cm")):
                settings.character_unit = panel
                with bpy.context.temp_override(active_object=None):
                    self.assertEqual(bpy.ops.footfall.character_setup(
                        character_file=cm_file, mode="CREATE", name=name,
                        character_unit=given), {"FINISHED"})
                rig = bpy.data.objects[name + "_rig"]
                kept = ff.character.parse(rig.footfall_rig.character_json)
                self.assertAlmostEqual(kept["step_length"], metres["step_length"], places=9)
                self.assertAlmostEqual(kept["reach"], metres["reach"], places=9)
                body = rig.footfall_rig.body
                height = (body.matrix_world.translation - rig.matrix_world.translation).length
                self.assertAlmostEqual(height, 0.95, delta=1e-4, msg=name)
            # An unknown unit is a report, and makes nothing.
            settings.character_unit = "m"
            before = len(bpy.data.objects)
            with self.assertRaises(RuntimeError) as e:
                bpy.ops.footfall.character_setup(character_file=cm_file, mode="CREATE",
                                                 name="furlong", character_unit="furlong")
            self.assertIn("unknown linear unit 'furlong'", str(e.exception))
            self.assertEqual(len(bpy.data.objects), before)
        finally:
            settings.character_unit = "m"
            for obj in [o for o in bpy.data.objects if o.name.startswith(("cm_op", "cm_panel"))]:
                bpy.data.objects.remove(obj)

    def test_3a_new_rigs_go_into_the_active_collection(self):
        # (They went into the scene's own collection, wherever the animator was working.)
        layer = bpy.context.view_layer
        rigs = bpy.data.collections.new("rigs")
        bpy.context.scene.collection.children.link(rigs)
        saved = layer.active_layer_collection
        layer.active_layer_collection = layer.layer_collection.children["rigs"]
        try:
            result = bpy.ops.footfall.character_setup(
                character_file=os.path.join(CHARACTERS, "quadruped.json"), mode="CREATE",
                name="collected")
            self.assertEqual(result, {"FINISHED"})
            made = [o for o in bpy.data.objects if o.name.startswith("collected_")]
            self.assertTrue(made)
            for obj in made:
                self.assertEqual([c.name for c in obj.users_collection], ["rigs"], obj.name)
            # An excluded one is passed over for the scene's own.
            layer.layer_collection.children["rigs"].exclude = True
            layer.active_layer_collection = layer.layer_collection.children["rigs"]
            self.assertEqual(self.ops._new_objects_collection(bpy.context),
                             bpy.context.scene.collection)
        finally:
            layer.layer_collection.children["rigs"].exclude = False
            layer.active_layer_collection = saved
            for obj in [o for o in bpy.data.objects if o.name.startswith("collected_")]:
                bpy.data.objects.remove(obj)
            bpy.data.collections.remove(rigs)

    def test_3b_bad_character_or_walk_is_a_report_and_makes_nothing(self):
        # A pair naming a missing foot raised KeyError through the operator after the body and
        # the feet were made; a walk whose key has two coordinates raised IndexError.
        with open(os.path.join(CHARACTERS, "hexapod.json")) as f:
            data = json.load(f)
        data["pairs"] = [["L1", "NOPE"]]
        bad_character = os.path.join(ARGS.work_dir, "badpair.json")
        with open(bad_character, "w") as f:
            json.dump(data, f)
        bad_walk = os.path.join(ARGS.work_dir, "pos2.json")
        with open(bad_walk, "w") as f:
            json.dump({"tracks": [{"name": "L1", "kind": "foot", "keys": [
                {"frame": 1, "position": [0, 0]}]}]}, f)
        before = set(bpy.data.objects)
        with self.assertRaises(RuntimeError) as e:
            bpy.ops.footfall.character_setup(character_file=bad_character, mode="CREATE",
                                             name="broken")
        self.assertIn("pairs[0]: no foot named 'NOPE'", str(e.exception))
        self.assertNotIn("Traceback", str(e.exception))
        bpy.context.scene.footfall.rig = None
        self.select([], None)
        with self.assertRaises(RuntimeError) as e:
            bpy.ops.footfall.import_walk(filepath=bad_walk)
        self.assertIn("tracks[0].keys[0]: expected \"position\"", str(e.exception))
        self.assertEqual(set(bpy.data.objects), before)
        # Frames beyond Blender's range (its frames are floats within +-1048574): keys piled onto
        # a few frames, and the import said it had imported them all.
        far_walk = os.path.join(ARGS.work_dir, "far_frames.json")
        with open(far_walk, "w") as f:
            json.dump({"tracks": [{"name": "L1", "kind": "foot", "keys": [
                {"frame": -1e9 + i, "phase": "end", "position": [0, 0, i]} for i in range(4)]}]}, f)
        with self.assertRaises(RuntimeError) as e:
            bpy.ops.footfall.import_walk(filepath=far_walk)
        self.assertIn("frame -1000000000 is beyond Blender's frame range", str(e.exception))
        self.assertEqual(set(bpy.data.objects), before)
        # A coordinate beyond a 32-bit float: keyed as inf and nan, and reported as imported.
        huge_walk = os.path.join(ARGS.work_dir, "huge_position.json")
        with open(huge_walk, "w") as f:
            json.dump({"tracks": [{"name": "L1", "kind": "foot", "keys": [
                {"frame": 1, "phase": "end", "position": [1e39, 0, 0]}]}]}, f)
        with self.assertRaises(RuntimeError) as e:
            bpy.ops.footfall.import_walk(filepath=huge_walk)
        self.assertIn("coordinate 1e+39 is beyond what a Blender key holds", str(e.exception))
        self.assertEqual(set(bpy.data.objects), before)
        # A walk whose tracks have no keys: its empties were made, then "has no keys" reported.
        no_keys = os.path.join(ARGS.work_dir, "no_keys.json")
        with open(no_keys, "w") as f:
            json.dump({"tracks": [{"name": "L1", "kind": "foot", "keys": []},
                                  {"name": "body", "kind": "body", "keys": []}]}, f)
        with self.assertRaises(RuntimeError) as e:
            bpy.ops.footfall.import_walk(filepath=no_keys)
        self.assertIn("has no keys", str(e.exception))
        self.assertEqual(set(bpy.data.objects), before)

    def test_3c_the_panels_buttons_read_its_character_file(self):
        # The panel's buttons set only the mode: with no file field anywhere on the panel, a
        # click always read the character file '' and failed.
        import footfall_blender.ui as ui

        class Layout:
            def __init__(self):
                self.props, self.buttons = [], []

            def column(self):
                return self

            def prop(self, data, name, **_):
                self.props.append(name)

            def label(self, **_):
                pass

            def operator(self, idname, **_):
                button = type("Button", (), {})()
                self.buttons.append((idname, button))
                return button

        layout = Layout()
        panel = type("Panel", (), {"layout": layout})()
        ui.FOOTFALL_PT_character.draw(panel, bpy.context)
        self.assertEqual(layout.props[0], "character_file")
        setups = [b for idname, b in layout.buttons if idname == "footfall.character_setup"]
        self.assertEqual([b.mode for b in setups], ["CREATE", "PICK"])
        self.assertFalse(any(hasattr(b, "character_file") for b in setups))

        scene = bpy.context.scene
        before, rig_before = set(bpy.data.objects), scene.footfall.rig
        path = os.path.join(CHARACTERS, "hexapod.json")
        try:
            scene.footfall.character_file = ""
            with self.assertRaises(RuntimeError) as e:
                bpy.ops.footfall.character_setup(mode="CREATE", name="panel")
            self.assertIn("choose a character file (Character Setup > Character file)",
                          str(e.exception))
            self.assertEqual(set(bpy.data.objects), before)
            scene.footfall.character_file = path
            self.assertEqual(bpy.ops.footfall.character_setup(mode="CREATE", name="panel"),
                             {"FINISHED"})
            rig = bpy.data.objects["panel_rig"]
            self.assertEqual(rig.footfall_rig.character_path, path)
            self.assertEqual(len(rig.footfall_rig.feet), 6)
            # The operator's own file (a script's) goes before the panel's.
            with self.assertRaises(RuntimeError) as e:
                bpy.ops.footfall.character_setup(
                    character_file=os.path.join(ARGS.work_dir, "missing.json"), mode="CREATE",
                    name="panel2")
            self.assertIn("missing.json", str(e.exception))
        finally:
            scene.footfall.character_file = ""
            for obj in set(bpy.data.objects) - before:
                bpy.data.objects.remove(obj)
            scene.footfall.rig = rig_before

    def test_4_biped_setup_picks_ik_targets(self):
        with open(os.path.join(CHARACTERS, "biped.json")) as f:
            names = [foot["name"] for foot in json.load(f)["feet"]]
        bpy.ops.object.armature_add(location=(0.0, 3.0, 1.0))
        arm = bpy.context.active_object
        arm.name = "biped_armature"
        body = bpy.data.objects.new("biped_body", None)
        bpy.context.scene.collection.objects.link(body)
        body.location = (0.0, 3.0, 1.0)
        body.rotation_euler = (0.0, 0.0, math.radians(30))  # faces 30 degrees off -Y
        empties = []
        for i, name in enumerate(names):
            e = bpy.data.objects.new("biped_IK_" + name, None)
            bpy.context.scene.collection.objects.link(e)
            e.location = (0.2 if i == 0 else -0.2, 3.0, 0.0)
            empties.append(e)
        ik = arm.pose.bones[0].constraints.new("IK")
        ik.target = empties[0]
        self.select(empties + [body], body)
        result = bpy.ops.footfall.character_setup(
            character_file=os.path.join(CHARACTERS, "biped.json"), mode="PICK", name="biped")
        self.assertEqual(result, {"FINISHED"})
        rig = bpy.data.objects["biped_rig"]
        self.assertEqual({f.name: f.target for f in rig.footfall_rig.feet},
                         dict(zip(names, empties)))
        self.assertIs(rig.footfall_rig.body, body)
        tree = self.samples_tree()
        for e in empties:
            self.assertLess(tree.find(to_ff(e.matrix_world.translation))[2], 1e-5)

    def _generate_and_compare(self, rig_name, steps):
        rig = bpy.data.objects[rig_name]
        scene = bpy.context.scene.footfall
        scene.rig, scene.steps, scene.start_frame = rig, steps, 1
        self.select([rig], rig)  # the rig of the active object is keyed
        self.assertEqual(bpy.ops.footfall.generate_walk(), {"FINISHED"})
        expected, _ = self.cli_walk(rig, steps, rig_name + "_cli")
        got = json.loads(bpy.data.texts["footfall_walk.json"].as_string())
        self.assertEqual(got, expected)  # the same walk as the command line, to the last bit
        feet = {f.name: f.target for f in rig.footfall_rig.feet}
        self.assert_keys_equal_walk(expected, feet, rig.footfall_rig.body)
        self.assert_feet_on_terrain(expected)
        return expected

    def test_5_hexapod_walk_matches_cli(self):
        walk = self._generate_and_compare("hexapod_rig", 6)
        self.assertEqual(len([t for t in walk["tracks"] if t["kind"] == "foot"]), 6)

    def test_6_biped_walk_matches_cli(self):
        walk = self._generate_and_compare("biped_rig", 8)
        self.assertEqual(len([t for t in walk["tracks"] if t["kind"] == "foot"]), 2)

    def assert_world_at_key_frames(self, walk, feet, body, tol=1e-4):
        """At each key's frame, the objects are where the walk puts them, in world space (their
        matrix_world as the depsgraph evaluates it at that frame), to `tol` metres."""
        scene = bpy.context.scene
        frame = scene.frame_current
        worst = 0.0
        try:
            for track in walk["tracks"]:
                is_body = track["kind"] == "body"
                obj = body if is_body else feet[track["name"]]
                for k in track["keys"]:
                    scene.frame_set(int(k["frame"]))
                    depsgraph = bpy.context.evaluated_depsgraph_get()
                    mw = obj.evaluated_get(depsgraph).matrix_world
                    worst = max(worst, (mw.translation - Vector(from_ff(k["position"]))).length)
                    if "rotation" in k:
                        x, y, z, w = k["rotation"]
                        got = mw.to_quaternion()
                        self.assertGreater(abs(got.dot(Quaternion((w, x, -z, y)))), 1 - tol,
                                           "%s rotation at %s" % (track["name"], k["frame"]))
        finally:
            scene.frame_set(frame)
        self.assertLess(worst, tol)

    def test_6b_targets_under_an_animated_parent(self):
        # Targets (and a body) parented to an animated control: each key was converted to the
        # parent's space with the parent's matrix at the frame the user was on, so at the other
        # frames the feet were up to a metre off the walk.
        scene = bpy.context.scene
        scene.frame_set(1)
        control = new_empty("mover_control")
        control.keyframe_insert("location", frame=1)
        control.keyframe_insert("rotation_euler", frame=1)
        control.location = (1.0, 0.5, 0.3)
        control.rotation_euler = (0.0, 0.0, math.radians(25))
        control.keyframe_insert("location", frame=100)
        control.keyframe_insert("rotation_euler", frame=100)
        scene.frame_set(1)
        body = new_empty("mover_body", control, (2.5, -3.5, 1.0))
        body.rotation_euler = (0.0, 0.0, math.pi)  # faces +Y
        targets = []
        for name, x in (("L", 2.62), ("R", 2.38)):
            e = bpy.data.objects.new("mover_IK_" + name, None)
            scene.collection.objects.link(e)
            e.parent = control
            e.location = (x, -3.5, 0.0)
            targets.append(e)
        # One foot under the body, which the walk keys (in chunks: each chunk's body keys bend
        # its curve before them).
        targets[0].parent = body
        targets[0].location = (-0.12, 0.0, -1.0)
        bpy.context.view_layer.update()
        self.select(targets + [body], body)
        result = bpy.ops.footfall.character_setup(
            character_file=os.path.join(CHARACTERS, "biped.json"), mode="PICK", name="mover")
        self.assertEqual(result, {"FINISHED"})
        rig = bpy.data.objects["mover_rig"]
        feet = {f.name: f.target for f in rig.footfall_rig.feet}
        settings = scene.footfall
        settings.rig, settings.steps, settings.start_frame = rig, 6, 1
        self.select([rig], rig)  # the rig of the active object is keyed
        scene.frame_set(50)  # the user looks at another frame than the walk's first
        self.assertEqual(bpy.ops.footfall.generate_walk(chunk_steps=2), {"FINISHED"})
        self.assertEqual(scene.frame_current, 50)
        walk = json.loads(bpy.data.texts["footfall_walk.json"].as_string())
        self.assertEqual(walk, self.cli_walk(rig, 6, "mover_cli")[0])
        self.assert_world_at_key_frames(walk, feet, body)
        # Import Walk keys the same way.
        path = os.path.join(ARGS.work_dir, "mover_cli.json")
        clear_animation(list(feet.values()) + [body])
        self.assertEqual(bpy.ops.footfall.import_walk(filepath=path), {"FINISHED"})
        self.assertEqual(scene.frame_current, 50)
        self.assert_world_at_key_frames(walk, feet, body)
        settings.rig = None
        scene.frame_set(1)

    def test_6c_picked_body_keeps_its_rotation_mode(self):
        # Character Setup switched a picked body to quaternion rotation: the user's Euler keys
        # stopped driving it, and the walk was keyed as quaternions.
        scene = bpy.context.scene
        scene.frame_set(1)
        body = bpy.data.objects.new("turner_body", None)
        scene.collection.objects.link(body)
        body.rotation_mode = "ZXY"
        body.location = (-2.5, -3.5, 1.0)
        # Faces +Y; with a key of the user's after the walks' end, which they keep (it went:
        # Generate Walk cleared the rig's keys from the start frame on).
        user = {-30.0: (0.0, 0.0, math.pi - 0.4), -10.0: (0.0, 0.0, math.pi),
                900.0: (0.0, 0.0, math.pi - 0.2)}
        for frame, angles in user.items():
            body.rotation_euler = angles
            body.keyframe_insert("rotation_euler", frame=frame)
        targets = []
        for name, x in (("L", -2.38), ("R", -2.62)):
            e = bpy.data.objects.new("turner_IK_" + name, None)
            scene.collection.objects.link(e)
            e.location = (x, -3.5, 0.0)
            targets.append(e)
        scene.frame_set(1)
        self.select(targets + [body], body)
        self.assertEqual(bpy.ops.footfall.character_setup(
            character_file=os.path.join(CHARACTERS, "biped.json"), mode="PICK", name="turner"),
            {"FINISHED"})
        self.assertEqual(body.rotation_mode, "ZXY")
        rig = bpy.data.objects["turner_rig"]
        feet = {f.name: f.target for f in rig.footfall_rig.feet}
        settings = scene.footfall
        settings.rig, settings.start_frame = rig, 1
        self.select([rig], rig)  # the rig of the active object is keyed
        for steps in (6, 4):  # the second walk clears the first's Euler keys after its end
            settings.steps = steps
            self.assertEqual(bpy.ops.footfall.generate_walk(chunk_steps=2), {"FINISHED"})
            walk, _ = self.cli_walk(rig, steps, "turner_%d" % steps)
            self.assertEqual(body.rotation_mode, "ZXY")
            paths = {fc.data_path for fc in body.animation_data.action.fcurves}
            self.assertEqual(paths, {"location", "rotation_euler"})
            keys = fcurve_keys(body, "rotation_euler", 3)
            body_frames = [float(k["frame"]) for t in walk["tracks"] if t["kind"] == "body"
                           for k in t["keys"]]
            self.assertEqual(sorted(keys), sorted(list(user) + body_frames))
            for frame, angles in user.items():  # the user's keys before and after the walk stay
                for g, w in zip(keys[frame], angles):
                    self.assertAlmostEqual(g, w, delta=TOL)
            # Each key's angles near the one before (no turn of 360 degrees between keys:
            # the walk faces +Y, where angles from -pi to pi wrap).
            frames = sorted(keys)
            for a, b in zip(frames, frames[1:]):
                for u, v in zip(keys[a], keys[b]):
                    self.assertLess(abs(u - v), 1.0, "Euler keys %s -> %s: %s -> %s"
                                    % (a, b, keys[a], keys[b]))
            self.assert_keys_equal_walk(walk, feet, body)
            self.assert_world_at_key_frames(walk, feet, body)
        # An axis-angle body is keyed as axis-angle.
        clear_animation([body] + targets)
        body.rotation_mode = "AXIS_ANGLE"
        self.assertEqual(bpy.ops.footfall.generate_walk(chunk_steps=2), {"FINISHED"})
        paths = {fc.data_path for fc in body.animation_data.action.fcurves}
        self.assertEqual(paths, {"location", "rotation_axis_angle"})
        self.assert_keys_equal_walk(walk, feet, body)
        self.assert_world_at_key_frames(walk, feet, body)
        settings.rig = None

    def test_6d_targets_and_body_under_bones(self):
        # IK targets and a body parented to bones (parent type BONE, as riggers put them under
        # a root bone) were keyed as if parented to the armature object: wherever the bone was
        # not at the armature's origin, the feet landed beside the walk.
        scene = bpy.context.scene
        scene.frame_set(1)
        bpy.ops.object.armature_add(location=(0.5, -1.5, 0.2))
        arm = bpy.context.active_object
        arm.name = "boner_armature"
        arm.rotation_euler = (0.0, 0.0, 0.35)
        arm.scale = (1.1, 1.1, 1.1)
        bpy.ops.object.mode_set(mode="EDIT")
        root = arm.data.edit_bones[0]
        root.name = "root"
        root.head, root.tail, root.roll = (0.2, -0.3, 0.1), (0.3, 0.2, 0.5), 0.4
        ctrl = arm.data.edit_bones.new("ctrl")
        ctrl.head, ctrl.tail, ctrl.roll = (-0.4, 0.1, 0.0), (-0.4, 0.1, 0.7), -0.2
        bpy.ops.object.mode_set(mode="OBJECT")
        arm.data.bones["ctrl"].use_relative_parent = True  # children take the bone's channel
        pose = arm.pose.bones
        pose["root"].location = (0.1, -0.2, 0.05)
        pose["root"].rotation_quaternion = Euler((0.1, -0.05, 0.3)).to_quaternion()
        pose["ctrl"].location = (0.05, 0.1, -0.1)
        pose["ctrl"].rotation_quaternion = Euler((0.0, 0.1, -0.2)).to_quaternion()
        bpy.context.view_layer.update()

        def under_bone(obj, bone):
            obj.parent, obj.parent_type, obj.parent_bone = arm, "BONE", bone
        body = bpy.data.objects.new("boner_body", None)
        scene.collection.objects.link(body)
        under_bone(body, "root")
        targets = {}
        for name in ("L", "R"):
            targets[name] = bpy.data.objects.new("boner_IK_" + name, None)
            scene.collection.objects.link(targets[name])
        targets["L"].parent = body  # a foot under the body under a bone
        under_bone(targets["R"], "ctrl")
        bpy.context.view_layer.update()
        body.matrix_world = Matrix.Translation((0.6, -1.2, 1.0)) @ Euler((0, 0, math.pi)).to_matrix().to_4x4()
        for name, x in (("L", 0.72), ("R", 0.48)):
            targets[name].matrix_world = Matrix.Translation((x, -1.2, 0.0))
        bpy.context.view_layer.update()
        self.select(list(targets.values()) + [body], body)
        self.assertEqual(bpy.ops.footfall.character_setup(
            character_file=os.path.join(CHARACTERS, "biped.json"), mode="PICK", name="boner"),
            {"FINISHED"})
        rig = bpy.data.objects["boner_rig"]
        feet = {f.name: f.target for f in rig.footfall_rig.feet}
        self.assertEqual(feet, targets)
        settings = scene.footfall
        settings.rig, settings.steps, settings.start_frame = rig, 6, 1
        self.select([rig], rig)  # the rig of the active object is keyed
        # A static pose: the bones' matrices are read once.
        self.assertEqual(bpy.ops.footfall.generate_walk(chunk_steps=2), {"FINISHED"})
        walk = json.loads(bpy.data.texts["footfall_walk.json"].as_string())
        self.assertEqual(walk, self.cli_walk(rig, 6, "boner_cli")[0])
        self.assert_world_at_key_frames(walk, feet, body, tol=1e-5)
        # The bones animated in the armature's action: evaluated at each key's frame, as
        # animated object parents are; Import keys the same way.
        for frame, angle in ((1, 0.3), (40, -0.2), (80, 0.5)):
            pose["root"].location = (0.1, -0.2 + 0.004 * frame, 0.05)
            pose["root"].rotation_quaternion = Euler((0.1, -0.05, angle)).to_quaternion()
            pose["ctrl"].location = (0.05, 0.1 + 0.002 * frame, -0.1)
            for bone in ("root", "ctrl"):
                pose[bone].keyframe_insert("location", frame=frame)
                pose[bone].keyframe_insert("rotation_quaternion", frame=frame)
        scene.frame_set(30)
        self.assertEqual(bpy.ops.footfall.generate_walk(chunk_steps=2), {"FINISHED"})
        self.assertEqual(scene.frame_current, 30)
        self.assert_world_at_key_frames(walk, feet, body, tol=1e-5)
        clear_animation(list(feet.values()) + [body])
        self.assertEqual(bpy.ops.footfall.import_walk(
            filepath=os.path.join(ARGS.work_dir, "boner_cli.json")), {"FINISHED"})
        self.assert_world_at_key_frames(walk, feet, body, tol=1e-5)
        settings.rig = None
        scene.frame_set(1)

    def test_6e_parents_that_cannot_be_keyed_are_refused(self):
        # A target hanging from a vertex, or from a curve whose Path Animation moves it along
        # the path, was keyed as if parented to the object: a report now, nothing changed.
        scene = bpy.context.scene
        scene.frame_set(1)
        rig, feet, body = rig_feet_body("boner_rig")
        target = feet["R"]
        saved = (target.parent, target.parent_type, target.parent_bone,
                 target.matrix_world.copy())
        bpy.ops.mesh.primitive_cube_add(size=0.2, location=(0.5, -1.2, 0.3))
        cube = bpy.context.active_object
        bpy.ops.curve.primitive_bezier_curve_add(location=(0.5, -1.0, 0.0))
        curve = bpy.context.active_object
        self.assertTrue(curve.data.use_path)
        scene.footfall.rig, scene.footfall.steps = rig, 6
        self.select([rig], rig)  # the rig of the active object is keyed
        path = os.path.join(ARGS.work_dir, "boner_cli.json")
        objects = list(feet.values()) + [body]
        for parent, kind, message in ((cube, "VERTEX", "parented to a vertex of Cube"),
                                      (cube, "VERTEX_3", "parented to three vertices of Cube"),
                                      (curve, "OBJECT", "Path Animation")):
            target.parent, target.parent_type = parent, kind
            if kind.startswith("VERTEX"):
                target.parent_vertices = (0, 1, 2)
            bpy.context.view_layer.update()
            before = {o.name: fcurve_keys(o, "location", 3) for o in objects}
            with self.assertRaises(RuntimeError) as e:
                bpy.ops.footfall.generate_walk(chunk_steps=2)
            self.assertIn(message, str(e.exception))
            self.assertIn("the rig's keys are unchanged", str(e.exception))
            with self.assertRaises(RuntimeError) as e:
                bpy.ops.footfall.import_walk(filepath=path)
            self.assertIn(message, str(e.exception))
            self.assertEqual({o.name: fcurve_keys(o, "location", 3) for o in objects}, before)
        # Without Path Animation a curve is an object parent like any other.
        curve.data.use_path = False
        target.matrix_world = saved[3]
        bpy.context.view_layer.update()
        self.assertEqual(bpy.ops.footfall.generate_walk(chunk_steps=2), {"FINISHED"})
        walk = json.loads(bpy.data.texts["footfall_walk.json"].as_string())
        self.assert_world_at_key_frames(walk, feet, body, tol=1e-5)
        # Targets sharing one action (Duplicate Linked): each played both feet's keys, one
        # mixed track, and the walk said it had succeeded.
        own = feet["L"].animation_data.action
        feet["L"].animation_data.action = feet["R"].animation_data.action
        try:
            before = {o.name: fcurve_keys(o, "location", 3) for o in objects}
            for run in (lambda: bpy.ops.footfall.generate_walk(chunk_steps=2),
                        lambda: bpy.ops.footfall.import_walk(filepath=path)):
                with self.assertRaises(RuntimeError) as e:
                    run()
                self.assertIn("share the action", str(e.exception))
                self.assertEqual({o.name: fcurve_keys(o, "location", 3) for o in objects}, before)
        finally:
            feet["L"].animation_data.action = own
        target.parent, target.parent_type, target.parent_bone = saved[:3]
        target.matrix_world = saved[3]
        for obj in (cube, curve):
            bpy.data.objects.remove(obj)
        scene.footfall.rig = None

    def test_6e2_delta_transforms_and_own_constraints(self):
        # A Delta Location on a target floated every foot key by it, and a Delta Rotation on the
        # body turned it by it; a constraint on a target itself (Child Of, Copy Location) put its
        # keys metres off the walk, reported as done.
        scene = bpy.context.scene
        scene.frame_set(1)
        rig, feet, body = rig_feet_body("biped_rig")
        target = feet["L"]
        scene.footfall.rig, scene.footfall.steps, scene.footfall.start_frame = rig, 6, 1
        self.select([rig], rig)  # the rig of the active object is keyed
        target.delta_location = (0.0, 0.0, 0.5)
        body.delta_rotation_euler = (0.0, 0.0, math.radians(30))
        scene.render.fps, scene.render.fps_base = 30, 1.001  # recorded in the walk (it said 24)
        try:
            self.assertEqual(bpy.ops.footfall.generate_walk(chunk_steps=2), {"FINISHED"})
            walk = json.loads(bpy.data.texts["footfall_walk.json"].as_string())
            self.assert_world_at_key_frames(walk, feet, body, tol=1e-5)
            self.assertAlmostEqual(walk["fps"], 30 / 1.001, delta=1e-5)  # fps_base: a float32
        finally:
            target.delta_location = (0.0, 0.0, 0.0)
            body.delta_rotation_euler = (0.0, 0.0, 0.0)
            scene.render.fps, scene.render.fps_base = 24, 1.0
        control = new_empty("constraint_control", location=(0.3, 0.2, 0.0))
        objects = list(feet.values()) + [body]
        for kind, shown in (("CHILD_OF", "Child Of"), ("COPY_LOCATION", "Copy Location")):
            c = target.constraints.new(kind)
            c.target = control
            bpy.context.view_layer.update()
            before = {o.name: fcurve_keys(o, "location", 3) for o in objects}
            with self.assertRaises(RuntimeError) as e:
                bpy.ops.footfall.generate_walk(chunk_steps=2)
            self.assertIn("has a %s constraint" % shown, str(e.exception))
            self.assertEqual({o.name: fcurve_keys(o, "location", 3) for o in objects}, before)
            c.mute = True  # a muted constraint moves nothing
            self.assertEqual(bpy.ops.footfall.generate_walk(chunk_steps=2), {"FINISHED"})
            target.constraints.remove(c)
        bpy.data.objects.remove(control)
        scene.footfall.rig = None

    def test_6e3_picked_objects_with_blenders_number_suffix(self):
        # Use Selected refused the body and IK targets of any second rig (biped_L.001) and
        # Shift+D duplicates: "no selected object named after foot L, R".
        with open(os.path.join(CHARACTERS, "biped.json")) as f:
            names = [foot["name"] for foot in json.load(f)["feet"]]
        body = new_empty("suffix_body", location=(1.0, 2.5, 1.0))
        new_empty("suffix_IK_" + names[0], location=(1.2, 2.5, 0.0))  # taken: the next are .001
        targets = [new_empty("suffix_IK_" + n, location=(1.0 + (0.2 if i == 0 else -0.2), 2.5, 0.0))
                   for i, n in enumerate(names)]
        self.assertTrue(targets[0].name.endswith(".001"))
        self.select(targets + [body], body)
        self.assertEqual(bpy.ops.footfall.character_setup(
            character_file=os.path.join(CHARACTERS, "biped.json"), mode="PICK",
            name="suffix"), {"FINISHED"})
        rig = bpy.context.scene.footfall.rig
        self.assertEqual({f.name: f.target for f in rig.footfall_rig.feet},
                         dict(zip(names, targets)))

    def test_6f_feet_under_the_body_keyed_again_only_where_it_changed(self):
        # Feet under the body were keyed again over the whole walk at each chunk, the scene
        # stepped through all their frames so far at each chunk (4830 frames for a walk of 400
        # steps with 1200 frames keyed: seconds in a heavy scene). They are keyed again only
        # from where the body's new keys changed its curve, with the same keys to the bit.
        scene = bpy.context.scene
        scene.frame_set(1)
        control = new_empty("stepper_control")
        control.keyframe_insert("location", frame=1)
        control.location = (0.2, 0.3, 0.05)
        control.keyframe_insert("location", frame=150)
        scene.frame_set(1)
        body = new_empty("stepper_body", control, (-1.0, -4.3, 1.0))
        body.rotation_euler = (0.0, 0.0, math.pi)  # faces +Y
        targets = []
        for name, x in (("L", 0.12), ("R", -0.12)):
            e = bpy.data.objects.new("stepper_IK_" + name, None)
            scene.collection.objects.link(e)
            e.parent = body
            e.location = (x, 0.0, -1.0)
            targets.append(e)
        bpy.context.view_layer.update()
        self.select(targets + [body], body)
        self.assertEqual(bpy.ops.footfall.character_setup(
            character_file=os.path.join(CHARACTERS, "biped.json"), mode="PICK", name="stepper"),
            {"FINISHED"})
        rig = bpy.data.objects["stepper_rig"]
        feet = {f.name: f.target for f in rig.footfall_rig.feet}
        settings = scene.footfall
        settings.rig, settings.steps, settings.start_frame = rig, 16, 1
        self.select([rig], rig)  # the rig of the active object is keyed

        def keys():
            """Every key of the feet and the body: frames, values and handles."""
            out = {}
            for obj in targets + [body]:
                for fc in obj.animation_data.action.fcurves:
                    out[(obj.name, fc.data_path, fc.array_index)] = [
                        (tuple(k.co), tuple(k.handle_left), tuple(k.handle_right))
                        for k in fc.keyframe_points]
            return out
        steps = []

        def count(*_):
            steps.append(scene.frame_current)
        edit = bpy.context.preferences.edit
        saved = edit.fcurve_new_auto_smoothing
        bpy.app.handlers.frame_change_post.append(count)
        try:
            # Blender's default smoothing of new F-curves (continuous acceleration: a new key
            # moves the handles of a dozen keys before it, by less and less, down to the last
            # bit of a float, so chunks of 2 steps save little) and none (a new key moves the
            # handles of the key before it only).
            for smoothing in ("CONT_ACCEL", "NONE"):
                edit.fcurve_new_auto_smoothing = smoothing
                clear_animation(targets + [body])
                del steps[:]
                self.assertEqual(bpy.ops.footfall.generate_walk(chunk_steps=16), {"FINISHED"})
                whole, whole_steps = keys(), len(steps)
                del steps[:]
                self.assertEqual(bpy.ops.footfall.generate_walk(chunk_steps=2), {"FINISHED"})
                chunked_steps = len(steps)
                self.assertEqual(body.animation_data.action.fcurves[0].auto_smoothing, smoothing)
                self.assertEqual(keys(), whole)  # in 8 chunks, the same keys as in 1, to the bit
                walk = json.loads(bpy.data.texts["footfall_walk.json"].as_string())
                self.assert_world_at_key_frames(walk, feet, body, tol=1e-5)
                # One chunk: the body's frames, then the feet's (each frame once for both), and
                # back to the frame it was on.
                frames = {t["kind"]: set() for t in walk["tracks"]}
                for t in walk["tracks"]:
                    frames[t["kind"]].update(k["frame"] for k in t["keys"])
                self.assertEqual(whole_steps, len(frames["body"]) + len(frames["foot"]) + 1)
                # Eight: the feet's frames again only from where the body's curve changed (they
                # were all stepped through again at each chunk: 184 frames, either smoothing).
                print("%s: frames stepped through: %d for the walk in one chunk, %d in eight"
                      % (smoothing, whole_steps, chunked_steps))
                if smoothing == "NONE":
                    self.assertLess(chunked_steps, 1.9 * whole_steps)
        finally:
            bpy.app.handlers.frame_change_post.remove(count)
            edit.fcurve_new_auto_smoothing = saved
        self.assertEqual(walk, self.cli_walk(rig, 16, "stepper_cli")[0])
        settings.rig = None
        scene.frame_set(1)

    def test_6g_a_walks_notes_and_its_stop_reach_the_animator(self):
        # The notes `footfall generate` prints (a step length beyond the reach, a start far
        # from the terrain) were never shown in Blender: warning reports now. A walk that stops
        # at the terrain's edge reports why, and its keys so far stay.
        rig, feet, body, settings = self.biped_walk_setup(4)
        home = rig.location.copy()
        try:
            result, error, reports = run_reporting(bpy.ops.footfall.generate_walk)
            self.assertEqual((result, error), ({"FINISHED"}, None))
            self.assertEqual([r for r in reports if r.startswith("Warning")], [])
            settings.step_length = 5.0  # the biped's reach 1.2 lets a foot travel about 2.9
            result, error, reports = run_reporting(bpy.ops.footfall.generate_walk)
            self.assertEqual((result, error), ({"FINISHED"}, None))
            notes = [r for r in reports if r.startswith("Warning: footfall: note: ")]
            self.assertEqual(len(notes), 1, reports)  # no position: no word on the frame
            self.assertIn("step_length 5 is longer than reach 1.2", notes[0])
            self.assertEqual(reports[-1], notes[-1])  # last: the status bar shows it
            settings.step_length = 0.0
            rig.location.x += 30.0  # 25 m beyond the terrain's edge
            bpy.context.view_layer.update()
            result, error, reports = run_reporting(bpy.ops.footfall.generate_walk)
            self.assertEqual((result, error), ({"FINISHED"}, None))
            notes = [r for r in reports if r.startswith("Warning: footfall: note: ")]
            self.assertEqual(len(notes), 2, reports)
            self.assertIn("snaps to the terrain's sample nearest it", notes[0])
            # Its positions are footfall's: the last note says how to read them in Blender.
            self.assertIn("is Blender's (x, -z, y) divided by the scene's Unit Scale", notes[1])
            start = to_ff(rig.matrix_world.translation)
            self.assertIn("the start (%.4f, %.4f, %.4f)" % start, notes[0])
            rig.location = home
            bpy.context.view_layer.update()
            # 200 steps walk off the 10 m terrain: the stop is an error report naming why and
            # the keys kept, and the keys up to the stop are there.
            clear_animation(list(feet.values()) + [body])
            settings.steps = 200
            result, error, reports = run_reporting(bpy.ops.footfall.generate_walk)
            self.assertIsNotNone(error, reports)
            walk = json.loads(bpy.data.texts["footfall_walk.json"].as_string())
            self.assertTrue(walk.get("stopped"), walk.keys())
            self.assertIn(walk["stopped"], str(error))
            self.assertIn("(no_foothold)", str(error))
            kept = sum(len(t["keys"]) for t in walk["tracks"])
            self.assertIn("; the %d keys made up to frame " % kept, str(error))
            self.assertTrue(reports[-1].startswith("Error: footfall: "), reports)
            # Its position is footfall's too: a note before it says how to read it.
            self.assertRegex(walk["stopped"], r"\(-?[0-9.]+, -?[0-9.]+, -?[0-9.]+\)")
            self.assertIn("is Blender's (x, -z, y) divided by the scene's Unit Scale",
                          reports[-2])
            self.assert_keys_equal_walk(walk, feet, body)
        finally:
            settings.step_length = 0.0
            rig.location = home
            bpy.context.view_layer.update()
        self._generate_and_compare("biped_rig", 8)  # as the tests after this one expect it

    def test_7_import_json_walk(self):
        path = os.path.join(ARGS.work_dir, "hexapod_rig_cli.json")
        with open(path) as f:
            walk = json.load(f)
        bpy.context.scene.footfall.rig = None
        self.select([], None)
        self.assertEqual(bpy.ops.footfall.import_walk(filepath=path), {"FINISHED"})
        feet = {t["name"]: bpy.data.objects["hexapod_rig_cli_" + t["name"]]
                for t in walk["tracks"] if t["kind"] == "foot"}
        self.assert_keys_equal_walk(walk, feet, bpy.data.objects["hexapod_rig_cli_body"])
        with self.assertRaises(RuntimeError) as e:
            bpy.ops.footfall.import_walk(filepath=os.path.join(ARGS.work_dir, "none.json"))
        self.assertIn("cannot import", str(e.exception))
        # A walk that says its unit (footfall generate --unit cm) is keyed at its size: the
        # same keys as the walk in metres (it was taken for metres, 100 times too large).
        in_cm = dict(walk, unit="cm", tracks=[
            dict(t, keys=[dict(k, position=[v * 100 for v in k["position"]]) for k in t["keys"]])
            for t in walk["tracks"]])
        cm_path = os.path.join(ARGS.work_dir, "hexapod_cm.json")
        with open(cm_path, "w") as f:
            json.dump(in_cm, f)
        self.assertEqual(bpy.ops.footfall.import_walk(filepath=cm_path), {"FINISHED"})
        feet = {t["name"]: bpy.data.objects["hexapod_cm_" + t["name"]]
                for t in walk["tracks"] if t["kind"] == "foot"}
        self.assert_keys_equal_walk(walk, feet, bpy.data.objects["hexapod_cm_body"])
        with open(cm_path, "w") as f:
            json.dump(dict(in_cm, unit="furlong"), f)
        with self.assertRaises(RuntimeError) as e:
            bpy.ops.footfall.import_walk(filepath=cm_path)
        self.assertIn("unit: expected one of mm, cm, m, km, in, ft, yd, mi", str(e.exception))

    def test_7b_failures_keep_what_the_user_has(self):
        rig = bpy.data.objects["biped_rig"]
        feet = {f.name: f.target for f in rig.footfall_rig.feet}
        body = rig.footfall_rig.body
        before = {o.name: fcurve_keys(o, "location", 3) for o in list(feet.values()) + [body]}
        self.assertTrue(all(before.values()))
        bpy.context.scene.footfall.rig = rig
        self.select([rig], rig)  # the rig of the active object is keyed
        settings = bpy.context.scene.footfall

        def generate_refused(setting, value, *messages):
            saved = getattr(settings, setting)
            setattr(settings, setting, value)
            try:
                with self.assertRaises(RuntimeError) as e:
                    bpy.ops.footfall.generate_walk()
                for message in messages + ("the rig's keys are unchanged",):
                    self.assertIn(message, str(e.exception))
            finally:
                setattr(settings, setting, saved)

        # A Generate Walk the generator refuses (frames_per_step 1) cleared the walk first.
        generate_refused("frames_per_step", 1)
        # A walk that would end beyond Blender's frame range: refused before anything is keyed
        # (its first chunk was keyed, the rig's keys cleared, before a later chunk was refused).
        generate_refused("start_frame", 1048570, "beyond Blender's frame range")
        # An import with no track for this rig cleared its keys before finding none.
        other = os.path.join(ARGS.work_dir, "other.json")
        with open(other, "w") as f:
            json.dump({"tracks": [{"name": "X1", "kind": "foot", "keys": [
                {"frame": 1, "position": [0, 0, 0]}]}]}, f)
        with self.assertRaises(RuntimeError) as e:
            bpy.ops.footfall.import_walk(filepath=other)
        self.assertIn("no track for this rig", str(e.exception))
        after = {o.name: fcurve_keys(o, "location", 3) for o in list(feet.values()) + [body]}
        self.assertEqual(after, before)
        # Another character's walk, whose body track alone matched: the rig's feet were cleared
        # and the import said it had keyed 3 keys.
        quadruped = os.path.join(ARGS.work_dir, "quadruped_walk.json")
        with open(quadruped, "w") as f:
            json.dump({"tracks": [
                {"name": n, "kind": "foot", "keys": [{"frame": 1, "position": [0, 0, 0]}]}
                for n in ("LF", "RF", "LH", "RH")] + [
                {"name": "body", "kind": "body", "keys": [
                    {"frame": 1, "position": [0, 1, 0], "rotation": [0, 0, 0, 1]}]}]}, f)
        with self.assertRaises(RuntimeError) as e:
            bpy.ops.footfall.import_walk(filepath=quadruped)
        self.assertIn("keys feet this rig does not have (LF, RF, LH, RH", str(e.exception))
        self.assertIn("the rig's keys are unchanged", str(e.exception))
        after = {o.name: fcurve_keys(o, "location", 3) for o in list(feet.values()) + [body]}
        self.assertEqual(after, before)
        # Tracks of this rig without keys (beside another's keyed track, or alone): its keys
        # were cleared from the walk's first frame (frame 0 when no track had a key) before the
        # import found nothing to key.
        for name, tracks in (("empty_tracks.json", [{"name": "L", "kind": "foot", "keys": []}]),
                             ("empty_rig_tracks.json", [
                                 {"name": "L", "kind": "foot", "keys": []},
                                 {"name": "body", "kind": "body", "keys": []},
                                 {"name": "X1", "kind": "foot", "keys": [
                                     {"frame": 1, "position": [0, 0, 0]}]}])):
            empty = os.path.join(ARGS.work_dir, name)
            with open(empty, "w") as f:
                json.dump({"tracks": tracks}, f)
            with self.assertRaises(RuntimeError) as e:
                bpy.ops.footfall.import_walk(filepath=empty)
            self.assertTrue("has no keys" in str(e.exception) or
                            "no track for this rig" in str(e.exception), str(e.exception))
            after = {o.name: fcurve_keys(o, "location", 3) for o in list(feet.values()) + [body]}
            self.assertEqual(after, before)
        # Character files the generator refuses, and a "name" that is not text: a report, and
        # nothing made (a version 2 file made a whole rig; a numeric name raised TypeError).
        with open(os.path.join(CHARACTERS, "biped.json")) as f:
            data = json.load(f)
        objects = set(bpy.data.objects)
        for change, message in ((("version", 2), "version"),
                                (("frames_per_step", 1), "frames_per_step"),
                                (("name", 5), "'name' must be a string")):
            bad = dict(data)
            bad[change[0]] = change[1]
            path = os.path.join(ARGS.work_dir, "bad_%s.json" % change[0])
            with open(path, "w") as f:
                json.dump(bad, f)
            with self.assertRaises(RuntimeError) as e:
                bpy.ops.footfall.character_setup(character_file=path, mode="CREATE")
            self.assertIn(message, str(e.exception))
            self.assertNotIn("Traceback", str(e.exception))
        self.assertEqual(set(bpy.data.objects), objects)

    def test_7c_import_crowd_walk(self):
        # Each character of a crowd walk gets its own empties (all its tracks were keyed onto
        # one set: the last character's).
        rig = bpy.data.objects["biped_rig"]
        out = os.path.join(ARGS.work_dir, "crowd.json")
        run_cli("generate", "--terrain", self.pts, "--character", rig.footfall_rig.character_path,
                "--start", csv(to_ff(rig.matrix_world.translation)), "--steps", 4,
                "--crowd", 2, "--out", out, "--out", out[:-5] + "_gltf.gltf")
        with open(out) as f:
            walk = json.load(f)
        bpy.context.scene.footfall.rig = None
        self.select([], None)
        self.assertEqual(bpy.ops.footfall.import_walk(filepath=out), {"FINISHED"})
        for who in ("c1", "c2"):
            part = {"tracks": [t for t in walk["tracks"] if t["character"] == who]}
            feet = {t["name"]: bpy.data.objects["crowd_%s_%s" % (who, t["name"])]
                    for t in part["tracks"] if t["kind"] == "foot"}
            self.assert_keys_equal_walk(part, feet, bpy.data.objects["crowd_%s_body" % who])
        # The same walk as glTF: its nodes name their character (the tracks were mixed onto
        # one set of empties).
        self.assertEqual(bpy.ops.footfall.import_walk(filepath=out[:-5] + "_gltf.gltf"),
                         {"FINISHED"})
        for who in ("c1", "c2"):
            part = {"tracks": [t for t in walk["tracks"] if t["character"] == who]}
            feet = {t["name"]: bpy.data.objects["crowd_gltf_%s_%s" % (who, t["name"])]
                    for t in part["tracks"] if t["kind"] == "foot"}
            self.assert_keys_equal_walk(part, feet, bpy.data.objects["crowd_gltf_%s_body" % who])
        # Onto a rig: refused, nothing changed.
        bpy.context.scene.footfall.rig = rig
        self.select([rig], rig)  # the rig of the active object is keyed
        for path in (out, out[:-5] + "_gltf.gltf"):
            with self.assertRaises(RuntimeError) as e:
                bpy.ops.footfall.import_walk(filepath=path)
            self.assertIn("a crowd walk (2 characters)", str(e.exception))

    def test_7d_the_active_objects_rig_is_keyed(self):
        # Generate Walk and Import keyed the rig in the Rig field (the one Character Setup made
        # last) whichever rig's object was active, and Import with nothing active keyed it too.
        settings = bpy.context.scene.footfall
        hexapod, biped = bpy.data.objects["hexapod_rig"], bpy.data.objects["biped_rig"]
        feet = {f.name: f.target for f in hexapod.footfall_rig.feet}
        body = hexapod.footfall_rig.body
        others = [f.target for f in biped.footfall_rig.feet] + [biped.footfall_rig.body]
        before = {o.name: fcurve_keys(o, "location", 3) for o in others}
        clear_animation(list(feet.values()) + [body])
        settings.rig, settings.steps, settings.start_frame = biped, 6, 1
        self.select([feet["L1"]], feet["L1"])  # one of the hexapod's IK targets
        self.assertEqual(bpy.ops.footfall.generate_walk(), {"FINISHED"})
        walk, path = self.cli_walk(hexapod, 6, "hexapod_active")
        self.assert_keys_equal_walk(walk, feet, body)
        clear_animation(list(feet.values()) + [body])
        self.select([body], body)
        self.assertEqual(bpy.ops.footfall.import_walk(filepath=path), {"FINISHED"})
        self.assert_keys_equal_walk(walk, feet, body)
        # No rig active: new empties, whatever the Rig field holds.
        self.select([], None)
        objects = set(bpy.data.objects)
        self.assertEqual(bpy.ops.footfall.import_walk(filepath=path), {"FINISHED"})
        made = set(bpy.data.objects) - objects
        self.assertEqual(sorted(o.name for o in made), sorted(
            "hexapod_active_" + n for n in list(feet) + ["body"]))
        for obj in made:
            bpy.data.objects.remove(obj)
        self.assertEqual({o.name: fcurve_keys(o, "location", 3) for o in others}, before)

    def test_7e_a_deleted_rig_is_a_report(self):
        # Deleted objects stay in bpy.data while the rig's properties refer to them: Generate
        # Walk keyed them and reported success.
        settings = bpy.context.scene.footfall
        bpy.context.scene.cursor.location = (3.0, -1.0, 0.0)
        self.assertEqual(bpy.ops.footfall.character_setup(
            character_file=os.path.join(CHARACTERS, "biped.json"), mode="CREATE", name="doomed"),
            {"FINISHED"})
        rig = bpy.data.objects["doomed_rig"]
        feet = {f.name: f.target for f in rig.footfall_rig.feet}
        body = rig.footfall_rig.body
        settings.steps, settings.start_frame = 4, 1
        self.select([feet["L"]], feet["L"])
        bpy.ops.object.delete()
        self.select([rig], rig)
        with self.assertRaises(RuntimeError) as e:
            bpy.ops.footfall.generate_walk()
        self.assertIn("foot L's IK target of doomed_rig (doomed_L) is no longer in the scene",
                      str(e.exception))
        with self.assertRaises(RuntimeError) as e:
            bpy.ops.footfall.import_walk(
                filepath=os.path.join(ARGS.work_dir, "biped_rig_cli.json"))
        self.assertIn("(doomed_L) is no longer in the scene", str(e.exception))
        self.select([rig, body, feet["R"]], rig)
        bpy.ops.object.delete()
        self.select([], None)
        self.assertIs(settings.rig, rig)  # (the Rig field still refers to it)
        with self.assertRaises(RuntimeError) as e:
            bpy.ops.footfall.generate_walk()
        self.assertIn("the rig doomed_rig is not in this scene (deleted from it, or another "
                      "scene's): run Character Setup here", str(e.exception))
        for obj in list(feet.values()) + [body]:
            self.assertEqual(fcurve_keys(obj, "location", 3), {}, obj.name)
        settings.rig = None
        # A body removed from the file (the rig's pointer then None): the feet alone were keyed,
        # reported as done.
        bpy.context.scene.cursor.location = (3.0, 1.0, 0.0)
        self.assertEqual(bpy.ops.footfall.character_setup(
            character_file=os.path.join(CHARACTERS, "biped.json"), mode="CREATE",
            name="bodiless"), {"FINISHED"})
        rig = bpy.data.objects["bodiless_rig"]
        feet = {f.name: f.target for f in rig.footfall_rig.feet}
        bpy.data.objects.remove(rig.footfall_rig.body)
        self.assertIsNone(rig.footfall_rig.body)
        self.select([rig], rig)
        with self.assertRaises(RuntimeError) as e:
            bpy.ops.footfall.generate_walk()
        self.assertIn("the body of bodiless_rig is no longer in the file: run Character Setup",
                      str(e.exception))
        for obj in feet.values():
            self.assertEqual(fcurve_keys(obj, "location", 3), {}, obj.name)
        settings.rig = None

    def test_7f_a_beveled_path_is_its_centre_line(self):
        # A path curve with Bevel Depth or Extrude was sent as its tube's (or ribbon's) vertices.
        settings = bpy.context.scene.footfall
        rig = bpy.data.objects["biped_rig"]
        data = bpy.data.curves.new("bevelled_path", "CURVE")
        data.dimensions = "3D"
        spline = data.splines.new("POLY")
        spline.points.add(2)
        for p, co in zip(spline.points, [(0.0, 3.0, 0.5), (1.0, 1.0, 0.5), (0.0, -1.0, 0.5)]):
            p.co = co + (1.0,)
        path = bpy.data.objects.new("bevelled_path", data)
        bpy.context.scene.collection.objects.link(path)
        settings.path = path
        try:
            bpy.context.view_layer.update()
            plain = self.ops.walk_request(bpy.context, rig, 4, 1)["path"]
            self.assertEqual(len(plain), 3)
            counts = (len(bpy.data.objects), len(bpy.data.curves))
            for setting in ("bevel_depth", "extrude"):
                setattr(data, setting, 0.3)
                bpy.context.view_layer.update()
                self.assertEqual(self.ops.walk_request(bpy.context, rig, 4, 1)["path"], plain,
                                 setting)
                setattr(data, setting, 0.0)
            self.assertEqual((len(bpy.data.objects), len(bpy.data.curves)), counts)
        finally:
            settings.path = None
            bpy.data.objects.remove(path)
            bpy.data.curves.remove(data)

    def test_7f1_a_path_is_walked_as_its_modifiers_leave_it(self):
        # A Hook on a path's end point drags it where the viewport draws it; the path was read
        # without its modifiers, and the walk went to the end the Hook had moved away.
        data = bpy.data.curves.new("hooked_path", "CURVE")
        data.dimensions = "3D"
        spline = data.splines.new("POLY")
        spline.points.add(1)
        for p, co in zip(spline.points, [(-1.0, 0.0, 0.0), (1.0, 0.0, 0.0)]):
            p.co = co + (1.0,)
        path = bpy.data.objects.new("hooked_path", data)
        hook = bpy.data.objects.new("hook_target", None)
        for o in (path, hook):
            bpy.context.scene.collection.objects.link(o)
        modifier = path.modifiers.new("Hook", "HOOK")
        modifier.object = hook
        modifier.vertex_indices_set([1])
        hook.location = (0.0, -3.0, 0.0)
        try:
            bpy.context.view_layer.update()
            dg = bpy.context.evaluated_depsgraph_get()
            shown = path.evaluated_get(dg).to_mesh()
            end = path.matrix_world @ shown.vertices[1].co
            path.evaluated_get(dg).to_mesh_clear()
            self.assertLess((end - Vector((1.0, -3.0, 0.0))).length, 1e-5)
            counts = (len(bpy.data.objects), len(bpy.data.curves), len(bpy.data.meshes))
            pts = self.ops.curve_points(bpy.context, path)
            self.assertEqual(len(pts), 2)
            self.assertLess((pts[0] - Vector((-1.0, 0.0, 0.0))).length, 1e-5)
            self.assertLess((pts[-1] - end).length, 1e-5)
            self.assertEqual((len(bpy.data.objects), len(bpy.data.curves), len(bpy.data.meshes)),
                             counts)
        finally:
            bpy.data.objects.remove(path)
            bpy.data.objects.remove(hook)
            bpy.data.curves.remove(data)

    def test_7f1b_a_path_its_modifiers_draw_as_two_lines_is_refused(self):
        # A Mirror drew the path as two lines in a V; the walk went out along one and came back
        # across the gap along the other.
        data = bpy.data.curves.new("mirrored_path", "CURVE")
        data.dimensions = "3D"
        spline = data.splines.new("POLY")
        spline.points.add(1)
        for p, co in zip(spline.points, [(0.5, 0.0, 0.0), (2.0, 2.0, 0.0)]):
            p.co = co + (1.0,)
        path = bpy.data.objects.new("mirrored_path", data)
        bpy.context.scene.collection.objects.link(path)
        path.modifiers.new("Mirror", "MIRROR")
        try:
            bpy.context.view_layer.update()
            with self.assertRaises(ValueError) as e:
                self.ops.curve_points(bpy.context, path)
            self.assertIn("is drawn as 2 separate lines by its modifiers (Mirror)", str(e.exception))
            path.modifiers.clear()
            self.assertEqual(len(self.ops.curve_points(bpy.context, path)), 2)
        finally:
            bpy.data.objects.remove(path)
            bpy.data.curves.remove(data)

    def test_7f3_targets_whose_keys_would_not_act_or_not_be_saved_are_refused(self):
        # A driver on a target's own location beat its keys (the body stood 0.5 m off its
        # walk), and keys on an object linked from another file were lost on saving.
        import footfall_blender.keying as keying
        target = bpy.data.objects.new("driven_target", None)
        bpy.context.scene.collection.objects.link(target)
        try:
            driver = target.driver_add("location", 2)
            driver.driver.expression = "0.5"
            with self.assertRaises(ValueError) as e:
                keying.check_parents([target])
            self.assertIn("driven_target has a driver on its location[2]", str(e.exception))
            driver.mute = True
            keying.check_parents([target])  # a muted driver does not act
            target.driver_remove("location", 2)
            # Linked from a library file written here.
            path = os.path.join(ARGS.work_dir, "library_%d.blend" % os.getpid())
            bpy.data.libraries.write(path, {target})
            with bpy.data.libraries.load(path, link=True) as (source, linked):
                linked.objects = ["driven_target"]
            foreign = linked.objects[0]
            self.assertIsNotNone(foreign.library)
            with self.assertRaises(ValueError) as e:
                keying.check_parents([foreign])
            self.assertIn("is linked from", str(e.exception))
            self.assertIn("make a library override", str(e.exception))
            library = foreign.library
            bpy.data.objects.remove(foreign)
            bpy.data.libraries.remove(library)
        finally:
            bpy.data.objects.remove(target)

    def test_7f2_a_filled_2d_path_is_its_outline_and_a_deleted_one_is_a_report(self):
        # A closed 2D curve with a fill was walked along its fill's inner edges (186 waypoints,
        # jumps of 6 m); a path deleted from the scene was still followed.
        settings = bpy.context.scene.footfall
        rig = bpy.data.objects["biped_rig"]
        bpy.ops.curve.primitive_bezier_circle_add(radius=3.0, location=(0.0, 0.0, 0.5))
        path = bpy.context.active_object
        path.data.dimensions = "2D"
        settings.path = path
        try:
            path.data.fill_mode = "NONE"
            bpy.context.view_layer.update()
            outline = self.ops.walk_request(bpy.context, rig, 4, 1)["path"]
            for mode in ("BOTH", "FRONT", "BACK"):
                path.data.fill_mode = mode
                bpy.context.view_layer.update()
                self.assertEqual(self.ops.walk_request(bpy.context, rig, 4, 1)["path"], outline,
                                 mode)
            bpy.ops.object.select_all(action="DESELECT")
            path.select_set(True)
            bpy.context.view_layer.objects.active = path
            bpy.ops.object.delete()
            with self.assertRaises(ValueError) as e:
                self.ops.walk_request(bpy.context, rig, 4, 1)
            self.assertIn("is not in this scene (deleted from it, or another scene's)",
                          str(e.exception))
        finally:
            settings.path = None

    def test_7h_a_path_of_several_splines_is_refused(self):
        # A path curve of several splines was walked as one line, jumping from the end of one
        # spline to the start of the next: a report now, before anything is keyed.
        settings = bpy.context.scene.footfall
        rig = bpy.data.objects["biped_rig"]
        feet = {f.name: f.target for f in rig.footfall_rig.feet}
        objects = list(feet.values()) + [rig.footfall_rig.body]
        data = bpy.data.curves.new("forked_path", "CURVE")
        data.dimensions = "3D"
        for line in ([(0.0, 3.0, 0.5), (1.0, 1.0, 0.5)], [(3.0, -1.0, 0.5), (2.0, 2.0, 0.5)],
                     [(-2.0, 0.0, 0.5), (-1.0, 1.0, 0.5)]):
            spline = data.splines.new("POLY")
            spline.points.add(len(line) - 1)
            for p, co in zip(spline.points, line):
                p.co = co + (1.0,)
        path = bpy.data.objects.new("forked_path", data)
        bpy.context.scene.collection.objects.link(path)
        saved = (settings.rig, settings.path, settings.steps)
        settings.rig, settings.path, settings.steps = rig, path, 4
        self.select([rig], rig)
        before = {o.name: fcurve_keys(o, "location", 3) for o in objects}
        try:
            bpy.context.view_layer.update()
            with self.assertRaises(RuntimeError) as e:
                bpy.ops.footfall.generate_walk()
            self.assertIn("path curve forked_path has 3 splines, and one spline is expected",
                          str(e.exception))
            self.assertIn("Separate", str(e.exception))
            self.assertIn("the rig's keys are unchanged", str(e.exception))
            self.assertEqual({o.name: fcurve_keys(o, "location", 3) for o in objects}, before)
        finally:
            settings.rig, settings.path, settings.steps = saved
            bpy.data.objects.remove(path)
            bpy.data.curves.remove(data)

    def test_7g_byte_order_marks_and_deep_nesting_in_files(self):
        # A walk or character file starting with a UTF-8 byte order mark was refused (the
        # command line reads it); one nested some thousands of levels deep raised
        # RecursionError through the operator.
        settings = bpy.context.scene.footfall
        path = os.path.join(ARGS.work_dir, "hexapod_rig_cli.json")
        with open(path, "rb") as f:
            text = f.read()
        walk = json.loads(text)
        marked = os.path.join(ARGS.work_dir, "hexapod_bom.json")
        with open(marked, "wb") as f:
            f.write(b"\xef\xbb\xbf" + text)
        saved_rig = settings.rig
        settings.rig = None
        self.select([], None)
        objects = set(bpy.data.objects)
        try:
            self.assertEqual(bpy.ops.footfall.import_walk(filepath=marked), {"FINISHED"})
            feet = {t["name"]: bpy.data.objects["hexapod_bom_" + t["name"]]
                    for t in walk["tracks"] if t["kind"] == "foot"}
            self.assert_keys_equal_walk(walk, feet, bpy.data.objects["hexapod_bom_body"])
            for obj in set(bpy.data.objects) - objects:
                bpy.data.objects.remove(obj)
            with open(os.path.join(CHARACTERS, "biped.json"), "rb") as f:
                character_text = f.read()
            marked_character = os.path.join(ARGS.work_dir, "biped_bom.json")
            with open(marked_character, "wb") as f:
                f.write(b"\xef\xbb\xbf" + character_text)
            bpy.context.scene.cursor.location = (-2.0, -2.0, 0.0)
            self.assertEqual(bpy.ops.footfall.character_setup(
                character_file=marked_character, mode="CREATE", name="marked"), {"FINISHED"})
            self.assertEqual(len(bpy.data.objects["marked_rig"].footfall_rig.feet), 2)
            for obj in set(bpy.data.objects) - objects:
                bpy.data.objects.remove(obj)
            deep = os.path.join(ARGS.work_dir, "deep.json")
            with open(deep, "w") as f:
                f.write('{"tracks": ' + "[" * 100000 + "]" * 100000 + "}")
            with self.assertRaises(RuntimeError) as e:
                bpy.ops.footfall.import_walk(filepath=deep)
            self.assertIn("cannot import %s: %s: nested deeper than 64 levels" % (deep, deep),
                          str(e.exception))
            with self.assertRaises(RuntimeError) as e:
                bpy.ops.footfall.character_setup(character_file=deep, mode="CREATE")
            self.assertIn("nested deeper than 64 levels", str(e.exception))
            self.assertNotIn("Traceback", str(e.exception))
            self.assertEqual(set(bpy.data.objects), objects)
        finally:
            settings.rig = saved_rig

    def test_8_import_gltf_walk(self):
        out = os.path.join(ARGS.work_dir, "biped_cli.gltf")
        rig = bpy.data.objects["biped_rig"]
        mw = rig.matrix_world
        result = subprocess.run(
            [CLI, "generate", "--terrain", self.pts, "--character", rig.footfall_rig.character_path,
             "--start", csv(to_ff(mw.translation)),
             "--heading", csv(to_ff(mw.to_3x3() @ Vector((0, -1, 0)))), "--steps", "8",
             "--out", out, "--out", out[:-5] + ".json"], capture_output=True, text=True)
        if result.returncode != 0 and "unsupported output" in result.stderr:
            print("glTF import NOT TESTED: %s" % result.stderr.strip())
            self.skipTest("this footfall build writes no glTF: " + result.stderr.strip())
        self.assertEqual(result.returncode, 0, result.stderr)
        with open(out[:-5] + ".json") as f:
            walk = json.load(f)
        feet = {f.name: f.target for f in rig.footfall_rig.feet}
        body = rig.footfall_rig.body
        clear_animation(list(feet.values()) + [body])
        bpy.context.scene.footfall.rig = rig
        self.select([rig], rig)  # the rig of the active object is keyed
        # Blender's importer switched a Workbench scene to EEVEE; the user's engine stays.
        render = bpy.context.scene.render
        engine, render.engine = render.engine, "BLENDER_WORKBENCH"
        try:
            self.assertEqual(bpy.ops.footfall.import_walk(filepath=out), {"FINISHED"})
            self.assertEqual(render.engine, "BLENDER_WORKBENCH")
        finally:
            render.engine = engine
        # glTF holds 32-bit floats and times in seconds: the same keys as the JSON walk.
        self.assert_keys_equal_walk(walk, feet, body)

    def test_8a_import_a_far_gltf_walk(self):
        # On a UTM-like terrain footfall's glTF puts the tracks under a root node,
        # footfall_origin, at the walk's origin: the keys read back from the child nodes alone
        # were that far off, and as absolute floats they would move by centimetres.
        shift = (500000.0, 0.0, -300000.0)
        far_pts = os.path.join(ARGS.work_dir, "far_terrain.pts")
        with open(self.pts) as f, open(far_pts, "w") as out:
            for line in f:
                v = line.split()
                if len(v) == 6 and not line.startswith("#"):
                    v[0], v[2] = repr(float(v[0]) + shift[0]), repr(float(v[2]) + shift[2])
                    line = " ".join(v) + "\n"
                out.write(line)
        rig = bpy.data.objects["biped_rig"]
        mw = rig.matrix_world
        start = [c + d for c, d in zip(to_ff(mw.translation), shift)]
        out = os.path.join(ARGS.work_dir, "far_walk.gltf")
        run_cli("generate", "--terrain", far_pts, "--character", rig.footfall_rig.character_path,
                "--start", csv(start), "--heading", csv(to_ff(mw.to_3x3() @ Vector((0, -1, 0)))),
                "--steps", 4, "--out", out, "--out", out[:-5] + ".json")
        with open(out[:-5] + ".json") as f:
            walk = json.load(f)
        with open(out) as f:
            gltf = json.load(f)
        roots = [n for n in gltf["nodes"] if n.get("name") == "footfall_origin"]
        self.assertEqual(len(roots), 1, "the far walk's glTF has a root origin node")
        self.assertNotEqual(roots[0]["translation"], [0, 0, 0])

        # What the add-on reads back, in double: every key within 1e-4 of the JSON walk's.
        read = self.ops.FOOTFALL_OT_import_walk._read_gltf(None, out)
        got = {t["name"]: t for t in read["tracks"]}
        checked = 0
        for track in walk["tracks"]:
            keys = {round(k["frame"]): k["position"] for k in got[track["name"]]["keys"]}
            for k in track["keys"]:
                p = keys[round(k["frame"])]
                self.assertLess(max(abs(a - b) for a, b in zip(p, k["position"])), 1e-4,
                                "%s frame %s: %s vs %s" % (track["name"], k["frame"], p,
                                                           k["position"]))
                self.assertGreater(abs(p[0]), 4e5)
                checked += 1
        self.assertGreater(checked, 8)

        # Imported onto new empties: their world keys are the walk's (to Blender's 32-bit
        # floats, 1/32 apart at 5e5), the root's translation included.
        settings = bpy.context.scene.footfall
        saved_rig = settings.rig
        objects = set(bpy.data.objects)
        try:
            settings.rig = None
            self.select([], None)
            self.assertEqual(bpy.ops.footfall.import_walk(filepath=out), {"FINISHED"})
            self.assertNotIn("footfall_origin", bpy.data.objects)  # the importer's are removed
            for track in walk["tracks"]:
                if track["kind"] != "foot":
                    continue
                keys = fcurve_keys(bpy.data.objects["far_walk_%s" % track["name"]], "location", 3)
                for k in track["keys"]:
                    for g, w in zip(keys[float(k["frame"])], from_ff(k["position"])):
                        self.assertAlmostEqual(g, w, delta=0.02, msg="%s frame %s"
                                               % (track["name"], k["frame"]))
        finally:
            settings.rig = saved_rig
            for obj in set(bpy.data.objects) - objects:
                bpy.data.objects.remove(obj)

    def test_8aa_a_foreign_gltfs_parent_nodes_are_applied(self):
        # A glTF from elsewhere: an animated node under a parent that moves and turns it (90
        # degrees about +Y). Its local keys alone were read as world positions.
        import base64
        import struct
        data = struct.pack("<2f6f", 0.0, 1.0, 1, 0, 0, 1, 0, 1)
        half = math.sqrt(0.5)
        gltf = {
            "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [1]}],
            "nodes": [{"name": "F", "translation": [1, 0, 0]},
                      {"name": "P", "translation": [1, 2, 3], "rotation": [0, half, 0, half],
                       "children": [0]}],
            "buffers": [{"byteLength": len(data), "uri": "data:application/octet-stream;base64,"
                         + base64.b64encode(data).decode()}],
            "bufferViews": [{"buffer": 0, "byteLength": 8},
                            {"buffer": 0, "byteOffset": 8, "byteLength": 24}],
            "accessors": [{"bufferView": 0, "componentType": 5126, "count": 2, "type": "SCALAR",
                           "min": [0], "max": [1]},
                          {"bufferView": 1, "componentType": 5126, "count": 2, "type": "VEC3"}],
            "animations": [{"samplers": [{"input": 0, "output": 1}],
                            "channels": [{"sampler": 0,
                                          "target": {"node": 0, "path": "translation"}}]}]}
        path = os.path.join(ARGS.work_dir, "parented.gltf")
        with open(path, "w") as f:
            json.dump(gltf, f)
        objects = set(bpy.data.objects)
        read = self.ops.FOOTFALL_OT_import_walk._read_gltf(None, path)
        self.assertEqual(set(bpy.data.objects), objects)
        self.assertEqual([t["name"] for t in read["tracks"]], ["F"])
        got = [k["position"] for k in sorted(read["tracks"][0]["keys"], key=lambda k: k["frame"])]
        # The parent turns local (x, y, z) into (z, y, -x), then moves it by (1, 2, 3).
        for p, want in zip(got, [(1, 2, 2), (2, 2, 2)]):
            for g, w in zip(p, want):
                self.assertAlmostEqual(g, w, delta=1e-5, msg="%s vs %s" % (got, want))
        self.assertEqual(len(got), 2)

    def test_8b_a_walk_after_an_import_replaces_it(self):
        # Import left the rig's walk end where it was: a shorter Generate Walk afterwards kept
        # the imported walk's later keys.
        rig, feet, body, settings = self.biped_walk_setup(4)
        _, path = self.cli_walk(rig, 12, "biped_12")
        self.assertEqual(bpy.ops.footfall.import_walk(filepath=path), {"FINISHED"})
        self.assertEqual(bpy.ops.footfall.generate_walk(), {"FINISHED"})
        self.assert_keys_equal_walk(self.cli_walk(rig, 4, "biped_4_after_import")[0], feet, body)

    def path_curve(self, name, points):
        """A poly curve through `points` (Blender world), linked to the scene and set as the
        Path: (object, curve data), for the caller to remove."""
        data = bpy.data.curves.new(name, "CURVE")
        data.dimensions = "3D"
        spline = data.splines.new("POLY")
        spline.points.add(len(points) - 1)
        for point, co in zip(spline.points, points):
            point.co = tuple(co) + (1.0,)
        path = bpy.data.objects.new(name, data)
        bpy.context.scene.collection.objects.link(path)
        bpy.context.scene.footfall.path = path
        return path, data

    def test_8c_keys_after_a_walk_that_ends_early_stay(self):
        # A path walk that reaches its goal long before Steps end: its end was taken as the
        # start plus Steps, and the user's keys up to there were removed (and that end kept for
        # the next walk).
        rig, feet, body, settings = self.biped_walk_setup(40)
        start = body.matrix_world.translation.copy()
        path, data = self.path_curve("short_path", [start, start + Vector((0.0, 2.0, 0.0))])
        user_frame = 400
        try:
            body.keyframe_insert("location", frame=user_frame)
            feet["L"].keyframe_insert("location", frame=user_frame)
            result, error, reports = run_reporting(bpy.ops.footfall.generate_walk)
            self.assertEqual(result, {"FINISHED"}, (error, reports))
            walk = json.loads(bpy.data.texts["footfall_walk.json"].as_string())
            last = max(k["frame"] for t in walk["tracks"] for k in t["keys"])
            self.assertLess(last, user_frame - 50)  # the goal was reached early
            # The steps walked are reported, not the 40 asked.
            walked = len([t for t in walk["tracks"] if t["kind"] == "body"][0]["keys"]) - 1
            self.assertLess(walked, 20)
            self.assertIn("Info: footfall: %d steps (the path's goal reached; 40 asked), "
                          % walked, "\n".join(reports))
            for obj in (body, feet["L"]):
                frames = [kp.co[0] for fc in obj.animation_data.action.fcurves
                          if fc.data_path == "location" for kp in fc.keyframe_points]
                self.assertIn(float(user_frame), frames, obj.name)
            self.assertEqual(rig.footfall_rig.walk_end, last)
        finally:
            settings.path = None
            bpy.data.objects.remove(path)
            bpy.data.curves.remove(data)

    def test_8c1_a_path_curve_of_one_point_is_a_goal(self):
        # A one-point curve was refused ("fewer than 2 points"); the command line takes one
        # waypoint as the goal.
        rig, feet, body, settings = self.biped_walk_setup(40)
        goal = body.matrix_world.translation + Vector((0.0, 2.0, 0.0))
        path, data = self.path_curve("goal_path", [goal])
        try:
            bpy.context.view_layer.update()
            self.assertEqual(len(self.ops.walk_request(bpy.context, rig, 4, 1)["path"]), 1)
            result, error, reports = run_reporting(bpy.ops.footfall.generate_walk)
            self.assertEqual(result, {"FINISHED"}, (error, reports))
            walk = json.loads(bpy.data.texts["footfall_walk.json"].as_string())
            body_keys = [t for t in walk["tracks"] if t["kind"] == "body"][0]["keys"]
            self.assertGreater(len(body_keys), 2)
            # The body ends within a step of the goal, across the ground.
            end = Vector(from_ff(body_keys[-1]["position"]))
            self.assertLess((end - goal).xy.length, 0.8)
        finally:
            settings.path = None
            bpy.data.objects.remove(path)
            bpy.data.curves.remove(data)

    def test_8d_character_setup_again_replaces_the_rig(self):
        # Character Setup again on the same picked body and IK targets made a second rig next
        # to the first: the body then belonged to both, Generate Walk keyed the old one (its
        # start, its character), and picking with the old rig selected too took its central
        # locator (named after both feet) as an IK target.
        with open(os.path.join(CHARACTERS, "biped.json")) as f:
            names = [foot["name"] for foot in json.load(f)["feet"]]
        settings = bpy.context.scene.footfall
        bpy.context.scene.frame_set(1)
        body = new_empty("again_body", location=(2.0, 2.0, 1.0))
        targets = [new_empty("again_IK_" + n, location=(2.0 + (0.2 if i == 0 else -0.2), 2.0, 0.0))
                   for i, n in enumerate(names)]
        character_file = os.path.join(CHARACTERS, "biped.json")

        def setup(selected):
            self.select(selected, body)
            self.assertEqual(bpy.ops.footfall.character_setup(
                character_file=character_file, mode="PICK", name="again"), {"FINISHED"})
            return settings.rig

        def rigs_of_body():
            return [o for o in bpy.context.scene.objects
                    if o.footfall_rig.is_rig and o.footfall_rig.body == body]

        first = setup(targets + [body])
        first_parts = [o for o in bpy.context.scene.objects if o.name.startswith("again_") and
                       o.name.endswith(("_center", "_target"))]
        self.assertEqual(len(first_parts), 3)  # one central locator, two target locators
        # The user's own object under the rig stays, where it is.
        note = new_empty("again_note", parent=first_parts[0], location=(0.0, 0.0, 0.5))
        bpy.context.view_layer.update()
        note_world = note.matrix_world.copy()
        settings.steps, settings.start_frame = 6, 1
        self.select([first], first)
        self.assertEqual(bpy.ops.footfall.generate_walk(), {"FINISHED"})
        long_walk = json.loads(bpy.data.texts["footfall_walk.json"].as_string())
        long_end = max(k["frame"] for t in long_walk["tracks"] for k in t["keys"])
        # The body has walked on: set up again where it stands at the walk's end, with the whole
        # old rig selected (its locators first).
        bpy.context.scene.frame_set(int(long_end))
        objects_before = set(bpy.context.scene.objects)
        rig = setup(first_parts + [first] + targets + [body])
        self.assertEqual(rig.name, "again_rig")
        self.assertEqual(rigs_of_body(), [rig])
        self.assertEqual({f.name: f.target for f in rig.footfall_rig.feet},
                         dict(zip(names, targets)))
        self.assertIs(rig.footfall_rig.body, body)
        for obj in targets + [body, note]:
            self.assertIn(obj, list(bpy.context.scene.objects), obj.name)
        self.assertTrue(note.matrix_world.translation.to_tuple(6) ==
                        note_world.translation.to_tuple(6))
        made = [o for o in bpy.context.scene.objects if o.name.startswith("again_") and
                o.name.endswith(("_center", "_target"))]
        self.assertEqual(sorted(o.name for o in made),
                         sorted(["again_L_R_center", "again_L_target", "again_R_target"]))
        self.assertEqual(len(bpy.context.scene.objects), len(objects_before))
        # Generate Walk from the body walks the new rig, and replaces the old rig's longer walk.
        settings.steps = 4
        self.select([body], body)
        self.assertEqual(bpy.ops.footfall.generate_walk(), {"FINISHED"})
        walk, _ = self.cli_walk(rig, 4, "again_4")
        self.assert_keys_equal_walk(walk, dict(zip(names, targets)), body)
        # With the rig itself active, its body and IK targets are set up again (the root was
        # taken as the body, and removed with the rig).
        self.select([rig], rig)
        self.assertEqual(bpy.ops.footfall.character_setup(
            character_file=character_file, mode="PICK", name="again"), {"FINISHED"})
        rig = settings.rig
        self.assertEqual(rigs_of_body(), [rig])
        self.assertEqual({f.name: f.target for f in rig.footfall_rig.feet},
                         dict(zip(names, targets)))
        made = [o for o in bpy.context.scene.objects if o.name.startswith("again_") and
                o.name.endswith(("_center", "_target"))]
        self.assertEqual(len(made), 3)
        for obj in [body, note] + targets + made + [rig]:
            bpy.data.objects.remove(obj)
        settings.rig = bpy.data.objects["biped_rig"]
        bpy.context.scene.frame_set(1)

    def test_8d2_objects_under_a_replaced_rig_keep_their_keyed_places(self):
        # Targets and body parented under the rig root (a master control), then Character Setup
        # again with the root active: they kept their place at the current frame only, and the
        # walk keyed under the old root played 1.8 to 3.5 m away.
        scene = bpy.context.scene
        settings = scene.footfall
        scene.frame_set(1)
        scene.cursor.location = (1.5, 1.0, 0.0)
        scene.cursor.rotation_euler = (0.0, 0.0, math.radians(60))
        self.select([], None)
        self.assertEqual(bpy.ops.footfall.character_setup(
            character_file=os.path.join(CHARACTERS, "biped.json"), mode="CREATE",
            name="master"), {"FINISHED"})
        rig, feet, body = rig_feet_body("master_rig")
        for obj in list(feet.values()) + [body]:
            world = obj.matrix_world.copy()
            obj.parent = rig
            obj.matrix_world = world
        bpy.context.view_layer.update()
        settings.rig, settings.steps, settings.start_frame = rig, 6, 1
        self.select([rig], rig)
        self.assertEqual(bpy.ops.footfall.generate_walk(), {"FINISHED"})
        objects = list(feet.values()) + [body]
        frames = (13, 25, 49, 73)

        def worlds():
            out = {}
            for frame in frames:
                scene.frame_set(frame)
                out.update({(o.name, frame): o.matrix_world.translation.copy() for o in objects})
            scene.frame_set(1)
            return out

        before = worlds()
        self.select([rig], rig)
        self.assertEqual(bpy.ops.footfall.character_setup(
            character_file=os.path.join(CHARACTERS, "biped.json"), mode="PICK",
            name="master"), {"FINISHED"})
        new_rig = settings.rig
        self.assertEqual(new_rig.name, "master_rig")
        self.assertEqual({o.parent for o in objects}, {new_rig})  # still under the rig
        after = worlds()
        for key, where in before.items():
            self.assertLess((after[key] - where).length, 1e-5, key)
        for obj in objects + self.ops.rig_parts(new_rig):
            bpy.data.objects.remove(obj)
        settings.rig = None
        scene.cursor.rotation_euler = (0.0, 0.0, 0.0)

    def test_8e_a_walk_again_keeps_the_users_curve_modifiers(self):
        # Generate Walk again removed the previous walk's keys, and a curve left without keys
        # went with the modifiers the user had put on it (a Noise on the body's height for a
        # bob): the new walk's keys came on a bare curve.
        rig = bpy.data.objects["biped_rig"]
        body = rig.footfall_rig.body
        scene = bpy.context.scene.footfall
        scene.rig, scene.steps, scene.start_frame = rig, 6, 1
        self.select([rig], rig)
        clear_animation([body])
        self.assertEqual(bpy.ops.footfall.generate_walk(), {"FINISHED"})
        curve = body.animation_data.action.fcurves.find("location", index=2)
        noise = curve.modifiers.new("NOISE")
        noise.strength = 0.05
        scene.steps = 4
        self.assertEqual(bpy.ops.footfall.generate_walk(), {"FINISHED"})
        curve = body.animation_data.action.fcurves.find("location", index=2)
        self.assertEqual([m.type for m in curve.modifiers], ["NOISE"])
        self.assertAlmostEqual(curve.modifiers[0].strength, 0.05, places=6)
        walk = json.loads(bpy.data.texts["footfall_walk.json"].as_string())
        frames = sorted({k["frame"] for t in walk["tracks"] if t["kind"] == "body"
                         for k in t["keys"]})
        self.assertEqual([kp.co[0] for kp in curve.keyframe_points], [float(f) for f in frames])
        clear_animation([body])

    def test_8e1_a_walk_keyed_in_nla_tweak_mode_plays_at_its_frames(self):
        # The body's action is a strip starting at frame 101, tweaked. Keys appended straight
        # into the action went at the scene's frames in the strip's own time (100 frames late),
        # while those keyframe_insert set went where they play.
        rig = bpy.data.objects["biped_rig"]
        body = rig.footfall_rig.body
        scene = bpy.context.scene.footfall
        clear_animation([body])
        ad = body.animation_data_create()
        ad.action = bpy.data.actions.new("body_nla")
        body.keyframe_insert("location", frame=1)
        action = ad.action
        ad.action = None
        track = ad.nla_tracks.new()
        strip = track.strips.new("body_nla", 101, action)
        strip.select = True
        ad.use_tweak_mode = True
        self.assertTrue(ad.use_tweak_mode)
        try:
            scene.rig, scene.steps, scene.start_frame = rig, 4, 101
            self.select([rig], rig)
            self.assertEqual(bpy.ops.footfall.generate_walk(), {"FINISHED"})
            walk = json.loads(bpy.data.texts["footfall_walk.json"].as_string())
            body_keys = [k for t in walk["tracks"] if t["kind"] == "body" for k in t["keys"]]
            frames = sorted({float(k["frame"]) for k in body_keys})
            self.assertEqual(frames[0], 101.0)
            curve = action.fcurves.find("location", index=0)
            # (The key at the strip's frame 1 was the walk's to replace: it starts there.)
            self.assertEqual([kp.co[0] for kp in curve.keyframe_points],
                             [f - 100 for f in frames])
            scale = bpy.context.scene.unit_settings.scale_length
            for k in body_keys[1:]:
                bpy.context.scene.frame_set(int(k["frame"]))
                got = body.matrix_world.translation
                for g, w in zip(got, from_ff(k["position"])):
                    self.assertAlmostEqual(g, w / scale, delta=TOL * max(1.0, abs(w)),
                                           msg="body at frame %s" % k["frame"])
        finally:
            ad.use_tweak_mode = False
            clear_animation([body])
            scene.start_frame = 1

    def test_8f_a_picked_body_keeps_its_scale(self):
        # Character Setup set a picked body's world matrix without its scale: a body control
        # scaled 2 came back at scale 1 (the IK targets kept theirs).
        bpy.context.scene.frame_set(1)
        before = set(bpy.data.objects)
        settings = bpy.context.scene.footfall
        field = settings.rig
        try:
            body = new_empty("scaled_body", location=(-2.0, -2.0, 1.0))
            body.scale = (2.0, 2.0, 0.5)
            targets = [new_empty("scaled_IK_" + n, location=(-2.0 + x, -2.0, 0.0))
                       for n, x in (("L", 0.12), ("R", -0.12))]
            targets[0].scale = (3.0, 3.0, 3.0)
            bpy.context.view_layer.update()
            self.select([body] + targets, body)
            self.assertEqual(bpy.ops.footfall.character_setup(
                character_file=os.path.join(CHARACTERS, "biped.json"), mode="PICK"),
                {"FINISHED"})
            for obj, scale in ((body, (2.0, 2.0, 0.5)), (targets[0], (3.0, 3.0, 3.0))):
                for got, want in zip(obj.matrix_world.to_scale(), scale):
                    self.assertAlmostEqual(got, want, places=5, msg=obj.name)
            rig = settings.rig
            self.select([rig], rig)
            settings.steps, settings.start_frame = 3, 1
            self.assertEqual(bpy.ops.footfall.generate_walk(), {"FINISHED"})
            bpy.context.scene.frame_set(13)
            for got, want in zip(body.matrix_world.to_scale(), (2.0, 2.0, 0.5)):
                self.assertAlmostEqual(got, want, places=5)
        finally:
            bpy.context.scene.frame_set(1)
            for obj in set(bpy.data.objects) - before:
                bpy.data.objects.remove(obj)
            settings.rig = field

    def test_9_server_killed_mid_walk(self):
        rig = bpy.data.objects["biped_rig"]
        feet = {f.name: f.target for f in rig.footfall_rig.feet}
        body = rig.footfall_rig.body
        clear_animation(list(feet.values()) + [body])
        scene = bpy.context.scene.footfall
        scene.rig, scene.steps = rig, 10
        self.select([rig], rig)  # the rig of the active object is keyed
        server = self.server
        # A walk of 10 steps first: the one cut short removes its keys past the new ones, and
        # says so (it said the keys were "kept").
        self.assertEqual(bpy.ops.footfall.generate_walk(), {"FINISHED"})

        def kill_after_second_chunk(op, done):
            if done == 4:
                server.kill()
        self.ops.chunk_hook = kill_after_second_chunk
        try:
            with self.assertRaises(RuntimeError) as e:
                bpy.ops.footfall.generate_walk(chunk_steps=2)
        finally:
            self.ops.chunk_hook = None
        self.assertIn("unavailable", str(e.exception))
        self.assertIn("kept", str(e.exception))
        self.assertRegex(str(e.exception), r"the previous walk's keys after frame [0-9.]+ are "
                                           r"removed \(Edit > Undo brings them back\)")
        # Blender is still here; the keys of the first 4 steps stay, exactly.
        server.restart()
        partial, _ = self.cli_walk(rig, 4, "biped_4")
        self.assert_keys_equal_walk(partial, feet, body)
        server.kill()
        # With no server at all and local starts allowed, the add-on starts its own footfalld,
        # uploads the terrain again and completes the walk.
        self.prefs.start_local = True
        self.assertEqual(bpy.ops.footfall.generate_walk(), {"FINISHED"})
        self.assertIsNotNone(self.ops._connection.local)
        self.assertTrue(self.ops._connection.local.running())
        server.restart()
        full, _ = self.cli_walk(rig, 10, "biped_10")
        self.assert_keys_equal_walk(full, feet, body)


    def test_9v_the_add_on_disabled_and_enabled_again(self):
        # Disabling stops the add-on's own footfalld and forgets the loaded terrains: enabled
        # again, a scene asks for Terrain Setup (nothing keyed), and after it walks as before.
        rig = bpy.data.objects["biped_rig"]
        body = rig.footfall_rig.body
        scene = bpy.context.scene.footfall
        scene.rig, scene.steps, scene.start_frame = rig, 4, 1
        keys = fcurve_keys(body, "location", 3)
        local = self.ops._connection.local
        addon_utils.disable("footfall_blender", default_set=True)
        if local is not None:
            self.assertFalse(local.running())
        self.assertIsNotNone(addon_utils.enable("footfall_blender", default_set=True,
                                                handle_error=None))
        prefs = bpy.context.preferences.addons["footfall_blender"].preferences
        prefs.host, prefs.port, prefs.start_local = "127.0.0.1", self.server.port, False
        type(self).prefs = prefs
        handlers = [h for h in bpy.app.handlers.depsgraph_update_post
                    if h.__name__ == "_depsgraph_updated"]
        self.assertEqual(len(handlers), 1)
        self.select([rig], rig)
        with self.assertRaises(RuntimeError) as e:
            bpy.ops.footfall.generate_walk()
        self.assertIn("not loaded in this Blender session: run Terrain Setup again",
                      str(e.exception))
        self.assertEqual(fcurve_keys(body, "location", 3), keys)
        terrain = bpy.data.objects["terrain"]
        self.select([terrain], terrain)
        scene.terrain_source, scene.separation = "MESH", 0.05
        self.assertEqual(bpy.ops.footfall.terrain_setup(), {"FINISHED"})
        self.assertEqual(scene.sample_count, self._count)
        self.select([rig], rig)
        self.assertEqual(bpy.ops.footfall.generate_walk(), {"FINISHED"})
        expected, _ = self.cli_walk(rig, 4, "biped_reenabled")
        feet = {f.name: f.target for f in rig.footfall_rig.feet}
        self.assert_keys_equal_walk(expected, feet, body)

    def test_9w_long_names_of_several_bytes_a_character(self):
        # Object names hold 63 bytes: Blender cut the end off, so a rig named in a script of
        # several bytes a character (22 of them in Japanese) had every empty named alike, its
        # feet and locators told apart only by .001, .002.
        scene = bpy.context.scene.footfall
        field = scene.rig
        with open(os.path.join(CHARACTERS, "biped.json")) as f:
            data = json.load(f)
        name = "歩行者" * 8  # 72 bytes
        feet = {"L": "左足", "R": "右足"}
        data["name"] = name
        for foot in data["feet"]:
            foot["name"] = feet[foot["name"]]
        data["gait"] = [[feet[n] for n in step] for step in data["gait"]]
        data["pairs"] = [[feet[n] for n in pair] for pair in data["pairs"]]
        path = os.path.join(ARGS.work_dir, "キャラクター.json")
        with open(path, "w", encoding="utf-8") as f:
            json.dump(data, f, ensure_ascii=False)
        before = set(bpy.data.objects)
        try:
            bpy.context.scene.cursor.location = (2.0, -2.0, 0.0)
            self.select([], None)
            for copy in ("", ".001"):  # a second rig of the same name: Blender's suffix too
                self.assertEqual(bpy.ops.footfall.character_setup(
                    character_file=path, mode="CREATE"), {"FINISHED"})
                rig = scene.rig
                self.assertTrue(rig.name.endswith("_rig" + copy), rig.name)
                self.assertTrue(rig.name.startswith("歩行者歩行者"), rig.name)
                self.assertTrue(rig.footfall_rig.body.name.endswith("_body" + copy))
                for foot in rig.footfall_rig.feet:
                    self.assertTrue(foot.target.name.endswith("_" + foot.name + copy),
                                    foot.target.name)
                locators = sorted(o.name.rsplit("_", 1)[1] for o in rig.children_recursive)
                self.assertEqual(locators, ["center" + copy] + ["target" + copy] * 2)
            self.select([rig], rig)
            scene.steps = 4
            self.assertEqual(bpy.ops.footfall.generate_walk(), {"FINISHED"})
            walk = json.loads(bpy.data.texts["footfall_walk.json"].as_string())
            self.assertEqual(sorted(t["name"] for t in walk["tracks"]), ["body", "右足", "左足"])
            # Import onto new empties, from a file of a long name: each keeps its track's name.
            out = os.path.join(ARGS.work_dir, "歩く" * 12 + ".json")
            with open(out, "w", encoding="utf-8") as f:
                json.dump(walk, f, ensure_ascii=False)
            self.select([], None)
            scene.rig = None
            made = set(bpy.data.objects)
            self.assertEqual(bpy.ops.footfall.import_walk(filepath=out), {"FINISHED"})
            names = sorted(o.name for o in set(bpy.data.objects) - made)
            self.assertEqual(sorted(n.rsplit("_", 1)[1] for n in names), ["body", "右足", "左足"])
            self.assertTrue(all(n.startswith("歩く歩く") for n in names), names)
        finally:
            for obj in set(bpy.data.objects) - before:
                bpy.data.objects.remove(obj)
            scene.rig = field

    def test_9x_scenes_in_other_unit_scales(self):
        # footfall's lengths are metres (the character files'), Blender's scene units are the
        # Unit Scale in metres. The add-on took scene units for metres: in a centimetre scene
        # (0.01) the biped was 0.95 cm tall and took 0.7 cm steps, a point file loaded 100
        # times too small, and a walk imported from JSON landed elsewhere than from glTF.
        character_file = os.path.join(CHARACTERS, "biped.json")
        original = bpy.data.objects["terrain"]
        for scale in (0.01, 100.0):
            other = bpy.data.scenes.new("units %g" % scale)
            other.unit_settings.system, other.unit_settings.scale_length = "METRIC", scale
            try:
                with bpy.context.temp_override(scene=other, view_layer=other.view_layers[0]):
                    self._walk_in_unit_scale(other, scale, character_file, original)
            finally:
                for obj in list(other.collection.all_objects):
                    bpy.data.objects.remove(obj)
                bpy.data.scenes.remove(other)
        self.ops.release_unused_terrains()
        self.ops.wait_for_unloads()

    def _walk_in_unit_scale(self, scene, scale, character_file, original):
        settings = scene.footfall
        # The terrain mesh, its object scaled to scene units: the same samples, in metres.
        terrain = original.copy()
        terrain.scale = (1 / scale,) * 3
        scene.collection.objects.link(terrain)
        bpy.context.view_layer.update()
        settings.terrain_source, settings.separation = "MESH", 0.05 / scale
        self.assertAlmostEqual(settings.separation * scale, 0.05, delta=1e-7)  # (not clamped)
        pts = os.path.join(ARGS.work_dir, "terrain_scaled.pts")
        with bpy.context.temp_override(active_object=terrain):
            self.assertEqual(bpy.ops.footfall.terrain_setup(save_points=pts), {"FINISHED"})
        tree = self.samples_tree()
        with open(pts) as f:
            rows = [tuple(float(v) for v in line.split()[:3]) for line in f
                    if line.strip() and not line.startswith("#")]
        self.assertAlmostEqual(len(rows), self._count, delta=0.01 * self._count)
        for p in rows[::97]:
            self.assertLess(tree.find(p)[2], 1e-3, "sample %s of the scaled mesh" % (p,))
        # The metres point file, and a biped on it: its size and its walk are the command
        # line's, in scene units.
        settings.terrain_source, settings.terrain_file = "FILE", self.pts
        self.assertEqual(bpy.ops.footfall.terrain_setup(), {"FINISHED"})
        self.assertEqual(settings.sample_count, self._count)
        scene.cursor.location = Vector((0.5, 2.5, 0.0)) / scale
        with bpy.context.temp_override(active_object=None):
            self.assertEqual(bpy.ops.footfall.character_setup(
                character_file=character_file, mode="CREATE", name="biped_units"), {"FINISHED"})
        rig = settings.rig
        body = rig.footfall_rig.body
        feet = {f.name: f.target for f in rig.footfall_rig.feet}
        for obj in feet.values():  # on the terrain: a sample, in metres
            _, _, dist = tree.find([c * scale for c in to_ff(obj.matrix_world.translation)])
            self.assertLess(dist, 1e-5, obj.name)
        height = (body.matrix_world.translation - rig.matrix_world.translation).length * scale
        self.assertAlmostEqual(height, 0.95, delta=1e-4)
        settings.steps, settings.start_frame = 6, 1
        # The panel's lengths are in scene units and reach footfall in metres; 0 keeps the
        # character file's.
        file_foot = ff.character.parse(rig.footfall_rig.character_json).get("foot_length")
        self.assertEqual(
            self.ops.walk_request(bpy.context, rig, 6, 1)["character"].get("foot_length"),
            file_foot)
        settings.foot_length = 0.3 / scale
        try:
            self.assertAlmostEqual(
                self.ops.walk_request(bpy.context, rig, 6, 1)["character"]["foot_length"], 0.3,
                delta=1e-6)
        finally:
            settings.foot_length = 0.0
        with bpy.context.temp_override(active_object=rig):
            self.assertEqual(bpy.ops.footfall.generate_walk(), {"FINISHED"})
        mw = rig.matrix_world
        out = os.path.join(ARGS.work_dir, "units_walk.json")
        run_cli("generate", "--terrain", self.pts, "--character", character_file,
                "--start", csv([c * scale for c in to_ff(mw.translation)]),
                "--heading", csv(to_ff(mw.to_3x3() @ Vector((0, -1, 0)))),
                "--steps", 6, "--start-frame", 1, "--unit", "m", "--out", out,
                "--out", out[:-5] + "_gltf.gltf")
        with open(out) as f:
            expected = json.load(f)
        got = json.loads(bpy.data.texts["footfall_walk.json"].as_string())
        self.assertEqual(got, expected)
        self.assert_keys_equal_walk(expected, feet, body, scale)
        # Import onto new empties: the same keys.
        settings.rig = None
        with bpy.context.temp_override(active_object=None):
            self.assertEqual(bpy.ops.footfall.import_walk(filepath=out), {"FINISHED"})
        feet = {t["name"]: bpy.data.objects["units_walk_" + t["name"]]
                for t in expected["tracks"] if t["kind"] == "foot"}
        self.assert_keys_equal_walk(expected, feet, bpy.data.objects["units_walk_body"], scale)
        # And from glTF (Blender's importer divides its metres by the Unit Scale too).
        with bpy.context.temp_override(active_object=None):
            self.assertEqual(bpy.ops.footfall.import_walk(filepath=out[:-5] + "_gltf.gltf"),
                             {"FINISHED"})
        feet = {t["name"]: bpy.data.objects["units_walk_gltf_" + t["name"]]
                for t in expected["tracks"] if t["kind"] == "foot"}
        self.assert_keys_equal_walk(expected, feet, bpy.data.objects["units_walk_gltf_body"],
                                    scale)

    def test_9x1_foot_rotations_key_each_target_on_its_ground(self):
        # Foot rotations on: each IK target is keyed turned as the walk's glTF and MEL key the
        # feet (--foot-rotations), standing on its ground; off again, the walk's rotation keys
        # on the targets go, and the user's own after the walk stay.
        rig, feet, body = rig_feet_body("biped_rig")
        settings = bpy.context.scene.footfall
        settings.rig, settings.steps, settings.start_frame = rig, 6, 1
        self.select([rig], rig)
        clear_animation(list(feet.values()) + [body])
        foot = feet["L"]
        foot.rotation_mode = "XYZ"
        own = foot.rotation_euler.copy()
        foot.rotation_euler = Euler((0.1, 0.2, 0.3))
        foot.keyframe_insert("rotation_euler", frame=500)
        foot.rotation_euler = own
        self.assertNotIn("foot_rotations", self.ops.walk_request(bpy.context, rig, 6, 1))
        settings.foot_rotations = True
        try:
            self.assertIs(self.ops.walk_request(bpy.context, rig, 6, 1)["foot_rotations"], True)
            self.assertEqual(bpy.ops.footfall.generate_walk(), {"FINISHED"})
        finally:
            settings.foot_rotations = False
        expected, out = self.cli_walk(rig, 6, "turned_cli", "--foot-rotations")
        got = json.loads(bpy.data.texts["footfall_walk.json"].as_string())
        self.assertEqual(got, expected)  # the command line's walk, rotations and all
        foot_keys = [k for t in got["tracks"] if t["kind"] == "foot" for k in t["keys"]]
        self.assertTrue(foot_keys and all("rotation" in k for k in foot_keys))
        self.assertTrue(rig.footfall_rig.walk_turned_feet)
        self.assert_keys_equal_walk(expected, feet, body)
        self.assert_world_at_key_frames(expected, feet, body)
        for k in foot_keys:  # each target's up (its local Z in Blender) on the key's normal
            x, y, z, w = k["rotation"]
            up = Quaternion((w, x, -z, y)) @ Vector((0, 0, 1))
            self.assertGreater(up.dot(Vector(from_ff(k["normal"])).normalized()), 1 - 1e-6)
        self.assertIn(500.0, body_rotation_keys(foot))
        # Off: the walk's foot rotation keys go (the targets keep the orientation they have),
        # the user's key after the walk stays.
        self.assertEqual(bpy.ops.footfall.generate_walk(), {"FINISHED"})
        self.assertFalse(rig.footfall_rig.walk_turned_feet)
        plain, _ = self.cli_walk(rig, 6, "unturned_cli")
        self.assertEqual(json.loads(bpy.data.texts["footfall_walk.json"].as_string()), plain)
        self.assert_keys_equal_walk(plain, feet, body)
        for obj in feet.values():
            self.assertEqual(sorted(body_rotation_keys(obj)), [500.0] if obj == foot else [],
                             obj.name)
        # Imported onto new empties, from the JSON and from the glTF: turned the same.
        gltf = out[:-5] + ".gltf"
        run_cli("generate", "--terrain", self.pts, "--character", rig.footfall_rig.character_path,
                "--start", csv(to_ff(rig.matrix_world.translation)),
                "--heading", csv(to_ff(rig.matrix_world.to_3x3() @ Vector((0, -1, 0)))),
                "--steps", 6, "--foot-rotations", "--out", gltf)
        settings.rig = None
        for path, prefix in ((out, "turned_cli_"), (gltf, "turned_cli_")):
            with bpy.context.temp_override(active_object=None):
                self.assertEqual(bpy.ops.footfall.import_walk(filepath=path), {"FINISHED"})
            made = {t["name"]: bpy.data.objects[prefix + t["name"]]
                    for t in expected["tracks"] if t["kind"] == "foot"}
            self.assert_keys_equal_walk(expected, made, bpy.data.objects[prefix + "body"])
            for obj in list(made.values()) + [bpy.data.objects[prefix + "body"]]:
                bpy.data.objects.remove(obj)
        settings.rig = rig

    def test_9y_a_deleted_scenes_terrains_are_unloaded(self):
        # Terrains were unloaded only when a file was loaded: a deleted scene's stayed loaded on
        # the server for the rest of the Blender session.
        connection, ops = self.ops._connection, self.ops
        scene = bpy.context.scene
        key = scene.footfall.terrain_key
        self.assertTrue(connection.has_terrain(key))

        def scene_with_terrain(name, setups=1):
            other = bpy.data.scenes.new(name)
            with bpy.context.temp_override(scene=other, view_layer=other.view_layers[0]):
                other.footfall.terrain_source, other.footfall.terrain_file = "FILE", self.pts
                keys = []
                for _ in range(setups):
                    self.assertEqual(bpy.ops.footfall.terrain_setup(), {"FINISHED"})
                    keys.append(other.footfall.terrain_key)
            return other, keys

        def gone(ids):
            for terrain in ids:
                with self.assertRaises(Exception) as e:  # (the add-on's own FootfallError)
                    connection.session.info(terrain)
                self.assertEqual(e.exception.status_name, "unknown_terrain")
        # Deleted: the next command that calls the server unloads its terrain first (here
        # one that fails after connecting).
        doomed, keys = scene_with_terrain("doomed")
        ids = [connection.terrain(keys[0])]
        bpy.data.scenes.remove(doomed)
        with self.assertRaises(RuntimeError):
            bpy.ops.footfall.character_setup(
                character_file=os.path.join(ARGS.work_dir, "bad_frames_per_step.json"))
        self.assertNotIn(keys[0], connection.terrain_names())
        gone(ids)
        self.assertTrue(connection.has_terrain(key))
        # Or the next depsgraph update has them unloaded from a timer (the event loop runs it;
        # here the test does), on a thread of its own. Both the scene's terrain and the one
        # its second Terrain Setup replaced (kept while the scene lived, for an undo) go.
        if bpy.app.timers.is_registered(ops._release_timer):  # (from the first deletion)
            bpy.app.timers.unregister(ops._release_timer)
        doomed, keys = scene_with_terrain("doomed with two terrains", setups=2)
        ids = [connection.terrain(k) for k in keys]
        bpy.context.view_layer.update()
        self.assertFalse(bpy.app.timers.is_registered(ops._release_timer))
        self.assertEqual(ops.unused_terrains(), [])
        bpy.data.scenes.remove(doomed)
        bpy.context.view_layer.update()
        self.assertTrue(bpy.app.timers.is_registered(ops._release_timer))
        bpy.app.timers.unregister(ops._release_timer)
        ops._release_timer()
        ops.wait_for_unloads()
        for k in keys:
            self.assertNotIn(k, connection.terrain_names())
        gone(ids)
        self.assertEqual(connection.session.info(connection.terrain(key))[0], self._count)
        # A hung server holds up the unload thread for one call timeout, not Blender.
        saved = self.prefs.timeout
        self.prefs.timeout = 1.0
        doomed, keys = scene_with_terrain("doomed on a hung server")
        bpy.data.scenes.remove(doomed)
        own = connection.local
        process = own.process if own is not None and own.running() else self.server.process
        os.kill(process.pid, signal.SIGSTOP)
        try:
            began = time.monotonic()
            ops.release_unused_terrains()
            self.assertLess(time.monotonic() - began, 0.5)
            ops.wait_for_unloads()
            print("unload on a stopped server: the thread took %.2f s (call timeout 1 s)"
                  % (time.monotonic() - began))
            self.assertLess(time.monotonic() - began, 3.0)
        finally:
            os.kill(process.pid, signal.SIGCONT)
            self.prefs.timeout = saved
        self.assertNotIn(keys[0], connection.terrain_names())
        self.assertTrue(connection.has_terrain(key))
        if bpy.app.timers.is_registered(ops._release_timer):
            bpy.app.timers.unregister(ops._release_timer)

    def test_9z_each_scene_and_file_has_its_own_terrain(self):
        # One terrain served the whole Blender session: another scene, or the file made by
        # File > New, walked on the previous terrain without a word, and it stayed loaded.
        connection = self.ops._connection
        scene = bpy.context.scene
        character_file = os.path.join(CHARACTERS, "biped.json")
        rig = bpy.data.objects["biped_rig"]
        body = rig.footfall_rig.body
        other = bpy.data.scenes.new("other")
        objects = set(bpy.data.objects)
        keys = fcurve_keys(body, "location", 3)

        def in_other():
            return bpy.context.temp_override(scene=other, view_layer=other.view_layers[0])
        with in_other():
            other.footfall.rig = rig
            with self.assertRaises(RuntimeError) as e:
                bpy.ops.footfall.character_setup(character_file=character_file, mode="CREATE")
            self.assertIn("no terrain in this scene: run Terrain Setup first", str(e.exception))
            with self.assertRaises(RuntimeError) as e:
                bpy.ops.footfall.generate_walk()
            self.assertIn("no terrain in this scene: run Terrain Setup first", str(e.exception))
        self.assertEqual(set(bpy.data.objects), objects)
        self.assertEqual(fcurve_keys(body, "location", 3), keys)
        # Its own terrain; Terrain Setup again replaces it (the old one stays loaded, as an
        # undo may bring it back, until a file is loaded), and the first scene keeps its own.
        key = scene.footfall.terrain_key
        self.assertTrue(connection.has_terrain(key))
        ids = []
        with in_other():
            other.footfall.terrain_source, other.footfall.terrain_file = "FILE", self.pts
            for _ in range(2):
                self.assertEqual(bpy.ops.footfall.terrain_setup(), {"FINISHED"})
                ids.append(connection.terrain(other.footfall.terrain_key))
        self.assertNotEqual(other.footfall.terrain_key, key)
        self.assertIn(key, connection.terrain_names())
        self.assertIn(other.footfall.terrain_key, connection.terrain_names())
        session = connection.session
        ids.append(connection.terrain(key))
        self.assertEqual(session.info(ids[-1])[0], self._count)
        # Undo: Terrain Setup is a step of its own. Undoing a step after it keeps the scene's
        # terrain (it was lost, the terrain left loaded with nothing using it); undoing Terrain
        # Setup brings the previous terrain back, still loaded.
        before = bpy.context.scene.footfall.terrain_key
        bpy.context.scene.footfall.terrain_source = "FILE"
        bpy.context.scene.footfall.terrain_file = self.pts
        bpy.ops.ed.undo_push(message="before Terrain Setup")
        self.assertEqual(bpy.ops.footfall.terrain_setup(), {"FINISHED"})
        # (Blender pushes an operator's undo step when the UI runs it, not from a script.)
        self.assertIn("UNDO", self.ops.FOOTFALL_OT_terrain_setup.bl_options)
        bpy.ops.ed.undo_push(message="Terrain Setup")
        after = bpy.context.scene.footfall.terrain_key
        ids.append(connection.terrain(after))
        bpy.context.scene.frame_current += 1
        bpy.ops.ed.undo_push(message="a step after it")
        bpy.ops.ed.undo()
        self.assertEqual(bpy.context.scene.footfall.terrain_key, after)
        self.assertTrue(self.ops.scene_terrain_loaded(bpy.context.scene))
        bpy.ops.ed.undo()
        self.assertEqual(bpy.context.scene.footfall.terrain_key, before)
        self.assertTrue(self.ops.scene_terrain_loaded(bpy.context.scene))
        # File > New: the closed file's terrains are unloaded from the server, and the new
        # file has none.
        bpy.ops.wm.read_homefile(use_empty=True)
        self.ops.wait_for_unloads()  # (unloaded in the background)
        self.assertEqual(connection.terrain_names(), [])
        for terrain in ids:
            with self.assertRaises(Exception) as e:
                session.info(terrain)
            self.assertEqual(e.exception.status_name, "unknown_terrain")
        bpy.context.scene.cursor.location = (0.0, 0.0, 0.0)
        with self.assertRaises(RuntimeError) as e:
            bpy.ops.footfall.character_setup(character_file=character_file, mode="CREATE")
        self.assertIn("no terrain in this scene: run Terrain Setup first", str(e.exception))
        self.assertEqual(len(bpy.data.objects), 0)


# -- the resampling with numpy against the pure-Python loops ----------------------------------

def packed(rows):
    """Each value's bits (struct-packed doubles), per row: None rows stay None. Raises for a
    value that is not exactly a float."""
    out = []
    for row in rows:
        if row is None:
            out.append(None)
            continue
        values = [v for part in row for v in (part if isinstance(part, tuple) else (part,))]
        for v in values:
            if type(v) is not float:
                raise AssertionError("%r in %r is a %s, not a float" % (v, row, type(v).__name__))
        out.append(struct.pack("<%dd" % len(values), *values))
    return out


def outcome(fn, *args, **kwargs):
    """fn's result as packed bits (a flat array: "flat" and its doubles' bits), or its error's
    type and message."""
    try:
        result = fn(*args, **kwargs)
    except Exception as e:  # compared, not hidden: the other path must raise the same
        return (type(e).__name__, str(e))
    if isinstance(result, array):
        return ("flat", packed_flat(result))
    return ("ok", None if result is None else packed(result))


def packed_flat(flat):
    """The bits of a flat array('d') of samples, as packed() of its rows joined; raises for
    anything but an array('d') of whole samples."""
    if type(flat) is not array or flat.typecode != "d" or len(flat) % 6:
        raise AssertionError("expected an array('d') of whole samples, got %r" % (flat,))
    return struct.pack("<%dd" % len(flat), *flat)


def as_flat(result):
    """sample_triangles' outcome as sample_triangles_flat's: its rows' bits joined, or the same
    error."""
    return ("flat", b"".join(result[1])) if result[0] == "ok" else result


def grid(n, spacing, offset=0.0, wave=0.3):
    pts = [(offset + i * spacing, wave * math.sin(0.9 * i * spacing) * math.cos(0.7 * j * spacing),
            offset + j * spacing) for j in range(n) for i in range(n)]
    tris = []
    for j in range(n - 1):
        for i in range(n - 1):
            a = j * n + i
            tris += [(a, a + n, a + 1), (a + 1, a + n, a + n + 1)]
    return pts, tris


def box(size=1.0, offset=(0.0, 0.0, 0.0)):
    """A closed box (creases of 90 degrees), wound outward."""
    pts = [(offset[0] + x * size, offset[1] + y * size, offset[2] + z * size)
           for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)]
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    return pts, [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]


def stairs(steps=5, rise=0.17, run=0.28, width=1.2):
    """A flight of stairs (treads and risers sharing their edges), up along +z."""
    profile = []
    for s in range(steps):
        profile += [(s * rise, s * run), ((s + 1) * rise, s * run)]
    profile.append((steps * rise, steps * run))
    pts = [(x, y, z) for y, z in profile for x in (0.0, width)]
    tris = []
    for p in range(len(profile) - 1):
        a = 2 * p
        tris += [(a, a + 2, a + 1), (a + 1, a + 2, a + 3)]
    return pts, tris


def tilted_plane(n=6):
    """A flat grid on a plane leaning every way: its triangles' normals agree but for their
    last bits, which decide whether a crease angle of 0 keeps each neighbour."""
    pts = [(i * 0.37, 0.21 * i + 0.43 * j, j * 0.29) for j in range(n) for i in range(n)]
    return pts, grid(n, 1.0)[1]


def random_mesh(seed):
    """Random triangles over shared vertices, some zero-area or naming a vertex twice, at
    varied scales and offsets."""
    r = random.Random(seed)
    n = r.randint(3, 40)
    scale = r.choice([1.0, 1e-3, 10.0, 250.0])
    offset = r.choice([0.0, -3.5, 1e5])
    pts = [tuple(offset + r.uniform(-1.0, 1.0) * scale for _ in range(3)) for _ in range(n)]
    if seed % 4 == 0:  # coordinates of few digits: lattice points of neighbours coincide
        pts = [tuple(round(v, 1) for v in p) for p in pts]
    tris = [tuple(r.randrange(n) for _ in range(3)) for _ in range(r.randint(1, 30))]
    tris.append((0, 0, 1))  # a vertex twice
    pts.append(pts[1])  # the same point twice, and a triangle through both copies
    tris.append((1, n, 2))
    mid = tuple((a + b) / 2 for a, b in zip(pts[0], pts[2]))
    pts.append(mid)  # on the segment from 0 to 2: a zero-area triangle
    tris.append((0, n + 1, 2))
    return pts, tris, scale


class SamplingNumpyTest(unittest.TestCase):
    """Blender's Python has numpy (Debian's python3-numpy): the add-on's resampling runs
    through sampling_numpy, which must give the pure-Python loops' samples bit for bit."""

    def test_numpy_is_used(self):
        import numpy  # noqa: F401 (Blender's Python must have it)
        self.assertTrue(ff.sampling.USE_NUMPY)
        self.assertIsNotNone(ff.sampling._numpy)

    def assert_same(self, label, fn, *args, **kwargs):
        want = outcome(fn, *args, pure=True, **kwargs)
        got = outcome(fn, *args, **kwargs)
        self.assertEqual(got[0], want[0], "%s: %s against %s" % (label, got, want))
        self.assertEqual(got, want, label)
        return want

    def assert_numpy_path(self, label, fn):
        """fn (a call of sampling_numpy) answers: no quiet fall back to the pure path."""
        try:
            return fn()
        except ff.sampling._numpy.Unsupported:
            self.fail("%s: sampling_numpy refused arguments it should take" % label)

    def assert_all_modes(self, label, pts, tris, separations, max_samples=ff.sampling.MAX_SAMPLES):
        np_ = ff.sampling._numpy
        for crease in (60.0, 0.0, 180.0):
            self.assert_same("%s corner normals %g" % (label, crease), ff.sampling.corner_normals,
                             pts, tris, crease)
        self.assert_numpy_path(label, lambda: np_.corner_normals(pts, tris, 0.5))
        corners = ff.sampling.corner_normals(pts, tris, pure=True)
        some_none = list(corners)
        for t in range(0, len(some_none), 3):
            some_none[t] = None
        vertex = [(math.sin(i), math.cos(i), 0.5) for i in range(len(pts))]
        # Opposite normals at two corners: their mean at the midpoint is zero (the face's).
        vertex[tris[0][0]], vertex[tris[0][1]] = (0.0, 0.0, 1.0), (0.0, 0.0, -1.0)
        vertex[tris[-1][2]] = (0.0, 0.0, 0.0)
        for separation in separations:
            what = "%s at %g" % (label, separation)
            self.assert_same(what + " count", ff.sampling.check_sample_count, pts, tris,
                             separation, max_samples)
            for name, kwargs in (("face", {}), ("corner normals", {"corner_normals": corners}),
                                 ("corner normals with None", {"corner_normals": some_none}),
                                 ("vertex normals", {"vertex_normals": vertex})):
                result = self.assert_same("%s %s" % (what, name), ff.sampling.sample_triangles,
                                          pts, tris, separation, max_samples=max_samples,
                                          **kwargs)
                # The flat array, on both paths: the tuples' doubles in their order, bit for
                # bit, or the same error.
                flat = self.assert_same("%s %s flat" % (what, name),
                                        ff.sampling.sample_triangles_flat, pts, tris, separation,
                                        max_samples=max_samples, **kwargs)
                self.assertEqual(flat, as_flat(result), "%s %s flat" % (what, name))
                if result[0] == "ok":
                    self.assert_numpy_path(what, lambda: np_.sample_triangles(
                        pts, tris, separation, kwargs.get("vertex_normals"),
                        kwargs.get("corner_normals")))
                    self.assertEqual(packed_flat(self.assert_numpy_path(
                        what, lambda: np_.sample_triangles_flat(
                            pts, tris, separation, kwargs.get("vertex_normals"),
                            kwargs.get("corner_normals")))), flat[1], what)

    def test_random_triangles_sharing_vertices(self):
        for seed in range(16):
            pts, tris, scale = random_mesh(seed)
            self.assert_all_modes("random mesh %d" % seed, pts, tris,
                                  [scale * f for f in (0.12, 0.5, 5.0)])

    def test_creases_of_a_box_and_stairs(self):
        self.assert_all_modes("box", *box(), [0.07, 0.25, 3.0])
        self.assert_all_modes("far box", *box(2.0, (1e5, -1e5, 3e5)), [0.05, 10.0])
        self.assert_all_modes("stairs", *stairs(), [0.02, 0.1, 1.0])
        self.assert_all_modes("tilted plane", *tilted_plane(), [0.1, 0.5])

    def test_wavy_grids_near_and_far(self):
        self.assert_all_modes("grid", *grid(15, 0.5), [0.06, 0.2, 0.7])
        self.assert_all_modes("far grid", *grid(10, 0.5, offset=1e5), [0.05, 2.0])

    def test_blocks_of_any_size_give_the_same_samples(self):
        # sampling_numpy works a block of lattice points (or corner pairs) at a time: blocks
        # of a few points, cutting lattices and a vertex's neighbours apart, change nothing.
        np_ = ff.sampling._numpy
        saved = np_._BLOCK
        try:
            for block in (1, 7, 50):
                np_._BLOCK = block
                self.assert_all_modes("grid in blocks of %d" % block, *grid(6, 0.5), [0.2, 0.7])
                pts, tris, scale = random_mesh(3)
                self.assert_all_modes("random mesh in blocks of %d" % block, pts, tris,
                                      [0.5 * scale])
        finally:
            np_._BLOCK = saved

    def test_keys_whose_hashes_collide_are_told_apart(self):
        # Duplicates are found by sorting a hash of each key; keys of equal hashes that differ
        # (every key, with a hash of 0) are sorted by the keys themselves.
        np_ = ff.sampling._numpy
        saved = np_._mix
        try:
            np_._mix = lambda bits: bits * 0
            self.assert_all_modes("grid, hashes all 0", *grid(8, 0.5), [0.1, 0.7])
            self.assert_all_modes("box, hashes all 0", *box(), [0.25])
        finally:
            np_._mix = saved

    def test_count_errors_are_the_same(self):
        inf, nan = float("inf"), float("nan")
        for pts, separation in (
                ([(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 0.0, 1.0), (inf, 0.0, 0.0)], 0.1),
                ([(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, nan, 1.0), (2.0, 0.0, 0.0)], 0.1),
                ([(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 0.0, 1.0), (nan, 0.0, 0.0)], 0.1),
                ([(1e308, 0.0, 0.0), (-1e308, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, 1.0, 0.0)], 0.1),
                ([(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, 1.0, 0.0)], 1e-300),
                ([(0.0, 0.0, 0.0), (10.0, 0.0, 0.0), (0.0, 0.0, 10.0), (10.0, 0.0, 10.0)],
                 0.001)):
            tris = [(0, 1, 2), (1, 3, 2), (0, 1, 3)]
            for fn in (ff.sampling.check_sample_count, ff.sampling.sample_triangles):
                got = self.assert_same("%s %r" % (fn.__name__, pts), fn, pts, tris, separation)
                self.assertEqual(got[0], "ValueError", pts)
            # (The flat samples' limit is numpy's own unless given: given, the same errors.)
            self.assertEqual(self.assert_same("flat %r" % (pts,),
                                              ff.sampling.sample_triangles_flat, pts, tris,
                                              separation, max_samples=ff.sampling.MAX_SAMPLES),
                             got)
        # Too many samples, first passed at a later triangle of a mesh, for a small limit.
        pts, tris = grid(20, 0.5)
        for limit in (10, 400, 1000, 4000):
            got = self.assert_same("limit %d" % limit, ff.sampling.sample_triangles, pts, tris,
                                   0.1, max_samples=limit)
            self.assertEqual(got[0], "ValueError")
            self.assertIn("more than %d samples" % limit, got[1])
            self.assertEqual(self.assert_same("flat limit %d" % limit,
                                              ff.sampling.sample_triangles_flat, pts, tris, 0.1,
                                              max_samples=limit), got)
        self.assertIsNone(ff.sampling._numpy.count_problem(pts, tris, 0.1, 10 ** 6))
        # A count that reaches the limit exactly passes: 4 vertices and two triangles of
        # lattice size 2 (1.5 samples each on their edges) make 7.
        square = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 0.0, 1.0), (1.0, 0.0, 1.0)]
        for limit in (6, 7, 8, 6.5, 7.0):
            self.assert_same("square limit %r" % limit, ff.sampling.sample_triangles, square,
                             [(0, 2, 1), (1, 2, 3)], 0.8, max_samples=limit)
        what, t = self.assert_numpy_path("limit", lambda: ff.sampling._numpy.count_problem(
            pts, tris, 0.1, 4000))
        self.assertEqual(what, "too many")  # at triangle t, as the pure-Python loop counts:
        ff.sampling.check_sample_count(pts, tris[:t], 0.1, 4000, pure=True)
        with self.assertRaises(ValueError):
            ff.sampling.check_sample_count(pts, tris[:t + 1], 0.1, 4000, pure=True)

    def test_arguments_numpy_cannot_take_exactly_go_the_pure_way(self):
        # Integer coordinates (exact integer arithmetic in pure Python), large ones included.
        for scale in (1, 3000, 10 ** 12):
            pts = [(0, 0, 0), (2 * scale, 0, 0), (0, 1, 2 * scale), (scale, 3, scale)]
            tris = [(0, 2, 1), (1, 2, 3)]
            want = self.assert_same("ints x%d" % scale, ff.sampling.sample_triangles, pts, tris,
                                    0.7 * scale)
            self.assertEqual(self.assert_same("ints x%d flat" % scale,
                                              ff.sampling.sample_triangles_flat, pts, tris,
                                              0.7 * scale), as_flat(want))
            self.assert_same("ints x%d" % scale, ff.sampling.corner_normals, pts, tris)
        pts, tris = box()
        # A separation so small that a key overflows, and indices out of range or negative.
        self.assert_same("tiny separation", ff.sampling.sample_triangles, [(1e300, 0.0, 0.0),
                         (1e300, 1e-290, 0.0), (1e300, 0.0, 1e-290)], [(0, 1, 2)], 1e-295)
        for bad in ([(0, 1, 99)], [(0, 1, -1)], [(0, 1, 2.0)], [(0, 1)]):
            want = self.assert_same("triangles %r" % bad, ff.sampling.sample_triangles, pts, bad,
                                    0.3)
            self.assertEqual(self.assert_same("triangles %r flat" % bad,
                                              ff.sampling.sample_triangles_flat, pts, bad, 0.3),
                             as_flat(want))
            self.assert_same("triangles %r" % bad, ff.sampling.corner_normals, pts, bad)

    def test_flat_samples_limit_is_numpys_and_the_loops_keep_theirs(self):
        # sample_triangles_flat holds to MAX_FLAT_SAMPLES where numpy samples (no tuple a
        # sample), and to MAX_SAMPLES in the pure-Python loops, numpy's fallback included.
        self.assertTrue(ff.sampling.USE_NUMPY)  # (no numpy: this fails, it is not skipped)
        self.assertEqual(ff.sampling.flat_sample_limit(), ff.sampling.MAX_FLAT_SAMPLES)
        self.assertEqual(ff.sampling.flat_sample_limit(pure=True), ff.sampling.MAX_SAMPLES)
        self.assertGreater(ff.sampling.MAX_FLAT_SAMPLES, ff.sampling.MAX_SAMPLES)
        # A 3000-unit square at 2.45: about 3 million samples, between the two limits.
        tris = [(0, 2, 1), (1, 2, 3)]
        square = [(0.0, 0.0, 0.0), (3000.0, 0.0, 0.0), (0.0, 0.0, 3000.0), (3000.0, 0.0, 3000.0)]
        ff.sampling.check_sample_count(square, tris, 2.45, ff.sampling.flat_sample_limit())
        with self.assertRaises(ValueError) as e:
            ff.sampling.check_sample_count(square, tris, 2.45)
        self.assertIn("more than %d samples" % ff.sampling.MAX_SAMPLES, str(e.exception))
        with self.assertRaises(ValueError) as e:  # (refused before sampling: quick)
            ff.sampling.sample_triangles_flat(square, tris, 2.45, pure=True)
        self.assertIn("more than %d samples" % ff.sampling.MAX_SAMPLES, str(e.exception))
        # Integer corners past 2048 are numpy's Unsupported: the loops' limit, not numpy's.
        ints = [tuple(int(v) for v in p) for p in square]
        with self.assertRaises(ValueError) as e:
            ff.sampling.sample_triangles_flat(ints, tris, 2.45)
        self.assertIn("more than %d samples" % ff.sampling.MAX_SAMPLES, str(e.exception))
        with self.assertRaises(ValueError) as e:
            ff.sampling.sample_triangles_flat(square, tris, 1.0)  # about 18 million
        self.assertIn("more than %d samples" % ff.sampling.MAX_FLAT_SAMPLES, str(e.exception))

    def test_point_files_of_flat_samples_are_the_tuples_text(self):
        # write_point_file of the flat array (numpy's or the loops') writes the bytes it writes
        # for sample_triangles' tuples; a float64 numpy array of 6 columns too.
        import numpy
        meshes = [("grid", grid(12, 0.5), 0.13), ("box", box(), 0.3),
                  ("stairs", stairs(), 0.07), ("far grid", grid(6, 0.5, offset=1e5), 0.4)]
        pts, tris, scale = random_mesh(5)
        meshes.append(("random mesh", (pts, tris), 0.3 * scale))
        for label, (pts, tris), separation in meshes:
            normals = ff.sampling.corner_normals(pts, tris)
            tuples = ff.sampling.sample_triangles(pts, tris, separation, corner_normals=normals,
                                                  pure=True)
            self.assertTrue(tuples, label)
            texts = []
            for samples in (tuples,
                            ff.sampling.sample_triangles_flat(pts, tris, separation,
                                                              corner_normals=normals),
                            ff.sampling.sample_triangles_flat(pts, tris, separation,
                                                              corner_normals=normals, pure=True),
                            numpy.array(tuples)):
                path = os.path.join(ARGS.work_dir, "flat_text.pts")
                ff.sampling.write_point_file(path, samples, "a comment")
                with open(path, "rb") as f:
                    texts.append(f.read())
            self.assertEqual(texts[0].count(b"\n"), len(tuples) + 1, label)
            for i, text in enumerate(texts[1:], 1):
                self.assertEqual(text, texts[0], "%s: writing %d" % (label, i))
        with self.assertRaises(ValueError) as e:
            ff.sampling.write_point_file(os.path.join(ARGS.work_dir, "never.pts"),
                                         array("d", range(7)))
        self.assertIn("7 numbers", str(e.exception))
        self.assertFalse(os.path.exists(os.path.join(ARGS.work_dir, "never.pts")))

    def test_flat_samples_load_the_tuples_terrain(self):
        # Session.load_samples takes numpy's flat array as it is: the same terrain as the
        # tuples' (count, bounds, and every snap answer at the samples and between them).
        pts, tris = grid(15, 0.5)
        normals = ff.sampling.corner_normals(pts, tris)
        tuples = ff.sampling.sample_triangles(pts, tris, 0.11, corner_normals=normals)
        flat = ff.sampling.sample_triangles_flat(pts, tris, 0.11, corner_normals=normals)
        probe = [(x + 0.013, y + 0.2, z - 0.021) for x, y, z, *_ in tuples[::5]]
        with ff.Session.embedded() as s:
            a, b = s.load_samples(tuples, "tuples"), s.load_samples(flat, "flat")
            self.assertEqual(s.info(a), s.info(b))
            self.assertEqual(s.info(b)[0], len(flat) // 6)
            self.assertEqual(s.snap(a, probe), s.snap(b, probe))
            self.assertEqual(s.normal(a, probe), s.normal(b, probe))
        flat.append(0.0)  # (the array was lent to the call, not kept: it still grows)


def main():
    loader = unittest.defaultTestLoader
    suite = unittest.TestSuite([loader.loadTestsFromTestCase(BlenderAddonTest),
                                loader.loadTestsFromTestCase(SamplingNumpyTest)])
    result = unittest.TextTestRunner(verbosity=2, stream=sys.stdout).run(suite)
    failed = len(result.failures) + len(result.errors)
    skipped = len(result.skipped)
    print("%d passed, %d failed, %d skipped" % (result.testsRun - failed - skipped, failed, skipped))
    if not result.wasSuccessful():
        raise RuntimeError("blender add-on tests failed")


main()
