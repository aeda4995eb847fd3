"""The add-on's operators: Terrain Setup, Character Setup, Generate Walk, Import Walk. Every
failure is a Blender report; nothing here may raise into Blender."""

import json
import math
import os
import re
import tempfile
import threading
import uuid

import bpy
from bpy.props import EnumProperty, IntProperty, StringProperty
from bpy_extras.io_utils import ImportHelper
from mathutils import Matrix, Quaternion, Vector

from . import keying
from .axes import from_ff, to_ff, unit_scale
from .props import preferences

try:  # inside the add-on zip
    from . import footfall_client as ffc
except ImportError:  # the source tree: plugins/python on sys.path
    import footfall_client as ffc
character = ffc.character
sampling = ffc.sampling

_connection = ffc.Connection()
# Called after each chunk of Generate Walk with (operator, steps done); tests use it to stop the
# server in the middle of a walk.
chunk_hook = None


def shutdown():
    """Closes the connection and stops a footfalld the add-on started."""
    if bpy.app.timers.is_registered(_release_timer):
        bpy.app.timers.unregister(_release_timer)
    wait_for_unloads()
    _connection.shutdown()
    _terrain_scenes.clear()


def session(context):
    """The connection's session (a server that answers), once the terrains no scene uses any
    more are unloaded (see release_unused_terrains)."""
    wait_for_unloads()  # the connection is used by one thread at a time
    prefs = preferences(context)
    if prefs is None:
        s = _connection.get()
    else:
        s = _connection.get(prefs.host, prefs.port, prefs.start_local,
                            bpy.path.abspath(prefs.footfalld) if prefs.footfalld else None,
                            prefs.timeout)
    for name in unused_terrains():  # the server has just answered
        _terrain_scenes.pop(name, None)
        _connection.unload(name)
    return s


def describe_connection():
    return _connection.describe()


# -- terrains: one per scene ---------------------------------------------------------------------

def scene_terrain_loaded(scene):
    """True when `scene`'s terrain is loaded in this Blender session."""
    key = scene.footfall.terrain_key
    return bool(key) and _connection.has_terrain(key)


def scene_terrain_key(scene):
    """The name of `scene`'s terrain (set by its Terrain Setup) in the add-on's connection.
    Raises ValueError when the scene has none loaded in this Blender session."""
    key = scene.footfall.terrain_key
    if not key:
        raise ValueError("no terrain in this scene: run Terrain Setup first")
    if not _connection.has_terrain(key):
        raise ValueError("the terrain of this scene (%s) is not loaded in this Blender session: "
                         "run Terrain Setup again" % (scene.footfall.terrain_name or "unnamed"))
    return key


# The scenes (their as_pointer(), which undo keeps) each loaded terrain was loaded for or used
# by since the file was opened. A terrain stays loaded while one of them exists, even when none
# refers to it now (undoing Terrain Setup in that scene brings it back), and is unloaded once
# none does (its scenes deleted) and no scene refers to it.
_terrain_scenes = {}
# The thread unloading terrains (release_unused_terrains), while it runs. Only one thread uses
# the connection at a time: session() waits for it.
_unloader = None


def unused_terrains():
    """The names of the loaded terrains that no scene refers to and whose scenes are all gone.
    Reads the scenes only (no server call)."""
    loaded = set(_connection.terrain_names())
    if not loaded:
        return []
    live = set()
    for scene in bpy.data.scenes:
        pointer = scene.as_pointer()
        live.add(pointer)
        key = scene.footfall.terrain_key
        if key in loaded:  # a copied scene shares its original's terrain
            _terrain_scenes.setdefault(key, set()).add(pointer)
    return sorted(name for name in loaded if not _terrain_scenes.get(name, set()) & live)


def _unload(names):
    for name in names:
        try:
            _connection.unload(name)
        except Exception:  # (a failed unload is ignored: the server drops it with the session)
            pass


def wait_for_unloads():
    """Waits for the unloads release_unused_terrains started. Each is one call within the
    connection's call timeout, and a call that times out disconnects the session, so that the
    ones after it make no call: a hung server holds this up to one timeout."""
    global _unloader
    if _unloader is not None:
        _unloader.join()
        _unloader = None


def release_unused_terrains():
    """Starts unloading the terrains unused_terrains() names, on a thread of its own: a hung
    server holds no one up (but the next command that calls the server, see session()). When
    unloads still run, tries again in a second, from a timer. Never raises."""
    global _unloader
    try:
        if _unloader is not None and _unloader.is_alive():
            _schedule_release(1.0)
            return
        names = unused_terrains()
        if not names:
            return
        for name in names:
            _terrain_scenes.pop(name, None)
        _unloader = threading.Thread(target=_unload, args=(names,), name="footfall unload",
                                     daemon=True)
        _unloader.start()
    except Exception:
        pass


def _release_timer():
    release_unused_terrains()
    return None  # once


def _schedule_release(delay=0.0):
    if not bpy.app.timers.is_registered(_release_timer):
        bpy.app.timers.register(_release_timer, first_interval=delay)


def scenes_changed():
    """After a depsgraph update (a scene deleted, among others): when a loaded terrain is no
    longer used, has release_unused_terrains() run from a timer, outside the operator or
    update running now. No server call; never raises."""
    try:
        if unused_terrains():
            _schedule_release()
    except Exception:
        pass


def file_loaded():
    """A file was opened (or File > New): the terrains its scenes refer to stay, now theirs,
    and the others are unloaded (in the background). Never raises."""
    try:
        _terrain_scenes.clear()
        loaded = set(_connection.terrain_names())
        for scene in bpy.data.scenes:
            if scene.footfall.terrain_key in loaded:
                _terrain_scenes.setdefault(scene.footfall.terrain_key, set()).add(
                    scene.as_pointer())
    except Exception:
        pass
    release_unused_terrains()


def _fail(op, message):
    op.report({"ERROR"}, message)
    return {"CANCELLED"}


def _error_text(e):
    if isinstance(e, ffc.FootfallError):
        return "footfall: %s (%s)" % (character.in_scene_terms(e.message, "Z"), e.status_name)
    return "footfall: %s" % e


# The most notes a walk reports one by one (as `footfall generate` prints them); the rest are
# counted.
MAX_NOTES = 20


