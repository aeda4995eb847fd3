"""footfall for Maya (maya.cmds): Terrain Setup, Character Setup and Generate Walk over footfalld,
thin over the shared package footfall_client. Maya is Y up and characters face +Z, as footfall,
so no axis conversion happens here. NOT RUN HERE: no Maya on the build machines (see
plugins/README.md); the logic it shares with Blender is tested through footfall_client.

    import footfall_maya; footfall_maya.show()
"""

import json
import math
import uuid

import maya.cmds as mc

try:
    from . import footfall_client as ffc  # packed next to this package
except ImportError:
    import footfall_client as ffc

character = ffc.character

_connection = ffc.Connection()
_settings = {"host": "127.0.0.1", "port": 7407, "start_local": True, "footfalld": "",
             "timeout": 10.0}
# The scene's terrain: its name in the connection, kept in the scene's fileInfo under this key
# (saved with the file, gone with File > New). One name served every scene: a new or another
# scene walked on the terrain of the one before, without a word.
TERRAIN_INFO = "footfallTerrain"
RIG_ATTR = "footfallCharacter"   # string attribute on the rig group: the character JSON
# Double attribute on the rig group: the last frame its walk keyed (Generate Walk or Import);
# NO_WALK before any. A rig without it (an older version's) has an unknown end.
WALK_END_ATTR = "footfallWalkEnd"
TURNED_FEET_ATTR = "footfallWalkTurnedFeet"  # its last walk keyed the handles' rotate
NO_WALK = -1e9
WINDOW = "footfallWindow"


def _error(message):
    """Every failure ends here: a warning in the script line and a dialog, never an exception
    into Maya."""
    mc.warning("footfall: " + message)
    try:
        mc.confirmDialog(title="footfall", message=message, button=["OK"])
    except RuntimeError:  # batch mode
        pass


# The most notes a walk shows one by one (as `footfall generate` prints them); the rest are
# counted.
MAX_NOTES = 20


def _show_notes(notes):
    """The walk's notes (a start far from the terrain, a step length beyond the reach, a path's
    goal not reached), each a warning in the script line, as `footfall generate` prints them."""
    if not notes:
        return
    from maya.api import OpenMaya as om  # noqa: N813 (MGlobal.displayWarning)
    for note in notes[:MAX_NOTES]:
        om.MGlobal.displayWarning("footfall: note: " + note)
    if len(notes) > MAX_NOTES:
        om.MGlobal.displayWarning("footfall: note: ... and %d more notes"
                                  % (len(notes) - MAX_NOTES))


def _session():
    return _connection.get(_settings["host"], _settings["port"], _settings["start_local"],
                           _settings["footfalld"] or None, _settings["timeout"])


def _guard(fn):
    def run(*args, **kwargs):
        try:
            return fn(*args, **kwargs)
        except ffc.FootfallError as e:
            _error("%s (%s)" % (ffc.character.in_scene_terms(e.message, "Y"), e.status_name))
        except (ValueError, OSError, RuntimeError) as e:
            _error(str(e))
        except Exception as e:  # anything else is a bug: reported, never a traceback into Maya
            _error("%s: %s" % (type(e).__name__, e))
        return None
    run.__name__ = fn.__name__
    return run


# -- Terrain Setup --------------------------------------------------------------------------------

def _mesh_samples(mesh, separation):
    from maya.api import OpenMaya as om  # noqa: N813 (only here: the API 2.0 mesh reader)
    sel = om.MSelectionList()
    sel.add(mesh)
    dag = sel.getDagPath(0)
    fn = om.MFnMesh(dag)
    # The API gives internal units (centimetres) whatever the scene's linear unit; xform,
    # pointOnCurve and the separation are in the scene's (UI) unit: in a metre scene the
    # terrain was 100 times too large for the character placed on it.
    to_ui = om.MDistance.internalToUI(1.0)
    points = [(p.x * to_ui, p.y * to_ui, p.z * to_ui) for p in fn.getPoints(om.MSpace.kWorld)]
    counts, verts = fn.getTriangles()
    # A mirroring transform (a negative scale) turns the winding in world space: wound back,
    # the normals face as Maya shows them (they pointed into the ground).
    order = (0, 2, 1) if dag.inclusiveMatrix().det3x3() < 0 else (0, 1, 2)
    tris = [tuple(verts[i + k] for k in order) for i in range(0, len(verts), 3)]
    # Normals from the geometry, as `footfall generate` samples a mesh file. The samples: one
    # array('d') of x y z nx ny nz each (len // 6 of them), sent as it is. (Refused as
    # sample_triangles_flat will, before the slow corner normals.)
    ffc.sampling.check_sample_count(points, tris, separation, ffc.sampling.flat_sample_limit())
    normals = ffc.sampling.corner_normals(points, tris)
    return ffc.sampling.sample_triangles_flat(points, tris, separation, corner_normals=normals)


