"""footfall for Maya (maya.cmds): Terrain Setup, Character Setup and Generate Walk over footfalld,
thin over the shared package footfall_client. Maya is Y up and characters face +Z, as footfall,
so no axis conversion happens here. NOT RUN HERE: no Maya on the build machines (see
plugins/README.md); the logic it shares with Blender is tested through footfall_client.

    import footfall_maya; footfall_maya.show()
"""

import json
import math

import maya.cmds as mc

try:
    from . import footfall_client as ffc  # packed next to this package
except ImportError:
    import footfall_client as ffc

character = ffc.character

_connection = ffc.Connection()
_settings = {"host": "127.0.0.1", "port": 7407, "start_local": True, "footfalld": "",
             "timeout": 10.0}
TERRAIN = "scene"
RIG_ATTR = "footfallCharacter"   # string attribute on the rig group: the character JSON
WINDOW = "footfallWindow"


def _error(message):
    """Every failure ends here: a warning in the script line and a dialog, never an exception
    into Maya."""
    mc.warning("footfall: " + message)
    try:
        mc.confirmDialog(title="footfall", message=message, button=["OK"])
    except RuntimeError:  # batch mode
        pass


def _session():
    return _connection.get(_settings["host"], _settings["port"], _settings["start_local"],
                           _settings["footfalld"] or None, _settings["timeout"])


def _guard(fn):
    def run(*args, **kwargs):
        try:
            return fn(*args, **kwargs)
        except ffc.FootfallError as e:
            _error("%s (%s)" % (e.message, e.status_name))
        except (ValueError, OSError, RuntimeError) as e:
            _error(str(e))
        return None
    run.__name__ = fn.__name__
    return run


# -- Terrain Setup --------------------------------------------------------------------------------

def _mesh_samples(mesh, separation):
    from maya.api import OpenMaya as om  # noqa: N813 (only here: the API 2.0 mesh reader)
    sel = om.MSelectionList()
    sel.add(mesh)
    fn = om.MFnMesh(sel.getDagPath(0))
    points = [(p.x, p.y, p.z) for p in fn.getPoints(om.MSpace.kWorld)]
    counts, verts = fn.getTriangles()
    tris = [tuple(verts[i:i + 3]) for i in range(0, len(verts), 3)]
    # Normals from the geometry, as `footfall generate` samples a mesh file.
    normals = ffc.sampling.corner_normals(points, tris)
    return ffc.sampling.sample_triangles(points, tris, separation, corner_normals=normals)


@_guard
def terrain_setup(separation=0.25, point_file=None):
    """Sends the selected mesh resampled at `separation` [scene units], or loads `point_file`.
    Returns the sample count."""
    s = _session()
    if point_file:
        terrain = _connection.load_file(TERRAIN, point_file, separation)
    else:
        sel = mc.ls(selection=True, dag=True, type="mesh", noIntermediate=True)
        if not sel:
            raise ValueError("select a mesh for the terrain")
        terrain = _connection.load_samples(TERRAIN, _mesh_samples(sel[0], separation))
    count, _ = s.info(terrain)
    mc.inViewMessage(amg="footfall: %d terrain samples" % count, pos="topCenter", fade=True)
    return count


# -- Character Setup ------------------------------------------------------------------------------

def _snap(s, terrain, point):
    hold = s.snap(terrain, [point])[0]
    if not hold.ok:
        raise ValueError("no terrain near %s" % (point,))
    return hold.point, hold.normal


@_guard
def character_setup(character_file, name=None, ik_handles=None, body=None):
    """Sets up a character at the origin-facing +Z (or at `body`): foot IK handles given as
    {foot name: handle} (created as locators when None), target locators half a step ahead of
    each foot under a central locator per foot pair, aligned to the terrain normal."""
    data = character.load(character_file)
    feet = character.feet(data, character_file)
    s = _session()
    terrain = _connection.terrain(TERRAIN)
    name = name or data.get("name") or "character"
    origin = mc.xform(body, q=True, ws=True, t=True) if body else [0.0, 0.0, 0.0]
    ground, normal = _snap(s, terrain, origin)
    rig = mc.group(empty=True, name=name + "_rig")
    mc.addAttr(rig, longName=RIG_ATTR, dataType="string")
    mc.setAttr(rig + "." + RIG_ATTR, json.dumps(data), type="string")
    mc.xform(rig, ws=True, t=ground)
    if not body:
        body = mc.spaceLocator(name=name + "_body")[0]
    height = character.body_height(data)
    mc.xform(body, ws=True, t=(ground[0], ground[1] + height, ground[2]))
    mc.addAttr(rig, longName="footfallBody", attributeType="message")
    mc.connectAttr(body + ".message", rig + ".footfallBody")
    placed = {}
    for index, (foot, rest) in enumerate(feet):
        point, _ = _snap(s, terrain, (ground[0] + rest[0], ground[1], ground[2] + rest[2]))
        handle = (ik_handles or {}).get(foot) or mc.spaceLocator(name="%s_%s" % (name, foot))[0]
        mc.xform(handle, ws=True, t=point)
        # By the foot's index: a foot name need not be a valid Maya attribute name.
        attr = _foot_attr(index)
        mc.addAttr(rig, longName=attr, attributeType="message")
        mc.connectAttr(handle + ".message", rig + "." + attr)
        placed[foot] = point
    step = character.number(data, "step_length", 0.6)
    for pair, members in character.pairs(data):
        centre = [sum(placed[m][i] for m in members) / len(members) for i in range(3)]
        point, normal = _snap(s, terrain, centre)
        central = mc.spaceLocator(name="%s_%s_center" % (name, pair))[0]
        mc.parent(central, rig)
        mc.xform(central, ws=True, t=point)
        # Align the locator's Y to the normal (rotation about the axis normal x Y).
        axis = (normal[2], 0.0, -normal[0])
        angle = math.degrees(math.acos(max(-1.0, min(1.0, normal[1]))))
        if angle > 1e-6:
            mc.rotate(axis[0] * angle, 0, axis[2] * angle, central, ws=True, r=True)
        for m in members:
            target = mc.spaceLocator(name="%s_%s_target" % (name, m))[0]
            mc.parent(target, central)
            mc.xform(target, ws=True, t=(placed[m][0], placed[m][1], placed[m][2] + step / 2))
    return rig


