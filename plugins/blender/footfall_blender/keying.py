"""Keys a footfall walk (the walk JSON as a dict) onto Blender objects, in world space."""

import bisect
import math

import bpy
from mathutils import Euler, Matrix, Quaternion, Vector

from .axes import from_ff, quat_from_ff, unit_scale


def _path_curve(obj):
    """True when obj is a curve whose children follow its path (Path Animation on)."""
    return obj.type == "CURVE" and obj.data is not None and obj.data.use_path


def unsupported_parent(obj):
    """Why obj's parent relation cannot be keyed exactly (None when it can). Object, lattice
    and armature-deform parents give their children the parent's world matrix, bone parents
    their bone's; a vertex parent gives the vertices' (deformed) position, and a curve with Path
    Animation a point on its path, which the add-on cannot compute."""
    parent = obj.parent
    if parent is None:
        return None
    if obj.parent_type in ("VERTEX", "VERTEX_3"):
        return ("%s is parented to %s of %s, whose position footfall cannot compute: parent it "
                "to an object or a bone" % (obj.name, "a vertex" if obj.parent_type == "VERTEX"
                                            else "three vertices", parent.name))
    if obj.parent_type == "OBJECT" and _path_curve(parent):
        return ("%s is parented to curve %s, whose Path Animation moves its children along the "
                "path, which footfall cannot compute: parent it to an object or a bone (or turn "
                "the curve's Path Animation off and place it again)" % (obj.name, parent.name))
    return None


def own_constraint(obj):
    """Why obj's own constraints keep its keys from being world positions (None when it has
    none that act): a constraint moves the object after its keys (a Child Of or a Copy
    Location put its keys metres off the walk), which the add-on cannot undo."""
    for c in obj.constraints:
        if not c.mute and c.influence > 0:
            return ("%s has a %s constraint (%s), which moves it after its keys: the walk's world "
                    "positions cannot be keyed through it; mute or remove it, or parent the "
                    "object instead" % (obj.name, c.type.replace("_", " ").title(), c.name))
    return None


def linked(obj):
    """Why obj's keys would not be saved (None when they would): an object linked from another
    file, not overridden, takes keys in this session, which Blender does not save (a walk keyed
    onto linked feet was gone on reopening)."""
    if obj.library is None:
        return None
    return ("%s is linked from %s, whose objects Blender does not save keys on: make a library "
            "override of it first (Object > Library Override > Make)"
            % (obj.name, bpy.path.abspath(obj.library.filepath)))


def own_driver(obj):
    """Why a driver on obj's own location or rotation keeps the walk's keys from acting (None
    when none does): a driven channel ignores its keys (the body stood 0.5 m off its walk)."""
    ad = obj.animation_data
    if ad is None:
        return None
    paths = ("location", "rotation_euler", "rotation_quaternion", "rotation_axis_angle")
    for fc in ad.drivers:
        if fc.data_path in paths and not fc.mute:
            return ("%s has a driver on its %s[%d], which overrides the walk's keys there: remove "
                    "or mute the driver, or drive a parent of it instead"
                    % (obj.name, fc.data_path, fc.array_index))
    return None


def check_parents(objects):
    """Raises ValueError naming the first of `objects` (None ones skipped) whose keys would not
    be saved (linked), whose parent relation cannot be keyed exactly (see unsupported_parent),
    whose own constraints or drivers move it (own_constraint, own_driver), or two of them that
    share one action (Duplicate Linked, Alt+D, shares it: both would play every key of both,
    one mixed track)."""
    for obj in objects:
        why = ((linked(obj) or unsupported_parent(obj) or own_constraint(obj) or own_driver(obj))
               if obj is not None else None)
        if why:
            raise ValueError(why)
    owner = {}
    for obj in objects:
        action = obj.animation_data.action if obj is not None and obj.animation_data else None
        if action is None:
            continue
        if action in owner and owner[action] is not obj:
            raise ValueError("%s and %s share the action %s, so each would play the other's keys "
                             "too: give each its own (Object > Relations > Make Single User > "
                             "Object Animation)" % (owner[action].name, obj.name, action.name))
        owner[action] = obj