# A position as footfall's notes write it: "(x, y, z)".
_POSITION = re.compile(r"\(-?[0-9][0-9.e+-]*, -?[0-9][0-9.e+-]*, -?[0-9][0-9.e+-]*\)")


def report_notes(op, notes, error=""):
    """The walk's notes (a start far from the terrain, a step length beyond the reach, a path's
    goal not reached), each a warning report, as `footfall generate` prints them. They, and the
    `error` reported after them (why the walk stopped), speak footfall's frame: when one gives
    a position, a last note says how to read it."""
    for note in notes[:MAX_NOTES]:
        op.report({"WARNING"}, "footfall: note: %s" % note)
    if len(notes) > MAX_NOTES:
        op.report({"WARNING"}, "footfall: note: ... and %d more notes" % (len(notes) - MAX_NOTES))
    if any(_POSITION.search(text) for text in notes[:MAX_NOTES] + [error]):
        op.report({"WARNING"}, "footfall: note: positions and lengths in footfall's messages "
                  "are footfall's: its (x, y, z), Y up in metres, is Blender's (x, -z, y) "
                  "divided by the scene's Unit Scale; the request's 'start' is the rig root")


def _status(context, text):
    try:
        if context.workspace is not None:
            context.workspace.status_text_set(text)
    except Exception:
        pass


# -- Terrain Setup ------------------------------------------------------------------------------

def _add_triangles(source, matrix, points, tris, scale):
    """Appends the triangles of `source` (an evaluated object; its mesh) in world space by
    `matrix` to `points` (footfall's frame, in metres: `scale` metres a Blender unit) and
    `tris`, wound counter-clockwise when `matrix` mirrors. An object with no mesh (an empty,
    a light) adds nothing."""
    # (Only objects with geometry: asked of an empty, to_mesh printed "Error: Object does not
    # have geometry data" to the console before it raised.)
    if source.type not in ("MESH", "CURVE", "SURFACE", "META", "FONT"):
        return
    try:
        mesh = source.to_mesh()
    except RuntimeError:
        return
    if mesh is None:
        return
    try:
        mesh.calc_loop_triangles()
        base = len(points)
        points.extend(to_ff(matrix @ v.co, scale) for v in mesh.vertices)
        mirrored = matrix.determinant() < 0
        for t in mesh.loop_triangles:
            a, b, c = (base + i for i in t.vertices)
            tris.append((a, c, b) if mirrored else (a, b, c))
    finally:
        source.to_mesh_clear()


def mesh_triangles(context, obj):
    """The points (footfall's frame) and triangles of `obj` as evaluated (modifiers count),
    with the instances it makes (a Geometry Nodes modifier's Instance on Points, its instancing
    of vertices or faces), each where the viewport shows it. Points in metres (unit_scale)."""
    depsgraph = context.evaluated_depsgraph_get()
    points, tris = [], []
    scale = unit_scale(context.scene)
    # An instancer the viewport hides ("Show Instancer" off for its vertex or face instancing)
    # is no terrain: its own faces were sampled, and feet stood on a plane nobody sees.
    if obj.instance_type not in ("VERTS", "FACES") or obj.show_instancer_for_viewport:
        _add_triangles(obj.evaluated_get(depsgraph), obj.matrix_world, points, tris, scale)
    for inst in depsgraph.object_instances:
        if inst.is_instance and inst.parent is not None and inst.parent.original == obj:
            _add_triangles(inst.object, inst.matrix_world.copy(), points, tris, scale)
    return points, tris


def mesh_samples(context, obj, separation):
    """The evaluated mesh of `obj` (and its instances, see mesh_triangles) resampled at
    `separation` [metres], in footfall's frame (metres): an array('d') of x y z nx ny nz per
    sample (sampling.sample_triangles_flat; len // 6 samples), sent and saved as it is."""
    points, tris = mesh_triangles(context, obj)
    if not tris:
        raise ValueError("%s has no faces to walk on: select a mesh, or an object that makes "
                         "faces (a curve with Extrude or Bevel, text, a collection instance)"
                         % obj.name)
    # Normals from the geometry, as `footfall generate` samples a mesh file (smooth, sharp at
    # edges past the crease angle), whatever the viewport's shading.
    # (Refused as sample_triangles_flat will, before the slow corner normals.)
    sampling.check_sample_count(points, tris, separation, sampling.flat_sample_limit())
    normals = sampling.corner_normals(points, tris)
    samples = sampling.sample_triangles_flat(points, tris, separation, corner_normals=normals)
    # (It was sent, and refused as "blender: no samples", naming no object.)
    if not samples:
        raise ValueError("%s has faces of no area to walk on (a scale of 0 on an axis?)"
                         % obj.name)
    return samples


class FOOTFALL_OT_terrain_setup(bpy.types.Operator):
    """Send the selected mesh (resampled at the point separation) or a point file to footfalld"""
    bl_idname = "footfall.terrain_setup"
    bl_label = "Terrain Setup"
    # A step of its own: undoing what follows keeps the scene's terrain, undoing it brings the
    # previous one back (still loaded: a scene's terrains stay loaded while the scene exists).
    bl_options = {"REGISTER", "UNDO"}

    save_points: StringProperty(name="Save samples", subtype="FILE_PATH", default="",
                                description="Also write the samples sent as a point file")

    def execute(self, context):
        settings = context.scene.footfall
        # The separation is in scene units (shown in the scene's), footfall's in metres.
        separation = settings.separation * unit_scale(context.scene)
        # A new key each time: a copied scene shares its original's key until either runs
        # Terrain Setup, and must not replace the other's terrain.
        key = "scene-" + uuid.uuid4().hex
        # This scene's from now on, even before it refers to it.
        _terrain_scenes[key] = {context.scene.as_pointer()}
        try:
            s = session(context)
            if settings.terrain_source == "FILE":
                path = bpy.path.abspath(settings.terrain_file)
                if not path:
                    return _fail(self, "footfall: choose a terrain file first")
                terrain = _connection.load_file(key, path, separation)
                name = os.path.basename(path)
            else:
                # Any object whose faces the viewport shows: a mesh, a curve, text or surface
                # (as evaluated), a collection instance (the faces of what it instances); an
                # object without faces is refused by mesh_samples. (Only meshes were taken: a
                # linked set, a collection instance, was "select a mesh".)
                obj = context.active_object
                if obj is None:
                    return _fail(self, "footfall: select a mesh for the terrain")
                samples = mesh_samples(context, obj, separation)
                if self.save_points:
                    sampling.write_point_file(bpy.path.abspath(self.save_points), samples,
                                              "footfall terrain points from Blender " + obj.name)
                terrain = _connection.load_samples(key, samples)
                name = obj.name
            count, _ = s.info(terrain)
        except (ffc.FootfallError, ValueError, OSError) as e:
            _connection.unload(key)
            _terrain_scenes.pop(key, None)
            return _fail(self, _error_text(e))
        settings.terrain_key = key
        settings.terrain_name = name
        settings.sample_count = count
        self.report({"INFO"}, "footfall: terrain %s, %d samples on %s"
                    % (name, count, _connection.describe()))
        return {"FINISHED"}