def _require_y_up():
    """Raises ValueError in a Z-up scene: the plugin places characters and asks for walks with
    Y up, as footfall's files are (in a Z-up scene the body stood sideways and Generate Walk
    stopped at once: "ground leans 84 deg")."""
    if str(mc.upAxis(q=True, axis=True)).lower() != "y":
        raise ValueError("this scene is Z-up, and footfall's Maya plugin works in Y-up scenes: "
                         "set Preferences > Settings > World Coordinate System > Up axis to Y")


@_guard
def terrain_setup(separation=0.25, point_file=None):
    """Sends the selected mesh resampled at `separation` [scene units], or loads `point_file`.
    Returns the sample count."""
    _require_y_up()
    s = _session()
    _release_other_terrains()
    if point_file:
        terrain = _connection.load_file(_new_scene_terrain(), point_file, separation)
    else:
        sel = mc.ls(selection=True, dag=True, type="mesh", noIntermediate=True)
        if not sel:
            raise ValueError("select a mesh for the terrain")
        samples = _mesh_samples(sel[0], separation)
        terrain = _connection.load_samples(_new_scene_terrain(), samples)
    count, _ = s.info(terrain)
    mc.inViewMessage(amg="footfall: %d terrain samples" % count, pos="topCenter", fade=True)
    return count


def _scene_terrain_name():
    """The name of the open scene's terrain (its fileInfo), or None when it has none."""
    values = mc.fileInfo(TERRAIN_INFO, query=True) or []
    return values[0] if values and values[0] else None


def _new_scene_terrain():
    """The name Terrain Setup loads the open scene's terrain under: its own (replaced once the
    new one is loaded), or a new one recorded in the scene."""
    name = _scene_terrain_name()
    if name is None:
        name = "scene-" + uuid.uuid4().hex
        mc.fileInfo(TERRAIN_INFO, name)
    return name


def _release_other_terrains():
    """Unloads the terrains of scenes no longer open (Maya has one open at a time)."""
    name = _scene_terrain_name()
    for other in _connection.terrain_names():
        if other != name:
            _connection.unload(other)


def _scene_terrain_key():
    """The name of the open scene's terrain (no server call). Raises ValueError when the scene
    has none, or none loaded in this Maya session."""
    name = _scene_terrain_name()
    if name is None:
        raise ValueError("no terrain in this scene: run Terrain Setup first")
    if not _connection.has_terrain(name):
        raise ValueError("the terrain of this scene is not loaded in this Maya session: run "
                         "Terrain Setup again")
    return name


def _scene_terrain():
    """The id of the open scene's terrain on the current session (uploaded again if the session
    changed)."""
    return _connection.terrain(_scene_terrain_key())


# -- Character Setup ------------------------------------------------------------------------------

def _snap(s, terrain, point):
    hold = s.snap(terrain, [point])[0]
    if not hold.ok:
        raise ValueError("no terrain near (%.3f, %.3f, %.3f)" % tuple(point))
    return hold.point, hold.normal


def _ui_angles():
    """The function from degrees to the scene's angle unit, which xform takes rotations in: in
    a scene set to radians, degrees turned a node 57.3 times too far."""
    return math.radians if mc.currentUnit(query=True, angle=True) == "rad" else float


def _scene_linear_unit():
    """The scene's linear unit, as Maya names it short ("cm")."""
    return str(mc.currentUnit(query=True, linear=True))


def _orient(node, up, forward):
    """Turns `node` (world space) so that its Y is `up` and its Z `forward` across it."""
    euler = ffc.rotation.quat_to_euler_xyz(ffc.rotation.quat_from_frame(up, forward))
    to_ui_angle = _ui_angles()
    mc.xform(node, ws=True, ro=[to_ui_angle(a) for a in euler])