def _delta_rotation(obj):
    """obj's delta rotation as a quaternion, in its rotation mode (Blender applies it before
    the rotation: basis rotation = delta @ rotation). Axis-angle objects have none the Python
    API shows (Blender's is then the identity)."""
    if obj.rotation_mode == "QUATERNION":
        return obj.delta_rotation_quaternion.normalized()
    if obj.rotation_mode == "AXIS_ANGLE":
        return Quaternion()
    return Euler(obj.delta_rotation_euler, obj.rotation_mode).to_quaternion()


def _bone(obj):
    """The pose bone obj is parented to (parent type BONE on an armature), or None."""
    parent = obj.parent
    if obj.parent_type != "BONE" or parent is None or parent.type != "ARMATURE":
        return None
    return parent.pose.bones.get(obj.parent_bone)


def _parent_world(obj):
    """The world matrix obj's parent gives it (as Blender's BKE_object_get_parent_matrix), as
    evaluated now: the parent's world matrix, times for a bone parent the bone's pose matrix
    and the bone's length along its Y (children of a bone hang from its tail), or for a bone
    with relative parenting its channel matrix. (A bone that does not exist gives the
    armature's matrix, as in Blender.)"""
    parent = obj.parent
    bone = _bone(obj)
    if bone is None:
        return parent.matrix_world.copy()
    if bone.bone.use_relative_parent:
        return parent.matrix_world @ bone.matrix_channel
    return parent.matrix_world @ bone.matrix @ Matrix.Translation((0.0, bone.bone.length, 0.0))


def _parent_key(obj):
    """What obj's parent space depends on: its parent object and bone."""
    bone = _bone(obj)
    return (obj.parent.name, bone.name if bone is not None else "")


def _moves(obj):
    """True when obj's world matrix (or a bone's of it) may change from frame to frame: it or
    an object up its parent chain has animation data (an action, NLA tracks or drivers),
    constraints (on the object or, for an armature, on a bone), or hangs from vertices or a
    path (which any animation of the mesh or curve moves)."""
    while obj is not None:
        ad = obj.animation_data
        if ad is not None and (ad.action is not None or len(ad.nla_tracks) or len(ad.drivers)):
            return True
        if len(obj.constraints):
            return True
        if obj.type == "ARMATURE" and obj.pose is not None and \
                any(len(bone.constraints) for bone in obj.pose.bones):
            return True
        if obj.parent is not None and unsupported_parent(obj):
            return True
        obj = obj.parent
    return False


def _under(obj, ancestor):
    """True when `ancestor` is up obj's parent chain."""
    obj = obj.parent
    while obj is not None:
        if obj == ancestor:
            return True
        obj = obj.parent
    return False