# -- Character Setup ----------------------------------------------------------------------------

# Blender's longest object name, in UTF-8 bytes; longer ones are cut at the end.
MAX_NAME_BYTES = 63


def object_name(base, suffix):
    """`base` + `suffix` as an object name: `base` cut (at a whole character) so that the
    name, with room for Blender's ".001", fits MAX_NAME_BYTES and keeps its suffix. (Blender
    cut the end off: a rig of a long name, or of a shorter one in a script of several bytes a
    character, had every empty named alike, its feet told apart by .001, .002 alone.)"""
    room = MAX_NAME_BYTES - 4 - len(suffix.encode("utf-8"))
    encoded = base.encode("utf-8")
    if len(encoded) > room:
        base = encoded[:max(room, 0)].decode("utf-8", "ignore")
    return base + suffix


def _new_objects_collection(context):
    """Where new objects go, as Blender's own Add menu puts them: the active collection, unless
    it is excluded from the view layer or not editable here (linked from a library); else the
    scene's own collection. (They all went into the scene's collection.)"""
    layer = context.view_layer.active_layer_collection if context.view_layer else None
    collection = layer.collection if layer is not None else None
    if collection is None or layer.exclude or collection.library is not None or \
            collection.override_library is not None:
        return context.scene.collection
    return collection


def _empty(context, name, display="PLAIN_AXES", size=0.2, parent=None):
    obj = bpy.data.objects.new(name, None)
    obj.empty_display_type = display
    obj.empty_display_size = size
    _new_objects_collection(context).objects.link(obj)
    if parent is not None:
        obj.parent = parent
    return obj


def _frame(up, forward):
    """A world rotation (Blender) with Z along `up` and -Y along `forward` projected."""
    z = up.normalized()
    f = forward - z * forward.dot(z)
    if f.length < 1e-9:
        f = z.orthogonal()
    y = -f.normalized()
    x = y.cross(z).normalized()
    return Matrix((x, y, z)).transposed()


def _snap(s, terrain, point, scale):
    """The terrain point nearest `point` (Blender world, `scale` metres a unit) and its
    normal, in Blender's world."""
    hold = s.snap(terrain, [to_ff(point, scale)])[0]
    if not hold.ok:
        raise ffc.FootfallError(hold.status, "no terrain near (%.3f, %.3f, %.3f)" % tuple(point),
                                "ffc_snap")
    return Vector(from_ff(hold.point, scale)), Vector(from_ff(hold.normal))