@_guard
def character_setup(character_file, name=None, ik_handles=None, body=None, character_unit="m"):
    """Sets up a character at the origin facing +Z (or at `body`, facing as it does): foot IK
    handles given as {foot name: handle} (created as locators when None), target locators half
    a step ahead of each foot under a central locator per foot pair, aligned to the terrain
    normal. The character file's lengths are in `character_unit` (metres, as the shipped
    files), scaled to the scene's linear unit (100 times in Maya's default centimetres); the rig
    keeps the character so scaled, and Generate Walk walks it. Checks the file as the generator
    reads it, and snaps everything, before anything is made; one undo chunk."""
    _require_y_up()
    _scene_terrain_key()  # (no terrain: before anything else)
    scene_unit = _scene_linear_unit()
    scale = character.unit_scale(character_unit, scene_unit)
    data = character.scaled(character.load(character_file), scale)
    s = _session()
    s.check_character(data, character_file)
    feet = character.rest_positions(data, character_file)
    terrain = _scene_terrain()
    name = name or character.display_name(data, "character")
    origin = mc.xform(body, q=True, ws=True, t=True) if body else [0.0, 0.0, 0.0]
    forward = (0.0, 0.0, 1.0)
    if body:
        m = mc.xform(body, q=True, ws=True, m=True)
        forward = ffc.vectors.unit((m[8], 0.0, m[10])) or forward  # its Z on the ground (bipeds: Y up)
    left = ffc.vectors.cross((0.0, 1.0, 0.0), forward)
    ground, normal = _snap(s, terrain, origin)
    placed = {}
    for foot, rest in feet:
        at = [ground[i] + left[i] * rest[0] + forward[i] * rest[2] for i in range(3)]
        placed[foot] = _snap(s, terrain, at)[0]
    centres = []
    for pair, members in character.pairs(data):
        centre = [sum(placed[m][i] for m in members) / len(members) for i in range(3)]
        centres.append((pair, members) + _snap(s, terrain, centre))
    step = character.number(data, "step_length", 0.6)
    height = character.body_height(data)
    mc.undoInfo(openChunk=True, chunkName="footfall character setup")
    try:
        rig = mc.group(empty=True, name=name + "_rig")
        mc.addAttr(rig, longName=RIG_ATTR, dataType="string")
        mc.setAttr(rig + "." + RIG_ATTR, json.dumps(data), type="string")
        _set_walk_end(rig, NO_WALK)
        mc.xform(rig, ws=True, t=ground)
        _orient(rig, (0.0, 1.0, 0.0), forward)  # Generate Walk heads along the rig's Z
        if not body:
            body = mc.spaceLocator(name=name + "_body")[0]
        mc.xform(body, ws=True, t=(ground[0], ground[1] + height, ground[2]))
        mc.addAttr(rig, longName="footfallBody", attributeType="message")
        mc.connectAttr(body + ".message", rig + ".footfallBody")
        for index, (foot, _) in enumerate(feet):
            handle = (ik_handles or {}).get(foot) or mc.spaceLocator(name="%s_%s" % (name, foot))[0]
            mc.xform(handle, ws=True, t=placed[foot])
            # By the foot's index: a foot name need not be a valid Maya attribute name.
            attr = _foot_attr(index)
            mc.addAttr(rig, longName=attr, attributeType="message")
            mc.connectAttr(handle + ".message", rig + "." + attr)
        for pair, members, point, normal in centres:
            central = mc.parent(mc.spaceLocator(name="%s_%s_center" % (name, pair))[0], rig)[0]
            mc.xform(central, ws=True, t=point)
            _orient(central, normal, forward)  # Y along the normal, Z the heading across it
            for m in members:
                target = mc.parent(mc.spaceLocator(name="%s_%s_target" % (name, m))[0],
                                   central)[0]
                p = placed[m]
                mc.xform(target, ws=True,
                         t=[p[i] + forward[i] * step / 2 for i in range(3)])
    finally:
        mc.undoInfo(closeChunk=True)
    if scale != 1:
        mc.inViewMessage(amg="footfall: %s scaled from %s to this scene's %s (x %g)"
                         % (name, character_unit, scene_unit, scale), pos="topCenter", fade=True)
    return rig


# -- Generate Walk --------------------------------------------------------------------------------

def _foot_attr(index):
    """The rig's message attribute linking foot `index` (file order) to its IK handle."""
    return "footfallFoot%d" % index


def _walk_end(rig):
    """The last frame the rig's previous walk keyed (NO_WALK: none yet), or None when unknown
    (a rig set up by an older version)."""
    if not mc.attributeQuery(WALK_END_ATTR, node=rig, exists=True):
        return None
    return float(mc.getAttr(rig + "." + WALK_END_ATTR))