class _ParentSpaces:
    """The matrix taking world space to an object's matrix_basis space (its parent's matrix,
    see _parent_world, and its parent inverse, inverted), at a key's frame. read() reads them
    for a group of objects: a static parent chain's once, an animated one's at each key's frame,
    the scene stepped once through the frames the group needs (set to each frame and subframe
    once, for all its objects); restore() goes back to the frame the scene was on."""

    def __init__(self, scene):
        self.scene = scene
        self.frame = (scene.frame_current, scene.frame_subframe)
        self.moved = False
        self._at = {}  # (frame, parent key) -> parent matrix then; (None, parent key): static

    def read(self, jobs):
        """Reads what inverse() needs for `jobs`, (object, frames) pairs. Raises ValueError for
        a parent relation unsupported_parent refuses."""
        wanted = {}  # frame -> {parent key: an object with that parent}
        for obj, frames in jobs:
            if obj.parent is None:
                continue
            why = unsupported_parent(obj)
            if why:
                raise ValueError(why)
            key = _parent_key(obj)
            if not _moves(obj.parent):
                if (None, key) not in self._at:
                    self._at[(None, key)] = _parent_world(obj)
                continue
            for frame in frames:
                if (frame, key) not in self._at:
                    wanted.setdefault(frame, {})[key] = obj
        for frame in sorted(wanted):
            whole = math.floor(frame)
            self.scene.frame_set(int(whole), subframe=frame - whole)
            self.moved = True
            for key, obj in wanted[frame].items():
                self._at[(frame, key)] = _parent_world(obj)

    def inverse(self, obj, frames):
        """One world-to-basis matrix per frame of `frames` for `obj` (read() first)."""
        if obj.parent is None:
            return [Matrix.Identity(4)] * len(frames)
        pinv = obj.matrix_parent_inverse
        key = _parent_key(obj)
        static = self._at.get((None, key))
        if static is not None:
            return [(static @ pinv).inverted()] * len(frames)
        return [(self._at[(frame, key)] @ pinv).inverted() for frame in frames]

    def forget(self, parent):
        """Drops what was read of `parent` (its keys have just changed) and has its action
        evaluated again (keys added through keyframe_points are not seen otherwise)."""
        if parent.animation_data is not None and parent.animation_data.action is not None:
            parent.animation_data.action.update_tag()
        self._at = {k: m for k, m in self._at.items() if k[1][0] != parent.name}

    def restore(self):
        if self.moved:
            self.scene.frame_set(self.frame[0], subframe=self.frame[1])
            self.moved = False


# What an F-curve's keys hold that its value between two keys depends on, and their widths.
_KEY_PROPS = (("co", 2), ("handle_left", 2), ("handle_right", 2), ("interpolation", 1),
              ("easing", 1))


def _curves(obj):
    """What obj's action evaluates to, key by key: {(data path, index): (linear extrapolation,
    flat lists of the keys' _KEY_PROPS)}, to find later where a change of its keys moved it.
    None when a change may move it anywhere in time: F-curve modifiers, NLA tracks (or tweak
    mode) or drivers."""
    ad = obj.animation_data
    if ad is None or ad.action is None:
        return {}
    if len(ad.nla_tracks) or ad.use_tweak_mode or len(ad.drivers):
        return None
    out = {}
    for fc in ad.action.fcurves:
        if len(fc.modifiers):
            return None
        points = fc.keyframe_points
        data = [fc.extrapolation == "LINEAR"]
        for prop, width in _KEY_PROPS:
            values = [0] * (width * len(points))
            points.foreach_get(prop, values)
            data.append(values)
        out[(fc.data_path, fc.array_index)] = tuple(data)
    return out


def _changed_from(before, after):
    """The first frame at which F-curves keyed as `after` may evaluate otherwise than keyed as
    `before` (snapshots of _curves), None when nowhere, -inf when anywhere. An F-curve between
    two keys depends on those two keys only (their frames, values, handles, interpolation):
    keys the same up to key i - 1 leave it the same up to key i - 1's frame. (Before the first
    key, extrapolated linearly, it depends on the first two.)"""
    if before is None or after is None:
        return -math.inf
    first = None
    for path in set(before) | set(after):
        old, new = before.get(path), after.get(path)
        if old is None or new is None or old[0] != new[0]:
            return -math.inf
        n = min(len(old[1]), len(new[1])) // 2

        def same(k):  # the first k keys are the same
            return all(o[:width * k] == w[:width * k]
                       for o, w, (_, width) in zip(old[1:], new[1:], _KEY_PROPS))
        if same(n):
            if len(old[1]) == len(new[1]):
                continue
            i = n
        else:  # the first key that differs, by halving (slices compare at C speed)
            i, bad = 0, n
            while bad - i > 1:
                mid = (i + bad) // 2
                if same(mid):
                    i = mid
                else:
                    bad = mid
        if i == 0 or (new[0] and i == 1):
            return -math.inf
        frame = new[1][2 * (i - 1)]
        first = frame if first is None else min(first, frame)
    return first