class FOOTFALL_OT_character_setup(bpy.types.Operator):
    """Set up a character on the terrain: pick its body and foot IK targets (selected objects
    named after the feet, the active one the body) or create empties; adds target and central
    locators"""
    bl_idname = "footfall.character_setup"
    bl_label = "Character Setup"
    bl_options = {"REGISTER", "UNDO"}

    # Empty: the panel's (the scene's Character file field).
    character_file: StringProperty(name="Character file", subtype="FILE_PATH")
    mode: EnumProperty(name="Rig", items=[
        ("CREATE", "Create empties", "Create a body and foot IK target empties at the 3D cursor"),
        ("PICK", "Pick selected", "Use the active object as body and selected objects named "
                                  "after the feet as IK targets")], default="CREATE")
    name: StringProperty(name="Name", default="", description="Rig name (default: the file's)")
    # Empty: the panel's (the scene's Character file unit).
    character_unit: StringProperty(name="Character file unit", default="",
                                   description="The unit the character file's lengths are in "
                                               "(m, cm, mm, in, ft, yd, km or mi)")

    def execute(self, context):
        try:
            key = scene_terrain_key(context.scene)  # before connecting, or anything made
            # The panel's buttons give no file: they take the panel's field.
            path = self.character_file or context.scene.footfall.character_file
            if not path:
                raise ValueError("choose a character file (Character Setup > Character file)")
            # The rig keeps the character in metres, footfall's unit here (as the scene's
            # lengths are sent, times the Unit Scale).
            unit = self.character_unit or context.scene.footfall.character_unit
            data = character.scaled(character.load(bpy.path.abspath(path)),
                                    character.unit_scale(unit, "m"))
            s = session(context)
            # As the generator reads it, before anything is made (a file it refuses made a
            # whole rig, and the error came only at Generate Walk).
            s.check_character(data, path)
            feet = character.rest_positions(data, path)
            terrain = _connection.terrain(key)  # uploaded again if the session changed
            return self._setup(context, s, terrain, data, feet, path)
        except (ffc.FootfallError, ValueError, OSError, TypeError, KeyError) as e:
            return _fail(self, _error_text(e))

    def _pick(self, context, feet):
        body = context.active_object
        if body is None:
            raise ValueError("select the body (active) and the foot IK targets")
        scene = context.scene
        # A rig's root and locators are never its body or IK targets (a central locator is named
        # after both its feet): with one of them active, Character Setup runs again on that
        # rig's body and IK targets (those not picked in their stead).
        parts = set()
        for o in scene.objects:
            if o.footfall_rig.is_rig:
                parts.update(rig_parts(o))
        known = {}
        if body in parts:
            rig = rig_of(scene, body).footfall_rig
            body = rig.body
            if body is None or not in_scene(scene, body):
                raise ValueError("the active rig has no body in the scene: select the body "
                                 "(active) and the foot IK targets")
            known = {f.name: f.target for f in rig.feet if in_scene(scene, f.target)}
        chosen = {}
        candidates = [o for o in context.selected_objects if o is not body and o not in parts]
        for name, _ in feet:
            for o in candidates:
                n = _without_number(o.name)  # biped_L.001 (a second rig, a duplicate) is L's
                if n == name or n.endswith(("_" + name, "." + name, "-" + name, ":" + name)):
                    chosen[name] = o
                    break
            else:
                if name in known:
                    chosen[name] = known[name]
        missing = [n for n, _ in feet if n not in chosen]
        if missing:
            raise ValueError("no selected object named after foot %s" % ", ".join(missing))
        return body, chosen

    def _setup(self, context, s, terrain, data, feet, path):
        rig_name = self.name or character.display_name(
            data, os.path.splitext(os.path.basename(path))[0])
        # The character's lengths are metres: in scene units, divided by the Unit Scale.
        scale = unit_scale(context.scene)
        height = character.body_height(data) / scale
        step = character.number(data, "step_length", 0.5) / scale
        if self.mode == "PICK":
            body, targets = self._pick(context, feet)
            origin = body.matrix_world.translation.copy()
            forward = body.matrix_world.to_3x3() @ Vector((0, -1, 0))
        else:
            body, targets = None, {}
            origin = context.scene.cursor.location.copy()
            forward = context.scene.cursor.matrix.to_3x3() @ Vector((0, -1, 0))
        ground, normal = _snap(s, terrain, origin, scale)
        multiped = not character.is_biped(data)
        up = normal if multiped else Vector((0, 0, 1))
        rot = _frame(up, forward)
        # Every snap before anything is made: a failure leaves no half-built rig.
        foot_points = {}
        for name, offset in feet:
            local = Vector(from_ff((offset[0], 0.0, offset[2]), scale))
            foot_points[name] = _snap(s, terrain, ground + rot @ local, scale)[0]
        centres = []
        for pair_name, members in character.pairs(data):
            centre = sum((foot_points[m] for m in members), Vector()) / len(members)
            centres.append((pair_name, members) + _snap(s, terrain, centre, scale))

        # Character Setup again on a rig's body or IK targets replaces that rig (a second rig
        # on the same objects had Generate Walk key the old one). Its walk is the new rig's
        # previous walk, whose keys the next Generate Walk replaces.
        walk_end_known, walk_end = True, -keying.MAX_FRAME - 1  # no walk yet
        replaced, adopted = replace_rigs(context.scene, [body] + list(targets.values()))
        for known, end in replaced:
            walk_end_known = walk_end_known and known
            walk_end = max(walk_end, end)

        root = _empty(context, object_name(rig_name, "_rig"), "ARROWS", 0.5 / scale)
        root_world = Matrix.Translation(ground) @ rot.to_4x4()
        root.matrix_world = root_world
        adopt(root, root_world, adopted)
        rig = root.footfall_rig
        rig.is_rig = True
        rig.walk_end_known, rig.walk_end = walk_end_known, walk_end
        rig.character_path = path
        rig.character_json = json.dumps(data)
        if body is None:  # a picked body keeps its rotation mode (the user's keys use it)
            body = _empty(context, object_name(rig_name, "_body"), "CUBE", 0.3 * height)
            body.rotation_mode = "QUATERNION"
        # A picked body keeps its scale (it was set to 1, the user's scaled control with it).
        body.matrix_world = (Matrix.Translation(ground + up.normalized() * height) @ rot.to_4x4()
                             @ Matrix.Diagonal(body.matrix_world.to_scale()).to_4x4())
        rig.body = body

        # Feet: on the terrain below their offset from the body (character space: +X left,
        # +Z forward; Blender: -X ... see axes.py), targets half a step in front of each foot.
        placed = {}
        for name, offset in feet:
            foot_point = foot_points[name]
            obj = targets.get(name) or _empty(context, object_name(rig_name, "_" + name),
                                             "SPHERE", 0.08 / scale)
            m = obj.matrix_world.copy()
            m.translation = foot_point
            obj.matrix_world = m
            placed[name] = (obj, foot_point)
            item = rig.feet.add()
            item.name = name
            item.target = obj
        fwd = rot @ Vector((0, -1, 0))
        for pair_name, members, point, normal in centres:
            central = _empty(context, object_name(rig_name, "_%s_center" % pair_name),
                             "CIRCLE", 0.3 / scale, parent=root)
            central.matrix_world = Matrix.Translation(point) @ _frame(normal, fwd).to_4x4()
            central.footfall_rig.is_locator = True
            for m in members:
                target = _empty(context, object_name(rig_name, "_%s_target" % m), "CONE",
                                0.06 / scale, parent=central)
                target.footfall_rig.is_locator = True
                target.matrix_world = Matrix.Translation(
                    placed[m][1] + _frame(normal, fwd) @ Vector((0, -step / 2, 0)))
        context.scene.footfall.rig = root
        context.view_layer.update()
        self.report({"INFO"}, "footfall: %s set up with %d feet" % (rig_name, len(feet)))
        return {"FINISHED"}


def _without_number(name):
    """`name` without the number Blender appends to a name already taken ("IK_L.001")."""
    head, dot, tail = name.rpartition(".")
    return head if dot and tail.isdigit() else name


def _is_locator(obj):
    """True for a central or target locator Character Setup made (older versions did not mark
    them: an empty named ..._center or ..._target, with Blender's .001 suffix or not)."""
    if obj.footfall_rig.is_locator:
        return True
    if obj.type != "EMPTY" or obj.footfall_rig.is_rig:
        return False
    return _without_number(obj.name).endswith(("_center", "_target"))


def rig_parts(rig_obj):
    """The objects Character Setup made for the rig `rig_obj`: its root and the locators under
    it (not its body or IK targets, nor anything else under it)."""
    rig = rig_obj.footfall_rig
    own = {rig.body} | {f.target for f in rig.feet}
    parts, stack = [rig_obj], list(rig_obj.children)
    while stack:
        obj = stack.pop()
        if obj not in own and _is_locator(obj):
            parts.append(obj)
            stack.extend(obj.children)
    return parts