def _set_walk_end(rig, frame):
    if not mc.attributeQuery(WALK_END_ATTR, node=rig, exists=True):
        mc.addAttr(rig, longName=WALK_END_ATTR, attributeType="double")
    mc.setAttr(rig + "." + WALK_END_ATTR, float(frame))


def _turned_feet(rig):
    """Whether the rig's last walk keyed its IK handles' rotate (Foot rotations)."""
    return bool(mc.attributeQuery(TURNED_FEET_ATTR, node=rig, exists=True) and
                mc.getAttr(rig + "." + TURNED_FEET_ATTR))


def _set_turned_feet(rig, turned):
    if not mc.attributeQuery(TURNED_FEET_ATTR, node=rig, exists=True):
        mc.addAttr(rig, longName=TURNED_FEET_ATTR, attributeType="bool")
    mc.setAttr(rig + "." + TURNED_FEET_ATTR, bool(turned))


def _cut(nodes, first, last, turned):
    """Removes the nodes' translate keys from frame `first` to `last` (none when `last` is
    before `first`), and the rotate keys of those in `turned` (the body, and the handles a walk
    turns or turned): a handle's own rotate keys are the user's otherwise."""
    if nodes and last >= first:
        mc.cutKey(nodes, time=(first, last), attribute="translate", clear=True)
        rotated = [n for n in nodes if n in turned]
        if rotated:
            mc.cutKey(rotated, time=(first, last), attribute="rotate", clear=True)


def _rig_targets(rig):
    data = json.loads(mc.getAttr(rig + "." + RIG_ATTR))
    feet = {}
    for index, (foot, _) in enumerate(character.feet(data)):
        attr = _foot_attr(index)
        if not mc.attributeQuery(attr, node=rig, exists=True):
            attr = "footfallFoot_" + foot  # a rig made before attributes went by index
        src = mc.listConnections(rig + "." + attr, source=True) or []
        if src:
            feet[foot] = src[0]
    body = (mc.listConnections(rig + ".footfallBody", source=True) or [None])[0]
    return data, feet, body


def key_walk(walk, feet, body, from_frame=None):
    """Keys the walk (footfall JSON dict) on the IK handles and body, as the seed's tool did;
    with `from_frame`, only its keys from that frame on (those before are keyed already). The
    body is keyed turned, and so is a handle whose every key has a rotation (a walk generated
    with foot rotations)."""
    count = 0
    to_ui_angle = _ui_angles()
    for track in walk.get("tracks", []):
        is_body = track.get("kind") == "body"
        node = body if is_body else feet.get(track.get("name"))
        if not node:
            continue
        keys = track.get("keys", [])
        turns = is_body or (bool(keys) and all("rotation" in key for key in keys))
        order = 2
        if turns:
            # A node with rotation keys of its own keeps its rotate order, the walk keyed in it
            # (setting another reinterpreted those keys: a pose keyed before the walk turned).
            # Any other turns in ZXY, as the MEL export: heading is rotateY alone, so a body
            # heading +-X is not at gimbal lock (in Maya's default XYZ it is).
            if mc.keyframe(node, attribute="rotate", query=True, keyframeCount=True):
                order = int(mc.getAttr(node + ".rotateOrder"))
            else:
                mc.setAttr(node + ".rotateOrder", 2)
        # Euler degrees in the node's rotate order (ZXY: R = Ry * Rx * Rz, as the MEL export
        # keys them), each nearest its neighbour's, keyed or not.
        rotated = [n for n, key in enumerate(keys) if turns and "rotation" in key]
        eulers = dict(zip(rotated, ffc.rotation.continuous_eulers(
            [keys[n]["rotation"] for n in rotated], order)))
        for n, key in enumerate(keys):
            frame = key["frame"]
            euler = eulers.get(n)
            if from_frame is not None and frame < from_frame:
                continue
            # Linear in and out tangents, as the MEL and glTF exports (the user's default
            # tangent would overshoot between a foot's keys, through the ground).
            mc.xform(node, ws=True, t=key["position"])
            mc.setKeyframe(node, attribute="translate", time=frame,
                           inTangentType="linear", outTangentType="linear")
            if euler is not None:
                mc.xform(node, ws=True, ro=[to_ui_angle(a) for a in euler])
                mc.setKeyframe(node, attribute="rotate", time=frame,
                               inTangentType="linear", outTangentType="linear")
            count += 1
    return count