# Blender's frame range (MAXFRAME): keys beyond it land on the wrong frames, or on one.
MAX_FRAME = 1048574
# The largest value a key holds (a 32-bit float): beyond it a key is infinite or not a number.
MAX_KEY_VALUE = 3.4028234663852886e38


def check_frames(walk):
    """Raises ValueError when a key of `walk` lies beyond Blender's frame range, or has a
    coordinate beyond what a key can hold."""
    for track in walk.get("tracks", []):
        for key in track.get("keys", []):
            frame = float(key["frame"])
            if not -MAX_FRAME <= frame <= MAX_FRAME:
                raise ValueError("track '%s': frame %.15g is beyond Blender's frame range (-%d "
                                 "to %d); generate it with a start frame nearer 0"
                                 % (track.get("name"), frame, MAX_FRAME, MAX_FRAME))
            for value in key.get("position") or ():
                if not abs(float(value)) <= MAX_KEY_VALUE:
                    raise ValueError("track '%s': frame %.15g: coordinate %.15g is beyond what "
                                     "a Blender key holds (32-bit floats, up to %.8g)"
                                     % (track.get("name"), frame, float(value), MAX_KEY_VALUE))


# The property holding an object's rotation in each rotation mode (the Euler orders: the rest).
_ROTATION_PATHS = {"QUATERNION": "rotation_quaternion", "AXIS_ANGLE": "rotation_axis_angle"}


def rotation_path(obj):
    """The data path of obj's rotation in its rotation mode (the one Blender evaluates)."""
    return _ROTATION_PATHS.get(obj.rotation_mode, "rotation_euler")


def action_frame(obj, frame):
    """The frame of obj's action that plays at scene frame `frame`: in NLA tweak mode, the
    tweaked strip's own time (its start, scale and repeats), as keyframe_insert maps it; else
    `frame` itself. (Keys written straight into an action in tweak mode landed at the scene's
    frames in the strip's time: a strip starting at 101 played them 100 frames late.)"""
    ad = obj.animation_data
    if ad is not None and ad.use_tweak_mode and ad.action is not None:
        return ad.nla_tweak_strip_time_to_scene(frame, invert=True)
    return frame


def clear_keys(objects, from_frame, body=None, to_frame=None, turned=()):
    """Removes location keys at frames from from_frame to to_frame (None: on to the end) from
    `objects`, and the rotation keys of `body` (one of them) and of the objects in `turned`
    (feet whose rotations a walk keys) in the path of its rotation mode. A curve left without
    keys is removed, but for one with modifiers, kept for the keys to come."""
    for obj in objects:
        action = obj.animation_data.action if obj and obj.animation_data else None
        if action is None:
            continue
        rotated = obj == body or obj in turned
        paths = ("location", rotation_path(obj)) if rotated else ("location",)
        first = action_frame(obj, from_frame)
        last = None if to_frame is None else action_frame(obj, to_frame)
        for fc in list(action.fcurves):
            if fc.data_path not in paths:
                continue
            for i in reversed(range(len(fc.keyframe_points))):
                frame = fc.keyframe_points[i].co[0]
                if frame >= first - 1e-6 and (last is None or frame <= last + 1e-6):
                    fc.keyframe_points.remove(fc.keyframe_points[i], fast=True)
            fc.update()
            # An emptied curve goes, unless the user gave it modifiers (a Noise for a bob, a
            # Cycles): those went with it, and the walk keyed again made a bare curve.
            if not fc.keyframe_points and not fc.modifiers:
                action.fcurves.remove(fc)