def replace_rigs(scene, objects):
    """Removes the rigs of `scene` whose body or IK targets are among `objects` (a rig about to
    be made for them): their roots and locators. Returns (walk_end_known, walk_end) of each
    removed rig, and the objects that were under the removed objects (the bodies, the IK
    targets, anything else of the user's) as (object, the parent space it had): adopt() puts
    them under the new rig's root where they were at every frame."""
    objects = {o for o in objects if o is not None}
    rigs = [o for o in scene.objects if o.footfall_rig.is_rig and
            ({o.footfall_rig.body} | {f.target for f in o.footfall_rig.feet}) & objects]
    if not rigs:
        return [], []
    removed = set()
    for rig_obj in rigs:
        removed.update(rig_parts(rig_obj))
    removed -= objects
    adopted = []
    for obj in bpy.data.objects:
        if obj not in removed and obj.parent in removed:
            adopted.append((obj, obj.parent.matrix_world @ obj.matrix_parent_inverse))
            obj.parent = None  # (its basis kept: adopt() gives it the same space again)
    ends = [(r.footfall_rig.walk_end_known, r.footfall_rig.walk_end) for r in rigs]
    for obj in removed:
        bpy.data.objects.remove(obj)
    return ends, adopted


def adopt(root, root_world, adopted):
    """Parents the objects replace_rigs took from under a removed rig to `root` (whose world
    matrix is `root_world`), with the parent inverse that keeps the space they had: their
    location and keys, in it, keep them where they were at every frame. (Their world matrix set
    at the current frame kept them there, and played a walk keyed under the old root metres
    away.)"""
    for obj, space in adopted:
        obj.parent = root
        obj.matrix_parent_inverse = root_world.inverted_safe() @ space


# -- Generate Walk ------------------------------------------------------------------------------

def walk_request(context, rig_obj, steps, start_frame):
    """The ffc_generate request for the rig and the scene's walk settings, and the character.
    Lengths in metres: the scene's (points, the step overrides) times its Unit Scale; the walk
    says so ("unit": "m")."""
    settings = context.scene.footfall
    scale = unit_scale(context.scene)
    rig = rig_obj.footfall_rig
    data = character.parse(rig.character_json, rig.character_path or rig_obj.name)
    data = character.with_overrides(data, step_length=settings.step_length * scale,
                                    step_height=settings.step_height * scale,
                                    foot_length=settings.foot_length * scale,
                                    frames_per_step=settings.frames_per_step)
    mw = rig_obj.matrix_world
    request = {"character": data,
               "start": list(to_ff(mw.translation, scale)),
               "heading": list(to_ff(mw.to_3x3() @ Vector((0, -1, 0)))),
               "steps": int(steps), "start_frame": int(start_frame),
               "fps": context.scene.render.fps / context.scene.render.fps_base,
               # The walk's lengths are metres (the scene's times its Unit Scale): its JSON says
               # so, and Maya's Import Walk, or anything else reading it, keeps its size.
               "unit": "m"}
    if settings.foot_rotations:
        request["foot_rotations"] = True
    if settings.path is not None:
        if not in_scene(context.scene, settings.path):
            raise ValueError("the path curve %s is not in this scene (deleted from it, or "
                             "another scene's): pick another path, or clear the Path field"
                             % settings.path.name)
        request["path"] = [list(to_ff(p, scale)) for p in curve_points(context, settings.path)]
    return request


def curve_points(context, obj):
    """World points of a path curve's centre line: its spline as Blender evaluates it (at its
    resolution), without Bevel, Extrude or a 2D curve's fill, which are not the path, in the order
    of its edges: a closed (cyclic) spline ends back at its first point. Raises ValueError when
    the curve has more than one spline (walked as one line, the path jumped from one to the
    next)."""
    count = len(obj.data.splines)
    if count > 1:
        raise ValueError("path curve %s has %d splines, and one spline is expected (the walk "
                         "would jump from one to the next): in Edit Mode select the spline to "
                         "follow and use Curve > Separate (P), then pick its curve as the path"
                         % (obj.name, count))
    data = obj.data.copy()
    data.bevel_mode, data.bevel_object = "ROUND", None
    data.bevel_depth, data.extrude = 0.0, 0.0
    if data.dimensions == "2D":
        data.fill_mode = "NONE"  # a closed 2D curve's fill: its inner edges joined the path
    # The copy keeps the curve's modifiers (a Hook dragging its points, a Lattice bending it),
    # which only a depsgraph applies: it is linked to the scene for as long as it is read (an
    # object in no scene is evaluated without them, and the walk followed a path the viewport
    # did not show).
    line = obj.copy()
    line.data = data
    line.hide_viewport = False
    try:
        context.scene.collection.objects.link(line)
        evaluated = line.evaluated_get(context.evaluated_depsgraph_get())
        mesh = evaluated.to_mesh()
        try:
            chain, pieces = _edge_chain(mesh) if mesh else ([], 0)
            pts = [obj.matrix_world @ mesh.vertices[i].co for i in chain]
        finally:
            evaluated.to_mesh_clear()
    finally:
        bpy.data.objects.remove(line)
        bpy.data.curves.remove(data)
    if pieces > 1:
        # (A Mirror or an Array drew two lines, and the walk went out along one and back
        # across the gap along the other.)
        raise ValueError("path curve %s is drawn as %d separate lines by its modifiers (%s), and "
                         "one line is expected (the walk would jump from one to the next): "
                         "remove or change the modifier, or apply it and separate the line to "
                         "follow" % (obj.name, pieces,
                                     ", ".join(m.name for m in obj.modifiers) or "none"))
    # One point is a goal, as `footfall generate --path X,Y,Z` takes it (it was refused).
    if not pts:
        raise ValueError("path curve %s has no points" % obj.name)
    return pts


def _edge_chain(mesh):
    """The vertex indices of a curve's mesh along its edges (one spline's), and how many
    separate lines they make (a modifier may copy the line): a cyclic spline's closing edge
    brings its first vertex back at its end (the vertices alone lost it, and a closed path ended
    a segment short of its start). Vertices on no edge (a one-point spline) come in their
    place."""
    chain, on_edge, pieces = [], set(), 0
    for e in mesh.edges:
        a, b = e.vertices
        if not chain or chain[-1] != a:
            chain.append(a)
            pieces += 1
        chain.append(b)
        on_edge.update((a, b))
    if not on_edge:
        return list(range(len(mesh.vertices))), 1
    return chain, pieces