@_guard
def generate_walk(rig, steps=8, start_frame=1, frames_per_step=0, step_length=0.0,
                  step_height=0.0, path=None, chunk_steps=0, foot_length=0.0,
                  foot_rotations=False):
    """Generates `steps` steps for `rig` and keys them; keys made before a failure stay (the
    error says how many). `foot_rotations`: the IK handles are keyed turned too, each foot on
    its ground facing the body's heading (as the MEL export's --foot-rotations). One undo
    chunk; progress in the main progress bar. The walk's notes are shown as warnings."""
    _require_y_up()
    _scene_terrain_key()  # (no terrain: before anything else)
    data, feet, body = _rig_targets(rig)
    data = character.with_overrides(data, step_length=step_length, step_height=step_height,
                                    frames_per_step=frames_per_step, foot_length=foot_length)
    start = mc.xform(rig, q=True, ws=True, t=True)
    m = mc.xform(rig, q=True, ws=True, m=True)
    request = {"character": data, "start": start, "heading": [m[8], m[9], m[10]],
               "start_frame": start_frame}
    if path:
        request["path"] = _curve_points(path)
    if foot_rotations:
        request["foot_rotations"] = True
    chunk = chunk_steps or max(1, int(math.ceil(steps / 10.0)))
    s = _session()
    terrain = _scene_terrain()
    bar = _main_progress_bar()
    if bar:
        mc.progressBar(bar, e=True, beginProgress=True, maxValue=steps,
                       status="footfall: generating")
    mc.undoInfo(openChunk=True, chunkName="footfall generate walk")
    notes = []  # the last walk's
    keyed = 0
    try:
        done = 0
        last_frame = None
        nodes = [n for n in list(feet.values()) + [body] if n]
        turned = {body} | (set(feet.values()) if foot_rotations else set())
        while done < steps:
            done = min(steps, done + chunk)
            request["steps"] = done
            status, text, message, notes_new = s.generate_json_with_notes(terrain, request)
            walk = json.loads(text) if text is not None else None
            if walk is not None:
                notes = notes_new
                frames = [k["frame"] for t in walk.get("tracks", []) for k in t.get("keys", [])]
                walk_last = max(frames) if frames else start_frame
                if last_frame is None:
                    # The previous walk goes once this one has keys (a refused request keeps
                    # it), up to its end (on to the last key for a rig of an older version):
                    # the user's keys after both walks stay (they were all cut).
                    # The handles' rotate keys go where the previous walk turned them.
                    old_end = _walk_end(rig)
                    _cut(nodes, start_frame, 1e9 if old_end is None else old_end,
                         turned | (set(feet.values()) if _turned_feet(rig) else set()))
                # Keys within this walk's frames go as it is keyed there.
                _cut(nodes, start_frame if last_frame is None else last_frame + 1e-3,
                     walk_last, turned)
                _set_walk_end(rig, walk_last)
                _set_turned_feet(rig, foot_rotations)
                # Each call gives the walk so far: only its new keys are set.
                key_walk(walk, feet, body, from_frame=last_frame)
                keyed = sum(len(t.get("keys", [])) for t in walk.get("tracks", [])
                            if (body if t.get("kind") == "body" else feet.get(t.get("name"))))
                last_frame = max(frames) if frames else last_frame
            stopped = walk.get("stopped") if walk is not None else None
            if status != 0 or stopped:
                message = message or stopped or "no walk"
                if keyed:
                    message += "; %d keys made before it were kept" % keyed
                raise ffc.FootfallError(status or 1, message, "generate")
            if bar:
                mc.progressBar(bar, e=True, progress=done)
    finally:
        mc.undoInfo(closeChunk=True)
        if bar:
            mc.progressBar(bar, e=True, endProgress=True)
        _show_notes(notes)  # (before the error's dialog, when it failed)
    return done


def _curve_points(curve):
    """Points along a NURBS curve (on it, not its control vertices), four per span."""
    spans = max(1, mc.getAttr(curve + ".spans"))
    lo, hi = mc.getAttr(curve + ".minValue"), mc.getAttr(curve + ".maxValue")
    n = 4 * spans
    return [mc.pointOnCurve(curve, parameter=lo + (hi - lo) * i / n, position=True)
            for i in range(n + 1)]