def _rotation_values(obj, rotations, first_frame):
    """obj's rotation path and its values for the world-to-basis quaternions `rotations`, in
    obj's rotation mode: Euler angles each as near the one before as the angles allow (no
    turns of 360 degrees between keys), quaternions (and axis-angles) on the hemisphere of the
    one before. The first is near obj's curve at `first_frame` (or its current rotation)."""
    path = rotation_path(obj)
    width = 3 if path == "rotation_euler" else 4
    action = obj.animation_data.action if obj.animation_data else None
    curves = [action.fcurves.find(path, index=i) if action else None for i in range(width)]
    current = getattr(obj, path)
    at = action_frame(obj, first_frame)
    before = [fc.evaluate(at) if fc is not None and len(fc.keyframe_points) else v
              for fc, v in zip(curves, current)]
    values = []
    if path == "rotation_euler":
        previous = Euler(before, obj.rotation_mode)
        for r in rotations:
            previous = r.to_euler(obj.rotation_mode, previous)
            values.append(tuple(previous))
        return path, values
    if path == "rotation_quaternion":
        previous = Quaternion(before)
    else:
        previous = Quaternion(before[1:], before[0])
    for r in rotations:
        q = r.copy()
        if previous.dot(q) < 0:
            q.negate()
        previous = q
        if path == "rotation_quaternion":
            values.append(tuple(q))
        else:
            axis, angle = q.to_axis_angle()
            values.append((angle,) + tuple(axis))
    return path, values


def _fcurve(obj, path, index):
    """The F-curve of obj's `path`[index] in its action (made as keyframe_insert makes it)."""
    if obj.animation_data is None:
        obj.animation_data_create()
    action = obj.animation_data.action
    if action is None:
        action = bpy.data.actions.new(obj.name + "Action")
        obj.animation_data.action = action
    fc = action.fcurves.find(path, index=index)
    if fc is None:
        fc = action.fcurves.new(path, index=index, action_group=obj.name)
    return fc


def _key_channel(obj, path, values, frames):
    """Keys obj's `path` (one value tuple per frame, ascending frames). Keys after the
    F-curves' last one are appended in one go (keyframe_insert reallocates a curve's keys at
    every insert: a long walk took minutes); earlier frames go through keyframe_insert.
    `frames` are the scene's: appended keys go at the action's frames (action_frame)."""
    width = len(values[0]) if values else 0
    curves = [_fcurve(obj, path, i) for i in range(width)]
    last = max((fc.keyframe_points[-1].co[0] for fc in curves if len(fc.keyframe_points)),
               default=None)
    local = [action_frame(obj, f) for f in frames]
    tail = 0
    while tail < len(frames) and last is not None and local[tail] <= last:
        setattr(obj, path, values[tail])
        obj.keyframe_insert(path, frame=frames[tail], group=obj.name)
        tail += 1
    count = len(frames) - tail
    if count == 0:
        return
    for i, fc in enumerate(curves):
        points = fc.keyframe_points
        before = len(points)
        points.add(count)
        co = [0.0] * (2 * (before + count))
        points.foreach_get("co", co)
        for k in range(count):
            co[2 * (before + k)] = local[tail + k]
            co[2 * (before + k) + 1] = values[tail + k][i]
        points.foreach_set("co", co)
        for point in points[before:]:
            point.interpolation = "BEZIER"
            point.handle_left_type = point.handle_right_type = "AUTO_CLAMPED"
        fc.update()
    setattr(obj, path, values[-1])


def turns(is_body, keys):
    """True when a track's keys key its object's rotation: a body's, and a foot's whose every
    key has one (a walk generated with foot rotations)."""
    return is_body or (bool(keys) and all("rotation" in key for key in keys))


def _worlds(rotated, keys, orientation, scale):
    """The world matrices of a track's keys: positions and, for a track that turns its object
    (`rotated`), rotations, else positions in `orientation`; positions (metres) divided by
    `scale` (metres a unit)."""
    worlds = []
    for key in keys:
        loc = Vector(from_ff(key["position"], scale))
        if rotated and "rotation" in key:
            rot = Quaternion(quat_from_ff(key["rotation"]))
            world = Matrix.Translation(loc) @ rot.to_matrix().to_4x4()
        else:
            world = orientation.copy()
            world.translation = loc
        worlds.append(world)
    return worlds