def in_scene(scene, obj):
    """True when `obj` is in `scene` (an object deleted from it stays in bpy.data while the
    add-on's properties refer to it)."""
    return obj is not None and scene.objects.get(obj.name) == obj


def rig_targets(scene, rig_obj):
    """The rig's {foot name: IK target} and body. Raises ValueError when one of them is no
    longer in `scene`, or in the file."""
    rig = rig_obj.footfall_rig
    feet = {f.name: f.target for f in rig.feet}
    for what, obj in [("the body", rig.body)] + [("foot %s's IK target" % n, o)
                                                 for n, o in feet.items()]:
        # Character Setup sets every one: none is one removed from the file (Outliner > Delete
        # of the data, a script), whose keys were dropped without a word.
        if obj is None:
            raise ValueError("%s of %s is no longer in the file: run Character Setup again"
                             % (what, rig_obj.name))
        if not in_scene(scene, obj):
            raise ValueError("%s of %s (%s) is no longer in the scene: run Character Setup "
                             "again" % (what, rig_obj.name, obj.name))
    return feet, rig.body


def rig_of(scene, obj):
    """The rig (root empty, in `scene`) that `obj` belongs to: the root itself, an object under
    it (its locators), its body or one of its IK targets, or an object under one of those;
    None when it belongs to no rig."""
    members = {}
    for o in scene.objects:
        rig = o.footfall_rig
        if rig.is_rig:
            members[o] = o
            for m in [rig.body] + [f.target for f in rig.feet]:
                if m is not None:
                    members.setdefault(m, o)
    while obj is not None:
        if obj in members:
            return members[obj]
        obj = obj.parent
    return None


def active_rig(context):
    """The rig of the active object (rig_of), or None."""
    obj = context.active_object
    return rig_of(context.scene, obj) if obj is not None else None


def walk_rig(context):
    """The rig Generate Walk keys: the active object's, else the scene's Rig field (the rig
    Character Setup made last). Raises ValueError when there is none, or when the field's rig
    is no longer in the scene."""
    rig_obj = active_rig(context)
    if rig_obj is not None:
        return rig_obj
    rig_obj = context.scene.footfall.rig
    if rig_obj is None or not rig_obj.footfall_rig.is_rig:
        raise ValueError("no rig: select one, or run Character Setup first")
    if not in_scene(context.scene, rig_obj):
        # (Said "no longer in the scene" of a rig of another scene too, which never was.)
        raise ValueError("the rig %s is not in this scene (deleted from it, or another "
                         "scene's): run Character Setup here" % rig_obj.name)
    return rig_obj


class FOOTFALL_OT_generate_walk(bpy.types.Operator):
    """Generate a walk with footfall and key the rig's IK targets and body"""
    bl_idname = "footfall.generate_walk"
    bl_label = "Generate Walk"
    bl_options = {"REGISTER", "UNDO"}

    chunk_steps: IntProperty(name="Steps per call", default=0, min=0,
                             description="Steps asked for per server call, keyed as they come "
                                         "(0: about a tenth of the walk)")

    def execute(self, context):
        settings = context.scene.footfall
        try:
            scene_terrain_key(context.scene)  # first: a scene without one has no rig to walk
            rig_obj = walk_rig(context)
            feet, body = rig_targets(context.scene, rig_obj)
        except ValueError as e:
            return _fail(self, "footfall: %s; nothing keyed" % e)
        if not feet:
            return _fail(self, "footfall: rig %s has no foot IK targets" % rig_obj.name)
        total = settings.steps
        chunk = self.chunk_steps or max(1, int(math.ceil(total / 10.0)))
        wm = context.window_manager
        keyed = 0
        walked = 0
        walk_text = None
        notes = []  # the last walk's
        # Where the previous walk ended (None: unknown, an older rig's), for the failure report.
        before = rig_obj.footfall_rig
        previous_end = before.walk_end if before.walk_end_known else None
        last_frame = None
        try:
            # Parents the keys cannot be computed in, before anything is keyed.
            keying.check_parents(list(feet.values()) + [body])
            # The whole walk's frames within Blender's range, before anything is keyed.
            request = walk_request(context, rig_obj, total, settings.start_frame)
            last = settings.start_frame + total * int(request["character"]["frames_per_step"])
            if last > keying.MAX_FRAME:
                raise ValueError("the walk would end at frame %d, beyond Blender's frame range "
                                 "(-%d to %d): start earlier or ask fewer steps"
                                 % (last, keying.MAX_FRAME, keying.MAX_FRAME))
            key = scene_terrain_key(context.scene)
            s = session(context)
            terrain = _connection.terrain(key)  # uploaded again if the session changed
            wm.progress_begin(0, total)
            done = 0
            # Each call asks for the walk up to `done` steps; the walk is the same for the steps
            # already keyed (the generator is deterministic), so only keys from the last keyed
            # frame on are set again (re-keying the whole walk at every call made a 1000-step
            # walk take 25 s, and longer ones ever slower). The previous walk's keys go only once
            # the first call has given a walk (a refused character kept nothing of either).
            last_frame = None
            while done < total:
                done = min(total, done + chunk)
                _status(context, "footfall: generating step %d of %d" % (done, total))
                request = walk_request(context, rig_obj, done, settings.start_frame)
                status, walk_text_new, message, notes_new = s.generate_json_with_notes(
                    terrain, request)
                if walk_text_new is not None:
                    notes = notes_new
                    walk = json.loads(walk_text_new)
                    keying.check_frames(walk)
                    frames = [k["frame"] for t in walk.get("tracks", []) for k in t.get("keys", [])]
                    walk_last = max(frames) if frames else settings.start_frame
                    rig = rig_obj.footfall_rig
                    objects = list(feet.values()) + [body]
                    # The feet's rotation keys go where this walk keys them (Foot rotations)
                    # and where the previous walk did; otherwise they are the user's.
                    turned = set(feet.values()) if settings.foot_rotations else set()
                    if walk_text is None:
                        # The previous walk's keys (up to its end, or on to the last key for a
                        # rig of an older version).
                        keying.clear_keys(objects, settings.start_frame, body,
                                          rig.walk_end if rig.walk_end_known else None,
                                          turned | (set(feet.values()) if rig.walk_turned_feet
                                                    else set()))
                    # Keys within this walk's frames so far go as it is keyed there; the user's
                    # keys after both walks stay (the walk's end is its last key, not its start
                    # plus Steps: a path walk that reached its goal early removed the user's
                    # later keys).
                    keying.clear_keys(objects, settings.start_frame if last_frame is None
                                      else last_frame + 1e-3, body, walk_last, turned)
                    rig.walk_end_known, rig.walk_end = True, walk_last
                    rig.walk_turned_feet = bool(settings.foot_rotations)
                    keying.key_walk(walk, feet, body, from_frame=last_frame)
                    last_frame = walk_last if frames else last_frame
                    keyed = sum(len(t.get("keys", [])) for t in walk.get("tracks", [])
                                if (t.get("kind") == "body" and body) or t.get("name") in feet)
                    walk_text = walk_text_new
                    stopped = walk.get("stopped")
                    # A body key a step, and one at the start.
                    walked = max((len(t.get("keys", [])) for t in walk.get("tracks", [])
                                  if t.get("kind") == "body"), default=1) - 1
                else:
                    stopped = None
                if status != 0 or stopped:
                    raise ffc.FootfallError(status if status else 1, message or stopped,
                                            "ffc_generate")
                wm.progress_update(done)
                if chunk_hook is not None:
                    chunk_hook(self, done)
                if walked < done:
                    break  # a path's goal reached: more steps asked would give the same walk
        except (ffc.FootfallError, ValueError, OSError) as e:
            if walk_text is None:  # nothing generated: the rig's keys are as they were
                return _fail(self, "%s; the rig's keys are unchanged" % _error_text(e))
            report_notes(self, notes, _error_text(e))  # before: the status bar shows the error
            # Said too: the previous walk's keys after the new ones were removed (they were
            # said to be "kept"), which Undo brings back.
            gone = ""
            if last_frame is not None and (previous_end is None or previous_end > last_frame):
                gone = ("; the previous walk's keys after frame %g are removed (Edit > Undo "
                        "brings them back)" % last_frame)
            self.report({"ERROR"}, "%s; the %d keys made up to frame %s were kept%s"
                        % (_error_text(e), keyed,
                           "%g" % last_frame if last_frame is not None else "?", gone))
            return {"FINISHED"} if keyed else {"CANCELLED"}
        finally:
            if walk_text is not None:
                keying.store_walk_text("footfall_walk.json", walk_text)
            try:
                wm.progress_end()
            except Exception:
                pass
            _status(context, None)
        # The steps walked (a path walk that reached its goal early was said to walk them all).
        self.report({"INFO"}, "footfall: %d steps%s, %d keys on %s"
                    % (walked, " (the path's goal reached; %d asked)" % total
                       if walked < total else "", keyed, rig_obj.name))
        report_notes(self, notes)  # after: the status bar shows the last report
        return {"FINISHED"}