def _main_progress_bar():
    try:
        import maya.mel
        bar = maya.mel.eval("$footfallTmp = $gMainProgressBar")
    except (ImportError, RuntimeError):
        return None
    return bar if bar and mc.progressBar(bar, exists=True) else None


@_guard
def import_walk(path, rig=None):
    """Keys a footfall walk JSON file onto `rig` (or new locators, one set per character of a
    crowd). Nothing is changed unless the walk keys something. One undo chunk (one undo took
    back one key)."""
    walk = ffc.character.read_json(path, "walk file")
    ffc.character.check_walk(walk, path)  # before any locator is made
    # A walk that says its unit (footfall generate --unit) in the scene's; one that does not is
    # keyed as it is, one walk unit to one scene unit.
    walk = ffc.character.walk_in_unit(walk, _scene_linear_unit())
    # (Tracks without keys made their locators, or cut the rig's keys from frame 0 on.)
    if not any(t.get("keys") for t in walk["tracks"]):
        raise ValueError("%s has no keys" % path)
    crowd = sorted({t.get("character", "") for t in walk["tracks"]})
    if rig:
        if len(crowd) > 1:
            raise ValueError("a crowd walk (%d characters) goes onto new locators: import it "
                             "without a rig" % len(crowd))
        _, feet, body = _rig_targets(rig)
        # Only what the walk keys is cut and keyed; another character's walk is refused.
        keyed, keys_body = ffc.character.rig_tracks(walk, feet, bool(body), path)
        feet = {n: feet[n] for n in keyed}
        body = body if keys_body else None
        sets = [(walk, feet, body)]
        previously_turned = _turned_feet(rig)
    mc.undoInfo(openChunk=True, chunkName="footfall import walk")
    try:
        if rig:
            # The rig's walk now ends at the walk's last frame: a later Generate Walk replaces
            # it.
            _set_walk_end(rig, max(k["frame"] for t in walk["tracks"]
                                   for k in t.get("keys", [])))
        else:
            sets = []
            for who in crowd:
                part = {"tracks": [t for t in walk["tracks"] if t.get("character", "") == who]}
                prefix = who + "_" if who else ""
                feet = {t["name"]: mc.spaceLocator(name=prefix + t["name"])[0]
                        for t in part["tracks"] if t.get("kind") == "foot"}
                body = mc.spaceLocator(name=prefix + "body")[0]
                sets.append((part, feet, body))
        count = 0
        for part, feet, body in sets:
            first = min((k["frame"] for t in part["tracks"] for k in t.get("keys", [])),
                        default=0)
            nodes = [n for n in list(feet.values()) + [body] if n]
            # Handles the walk turns (generated with foot rotations), and on a rig those its
            # last walk turned, lose their rotate keys too.
            turning = {feet[t["name"]] for t in part["tracks"]
                       if t.get("kind", "foot") == "foot" and t.get("name") in feet and
                       t.get("keys") and all("rotation" in k for k in t["keys"])}
            previous = set(feet.values()) if rig and previously_turned else set()
            _cut(nodes, first, 1e9, {body} | turning | previous)
            if rig:
                _set_turned_feet(rig, bool(turning))
            count += key_walk(part, feet, body)
    finally:
        mc.undoInfo(closeChunk=True)
    return count


# -- The window -----------------------------------------------------------------------------------

# The file dialogs' filters (Maya's fileDialog2 form).
TERRAIN_FILTER = ("Terrains (*.pts *.xyz *.txt *.obj *.ply *.off *.stl *.asc *.pgm);;"
                  "All files (*.*)")
CHARACTER_FILTER = "Characters (*.json);;All files (*.*)"
# The Character file unit menu's choices, the first the default (Maya's short names).
CHARACTER_UNITS = ffc.character.UNIT_MENU


def _browse_button(field, caption, file_filter):
    """Makes the "..." button of the textFieldButtonGrp `field` pick a file into it."""
    def browse(*_):
        chosen = mc.fileDialog2(fileMode=1, caption=caption, fileFilter=file_filter)
        if chosen:
            mc.textFieldButtonGrp(field, e=True, text=chosen[0])
    mc.textFieldButtonGrp(field, e=True, buttonCommand=browse)