# -- Generate Walk --------------------------------------------------------------------------------

def _foot_attr(index):
    """The rig's message attribute linking foot `index` (file order) to its IK handle."""
    return "footfallFoot%d" % index


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


def key_walk(walk, feet, body):
    """Keys the walk (footfall JSON dict) on the IK handles and body, as the seed's tool did."""
    count = 0
    for track in walk.get("tracks", []):
        is_body = track.get("kind") == "body"
        node = body if is_body else feet.get(track.get("name"))
        if not node:
            continue
        previous = None
        for key in track.get("keys", []):
            frame = key["frame"]
            mc.xform(node, ws=True, t=key["position"])
            mc.setKeyframe(node, attribute="translate", time=frame)
            if is_body and "rotation" in key:
                # XYZ Euler degrees as Maya's default rotate order composes them, unwrapped from
                # the previous key (as the MEL export keys them).
                euler = ffc.rotation.quat_to_euler_xyz(key["rotation"])
                if previous is not None:
                    euler = ffc.rotation.closest_euler(euler, previous)
                previous = euler
                mc.xform(node, ws=True, ro=euler)
                mc.setKeyframe(node, attribute="rotate", time=frame)
            count += 1
    return count


@_guard
def generate_walk(rig, steps=8, start_frame=1, frames_per_step=0, step_length=0.0,
                  step_height=0.0, path=None, chunk_steps=0):
    """Generates `steps` steps for `rig` and keys them; keys made before a failure stay. One
    undo chunk; progress in the main progress bar."""
    data, feet, body = _rig_targets(rig)
    data = character.with_overrides(data, step_length=step_length, step_height=step_height,
                                    frames_per_step=frames_per_step)
    start = mc.xform(rig, q=True, ws=True, t=True)
    m = mc.xform(rig, q=True, ws=True, m=True)
    request = {"character": data, "start": start, "heading": [m[8], m[9], m[10]],
               "start_frame": start_frame}
    if path:
        cvs = mc.ls(path + ".cv[*]", flatten=True)
        request["path"] = [mc.pointPosition(cv, world=True) for cv in cvs]
    chunk = chunk_steps or max(1, int(math.ceil(steps / 10.0)))
    s = _session()
    terrain = _connection.terrain(TERRAIN)
    bar = "MayaWindow|mainProgressBar" if mc.control("MayaWindow|mainProgressBar", exists=True) \
        else None
    if bar:
        mc.progressBar(bar, e=True, beginProgress=True, maxValue=steps,
                       status="footfall: generating")
    mc.undoInfo(openChunk=True, chunkName="footfall generate walk")
    try:
        done = 0
        while done < steps:
            done = min(steps, done + chunk)
            request["steps"] = done
            status, text, message = s.generate_json(terrain, request)
            if text is not None:
                walk = json.loads(text)
                key_walk(walk, feet, body)
            if status != 0 or (text is not None and walk.get("stopped")):
                raise ffc.FootfallError(status or 1, message or walk.get("stopped"), "generate")
            if bar:
                mc.progressBar(bar, e=True, progress=done)
    finally:
        mc.undoInfo(closeChunk=True)
        if bar:
            mc.progressBar(bar, e=True, endProgress=True)
    return done


@_guard
def import_walk(path, rig=None):
    """Keys a footfall walk JSON file onto `rig` (or new locators)."""
    with open(path) as f:
        walk = json.load(f)
    ffc.character.check_walk(walk, path)  # before any locator is made
    if rig:
        _, feet, body = _rig_targets(rig)
    else:
        feet = {t["name"]: mc.spaceLocator(name=t["name"])[0]
                for t in walk["tracks"] if t.get("kind") == "foot"}
        body = mc.spaceLocator(name="body")[0]
    return key_walk(walk, feet, body)


# -- The window -----------------------------------------------------------------------------------

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

    def setup(*_):
        sel = mc.ls(selection=True) or []
        data = character.load(mc.textFieldButtonGrp(cfile, q=True, text=True))
        names = [f for f, _ in character.feet(data)]
        handles = {f: s for f in names for s in sel if s == f or s.endswith("_" + f)}
        character_setup(mc.textFieldButtonGrp(cfile, q=True, text=True),
                        ik_handles=handles or None, body=sel[0] if handles else None)
    mc.button(label="Set Up (select body then IK handles, or nothing)", command=setup)
    mc.setParent("..")

    mc.frameLayout(label="Generate Walk", collapsable=True)
    steps = mc.intFieldGrp(label="Steps", value1=8)
    start = mc.intFieldGrp(label="Start frame", value1=1)
    fps = mc.intFieldGrp(label="Frames per step (0: file)", value1=0)
    length = mc.floatFieldGrp(label="Step length (0: file)", value1=0)
    height = mc.floatFieldGrp(label="Step height (0: file)", value1=0)
    curve = mc.textFieldGrp(label="Path curve")

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
                      mc.textFieldGrp(curve, q=True, text=True) or None)
    mc.button(label="Generate Walk", command=generate)
    mc.setParent("..")
    mc.showWindow(WINDOW)