# -- Import Walk --------------------------------------------------------------------------------

class FOOTFALL_OT_import_walk(bpy.types.Operator, ImportHelper):
    """Import a footfall walk (JSON or glTF) onto the active rig (or onto new empties)"""
    bl_idname = "footfall.import_walk"
    bl_label = "Import footfall Walk"
    bl_options = {"REGISTER", "UNDO"}

    filter_glob: StringProperty(default="*.json;*.gltf;*.glb", options={"HIDDEN"})

    def execute(self, context):
        path = self.filepath
        rig_obj = active_rig(context)  # before the glTF importer changes the selection
        try:
            if path.lower().endswith((".gltf", ".glb")):
                walk = self._walk_from_gltf(context, path)
            else:
                walk = character.read_json(path, "walk file")
            character.check_walk(walk, path)  # before anything is made
            # In metres, footfall's unit here (a walk generated with --unit cm was keyed 100
            # times too large).
            walk = character.walk_in_unit(walk, "m")
            keying.check_frames(walk)
            # (A walk whose tracks had no keys made their empties, or cleared the rig's keys from
            # frame 0 on, and then reported that it had no keys.)
            if not any(t.get("keys") for t in walk["tracks"]):
                return _fail(self, "footfall: %s has no keys" % path)
            crowd = sorted({t.get("character", "") for t in walk["tracks"]})
            if rig_obj is not None:
                if len(crowd) > 1:
                    raise ValueError("a crowd walk (%d characters) goes onto new empties, one set "
                                     "per character: make no rig's object active first"
                                     % len(crowd))
                feet, body = rig_targets(context.scene, rig_obj)
                keying.check_parents(list(feet.values()) + [body])
                # Nothing is cleared unless the walk keys something of this rig, and only what
                # it keys: another character's walk is refused.
                try:
                    keyed, keys_body = character.rig_tracks(walk, feet, body is not None, path)
                except ValueError as e:
                    return _fail(self, "footfall: %s; the rig's keys are unchanged" % e)
                feet = {n: feet[n] for n in keyed}
                body = body if keys_body else None
                sets = [(walk, feet, body, rig_obj)]
            else:
                base = os.path.splitext(os.path.basename(path))[0]
                sets = []
                for who in crowd:  # one set of empties per character of a crowd
                    part = {"tracks": [t for t in walk["tracks"] if t.get("character", "") == who]}
                    name = "%s_%s" % (base, who) if who else base
                    sets.append((part,) + self._empties(context, part, name) + (None,))
            count = 0
            for part, feet, body, rig_obj in sets:
                frames = [k["frame"] for t in part["tracks"] for k in t.get("keys", [])]
                first = min(frames, default=0)
                # Feet the walk turns (it was generated with foot rotations), and on a rig
                # those its last walk turned: their rotation keys go too.
                turned = {feet[t["name"]] for t in part["tracks"] if t.get("name") in feet and
                          t.get("kind", "foot") == "foot" and
                          keying.turns(False, t.get("keys", []))}
                previous = set()
                if rig_obj is not None and rig_obj.footfall_rig.walk_turned_feet:
                    previous = set(feet.values())
                keying.clear_keys(list(feet.values()) + [body], first, body,
                                  turned=turned | previous)
                count += keying.key_walk(part, feet, body)
                if rig_obj is not None and frames:
                    # The rig's walk now ends here (its keys after `first` are gone): a later
                    # Generate Walk replaces them up to here.
                    rig = rig_obj.footfall_rig
                    rig.walk_end_known, rig.walk_end = True, max(frames)
                    rig.walk_turned_feet = bool(turned)
        except (ffc.FootfallError, OSError, ValueError, KeyError, TypeError) as e:
            why = e.message if isinstance(e, ffc.FootfallError) else e
            return _fail(self, "footfall: cannot import %s: %s" % (path, why))
        if count == 0:
            return _fail(self, "footfall: %s has no keys" % path)
        self.report({"INFO"}, "footfall: %d keys imported from %s" % (count, os.path.basename(path)))
        return {"FINISHED"}

    def _empties(self, context, walk, name):
        feet, body, scale = {}, None, unit_scale(context.scene)  # (sizes in metres)
        for track in walk["tracks"]:
            if track.get("kind") == "body":
                body = _empty(context, object_name(name, "_body"), "CUBE", 0.3 / scale)
                body.rotation_mode = "QUATERNION"
            else:
                feet[track["name"]] = _empty(context, object_name(name, "_" + track["name"]),
                                             "SPHERE", 0.08 / scale)
        return feet, body

    def _walk_from_gltf(self, context, path):
        """Imports the glTF with Blender's importer and reads its node animation back as a
        walk dict (positions converted back to footfall's frame), then removes what it made
        and gives back the selection and the active object."""
        layer = context.view_layer
        active, selected = layer.objects.active, list(context.selected_objects)
        try:
            return self._read_gltf(path)
        finally:
            for obj in selected:
                # (Only where it can be: a script's context may name objects of another view
                # layer, and select_set raised there, failing the import after it had read.)
                if layer.objects.get(obj.name) == obj:
                    obj.select_set(True)
            if active is None or layer.objects.get(active.name) == active:
                layer.objects.active = active

    def _read_gltf(self, path):
        before = set(bpy.data.objects)
        actions_before = set(bpy.data.actions)
        # Blender's importer switches a Workbench scene to EEVEE (for the materials it makes):
        # the walk read, the scene's render engine is the user's again.
        render = bpy.context.scene.render
        engine = render.engine
        try:
            result = bpy.ops.import_scene.gltf(filepath=path)
        except RuntimeError as e:  # the importer's own error on a damaged file
            for obj in set(bpy.data.objects) - before:
                bpy.data.objects.remove(obj)
            raise ValueError("Blender's glTF importer: %s" % str(e).strip()) from None
        finally:
            if render.engine != engine:
                render.engine = engine
        if "FINISHED" not in result:
            raise ValueError("Blender's glTF importer failed")
        made = [o for o in bpy.data.objects if o not in before]
        bpy.context.view_layer.update()  # the parents' world matrices, for _parent_transform
        # The importer divides the glTF's metres by the Unit Scale: back to metres.
        scale = unit_scale(bpy.context.scene)
        tracks = []
        for obj in made:
            action = obj.animation_data.action if obj.animation_data else None
            if action is None:
                continue
            origin, parent_matrix = _parent_transform(obj, scale)
            curves = {(fc.data_path, fc.array_index): fc for fc in action.fcurves}
            frames = sorted({kp.co[0] for fc in action.fcurves for kp in fc.keyframe_points})
            keys = []
            for f in frames:
                key = {"frame": f}
                if ("location", 0) in curves:
                    local = [curves[("location", i)].evaluate(f) for i in range(3)]
                    if parent_matrix is not None:
                        local = parent_matrix @ Vector(local)
                    # Added in double: the origin of a far walk is what keeps it precise.
                    key["position"] = [o + c for o, c in zip(origin, to_ff(local, scale))]
                if ("rotation_quaternion", 0) in curves:
                    from .axes import quat_to_ff
                    q = Quaternion([curves[("rotation_quaternion", i)].evaluate(f)
                                    for i in range(4)])
                    if parent_matrix is not None:
                        q = parent_matrix.to_quaternion() @ q
                    key["rotation"] = list(quat_to_ff(q))
                keys.append(key)
            # footfall's glTF names each node's track and kind in its extras (custom properties
            # once imported); a glTF from elsewhere falls back to the node name.
            name = str(obj.get("track") or obj.name.split(".")[0])
            kind = str(obj.get("kind") or ("body" if ("rotation_quaternion", 0) in curves
                                           else "foot"))
            track = {"name": name, "kind": kind, "keys": keys}
            if obj.get("character"):  # a crowd's: imported per character, as from JSON
                track["character"] = str(obj.get("character"))
            tracks.append(track)
        for obj in made:
            bpy.data.objects.remove(obj)
        for action in set(bpy.data.actions) - actions_before:
            bpy.data.actions.remove(action)
        return {"tracks": tracks}


def _parent_transform(obj, scale):
    """How an imported glTF node's local keys become world ones: (origin, matrix). A footfall
    glTF of a far walk parents the track nodes to one root node, "footfall_origin" (custom
    property kind "origin"), that only translates: the origin is its translation in footfall's
    frame, in double precision (its "origin" property, else its location), added to each key
    in double; matrix is None. Any other parent (a glTF from elsewhere): origin 0 and its world
    matrix (32-bit, as Blender holds it). No parent: origin 0, matrix None. `scale`: metres
    per Blender unit (the origin is in metres)."""
    zero = (0.0, 0.0, 0.0)
    parent = obj.parent
    if parent is None:
        return zero, None
    if parent.get("kind") == "origin" and parent.parent is None:
        try:
            origin = tuple(float(c) for c in parent["origin"])
        except (KeyError, TypeError, ValueError):
            origin = ()
        if len(origin) != 3 or not all(math.isfinite(c) for c in origin):
            origin = to_ff(parent.location, scale)
        return origin, None
    return zero, parent.matrix_world @ obj.matrix_parent_inverse


classes = [FOOTFALL_OT_terrain_setup, FOOTFALL_OT_character_setup, FOOTFALL_OT_generate_walk,
           FOOTFALL_OT_import_walk]