def show():
    """Opens the footfall window: Server, Terrain Setup, Character Setup, Generate Walk."""
    if mc.window(WINDOW, exists=True):
        mc.deleteUI(WINDOW)
    mc.window(WINDOW, title="footfall")
    mc.columnLayout(adjustableColumn=True)
    mc.frameLayout(label="Server", collapsable=True)
    host = mc.textFieldGrp(label="Host", text=_settings["host"])
    port = mc.intFieldGrp(label="Port", value1=_settings["port"])
    local = mc.checkBoxGrp(label="Start local footfalld", value1=_settings["start_local"])

    def apply_server(*_):
        _settings["host"] = mc.textFieldGrp(host, q=True, text=True)
        _settings["port"] = mc.intFieldGrp(port, q=True, value1=True)
        _settings["start_local"] = mc.checkBoxGrp(local, q=True, value1=True)
    mc.button(label="Apply", command=apply_server)
    mc.setParent("..")

    mc.frameLayout(label="Terrain Setup", collapsable=True)
    sep = mc.floatFieldGrp(label="Point separation", value1=0.25)
    pfile = mc.textFieldButtonGrp(label="Point file", buttonLabel="...")
    _browse_button(pfile, "footfall terrain file", TERRAIN_FILTER)
    count = mc.text(label="Samples: -")

    def send(*_):
        apply_server()
        n = terrain_setup(mc.floatFieldGrp(sep, q=True, value1=True),
                          mc.textFieldButtonGrp(pfile, q=True, text=True) or None)
        if n is not None:
            mc.text(count, e=True, label="Samples: %d" % n)
    mc.button(label="Send Terrain", command=send)
    mc.setParent("..")

    mc.frameLayout(label="Character Setup", collapsable=True)
    cfile = mc.textFieldButtonGrp(label="Character file", buttonLabel="...")
    _browse_button(cfile, "footfall character file", CHARACTER_FILTER)
    # The unit the character file's lengths are in: metres for the shipped ones.
    cunit = mc.optionMenuGrp(label="Character file unit")
    for unit in CHARACTER_UNITS:
        mc.menuItem(label=unit)

    @_guard
    def setup(*_):
        sel = mc.ls(selection=True) or []
        data = character.load(mc.textFieldButtonGrp(cfile, q=True, text=True))
        names = [f for f, _ in character.feet(data)]
        handles = {f: s for f in names for s in sel if s == f or s.endswith("_" + f)}
        # The body: the first selected that is no foot's handle (the first handle selected
        # alone became the body and foot both; a body selected alone was ignored).
        bodies = [s for s in sel if s not in handles.values()]
        character_setup(mc.textFieldButtonGrp(cfile, q=True, text=True),
                        ik_handles=handles or None, body=bodies[0] if bodies else None,
                        character_unit=mc.optionMenuGrp(cunit, q=True, value=True))
    mc.button(label="Set Up (select body and/or IK handles, or nothing)", command=setup)
    mc.setParent("..")

    mc.frameLayout(label="Generate Walk", collapsable=True)
    steps = mc.intFieldGrp(label="Steps", value1=8)
    start = mc.intFieldGrp(label="Start frame", value1=1)
    fps = mc.intFieldGrp(label="Frames per step (0: file)", value1=0)
    length = mc.floatFieldGrp(label="Step length (0: file)", value1=0)
    height = mc.floatFieldGrp(label="Step height (0: file)", value1=0)
    foot = mc.floatFieldGrp(label="Foot length (0: file)", value1=0)
    turned = mc.checkBoxGrp(label="Foot rotations", value1=False)
    curve = mc.textFieldGrp(label="Path curve")

    @_guard  # (attributeQuery raises on a selected component)
    def generate(*_):
        sel = [n for n in (mc.ls(selection=True) or []) if mc.attributeQuery(RIG_ATTR, node=n,
                                                                               exists=True)]
        if not sel:
            _error("select a footfall rig group")
            return
        generate_walk(sel[0], mc.intFieldGrp(steps, q=True, value1=True),
                      mc.intFieldGrp(start, q=True, value1=True),
                      mc.intFieldGrp(fps, q=True, value1=True),
                      mc.floatFieldGrp(length, q=True, value1=True),
                      mc.floatFieldGrp(height, q=True, value1=True),
                      mc.textFieldGrp(curve, q=True, text=True) or None,
                      foot_length=mc.floatFieldGrp(foot, q=True, value1=True),
                      foot_rotations=bool(mc.checkBoxGrp(turned, q=True, value1=True)))
    mc.button(label="Generate Walk", command=generate)
    mc.setParent("..")
    mc.showWindow(WINDOW)