def key_walk(walk, feet, body, from_frame=None):
    """Keys every track of `walk`: feet {foot name: object} get location keys (and rotation
    keys when each of their keys has a rotation: Foot rotations), `body` gets location and
    rotation keys (world orientation of the walk) in its rotation mode. Tracks
    without an object are skipped; with `from_frame`, so are keys before it (keyed already: a
    longer walk generated again keeps the keys of its first steps). Keys are world positions:
    an object under an animated parent is keyed in its parent's space at each key's frame (the
    scene's frame is the same afterwards), less its delta transform. Positions are metres,
    keyed in scene units (divided by the scene's Unit Scale). Returns the number of keys set."""
    tracks = []  # (object, is body, frames, keys, orientation) of the whole track, by frame
    for track in walk.get("tracks", []):
        is_body = track.get("kind") == "body"
        obj = body if is_body else feet.get(track.get("name"))
        if obj is None:
            continue
        frames, keys = [], []
        for key in sorted(track.get("keys", []), key=lambda k: float(k["frame"])):
            frame = float(key["frame"])
            if frames and frames[-1] == frame:  # the later key of a frame wins
                frames.pop(), keys.pop()
            frames.append(frame)
            keys.append(key)
        if frames:  # a foot keeps its orientation (read at this frame) unless keyed
            tracks.append((obj, turns(is_body, keys), frames, keys,
                           obj.matrix_world.normalized()))
    # An object under another keyed object (a foot under the body) is keyed in its space, so
    # after it, in groups by the number of keyed objects above (the scene stepped once through
    # each group's frames). The keys an object above sets from `from_frame` on bend its curve
    # before that frame too (from the key before the first that changed): the object under it
    # is keyed again from there (it was keyed again over the whole walk, at each chunk).
    objects = [t[0] for t in tracks]
    above = {obj: [a for a in objects if a is not obj and _under(obj, a)] for obj in objects}
    below = {a for obj in objects for a in above[obj]}
    groups = {}
    for track in tracks:
        groups.setdefault(len(above[track[0]]), []).append(track)
    spaces = _ParentSpaces(bpy.context.scene)
    scale = unit_scale(bpy.context.scene)  # the walk's metres in scene units
    changed = {}  # keyed object with keyed objects under it -> _changed_from of its keys
    count = 0
    try:
        for depth in sorted(groups):
            jobs = []
            for obj, rotated, frames, keys, orientation in groups[depth]:
                start = from_frame
                for a in above[obj]:
                    if changed.get(a) is not None and start is not None:
                        start = min(start, changed[a])
                first = 0 if start is None else bisect.bisect_left(frames, start)
                if first == len(frames):
                    continue
                jobs.append((obj, rotated, frames[first:], keys[first:], orientation,
                             start is not None and start < from_frame))
            spaces.read([(job[0], job[2]) for job in jobs])
            for obj, rotated, frames, keys, orientation, again in jobs:
                worlds = _worlds(rotated, keys, orientation, scale)
                before = _curves(obj) if obj in below else None
                if again:  # keys from where the objects above changed
                    clear_keys([obj], frames[0], obj if rotated else None, frames[-1])
                # Less its delta transform, which Blender adds to the keyed location and
                # turns the keyed rotation by (a 0.5 m Delta Location floated every foot key).
                delta_location = obj.delta_location.copy()
                undelta = _delta_rotation(obj).inverted()
                locations, rotations = [], []
                for inverse, world in zip(spaces.inverse(obj, frames), worlds):
                    l, r, _ = (inverse @ world).decompose()
                    locations.append(tuple(l - delta_location))
                    rotations.append(undelta @ r)
                if rotated:
                    path, values = _rotation_values(obj, rotations, frames[0])
                _key_channel(obj, "location", locations, frames)
                if rotated:
                    _key_channel(obj, path, values, frames)
                spaces.forget(obj)
                if obj in below:
                    changed[obj] = _changed_from(before, _curves(obj))
                count += len(frames)
    finally:
        spaces.restore()
    return count


def store_walk_text(name, text):
    """Keeps the walk JSON in a text block (for the animator and for exports)."""
    block = bpy.data.texts.get(name) or bpy.data.texts.new(name)
    block.clear()
    block.write(text)
    return block
