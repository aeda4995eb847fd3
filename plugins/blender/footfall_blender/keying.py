"""Keys a footfall walk (the walk JSON as a dict) onto Blender objects, in world space."""

import bpy
from mathutils import Matrix, Quaternion, Vector

from .axes import from_ff, quat_from_ff


def _world_to_local(obj, world):
    """The matrix_basis that puts `obj` at world matrix `world` given its parent."""
    if obj.parent is None:
        return world
    return (obj.parent.matrix_world @ obj.matrix_parent_inverse).inverted() @ world


# Blender's frame range (MAXFRAME): keys beyond it land on the wrong frames, or on one.
MAX_FRAME = 1048574


def check_frames(walk):
    """Raises ValueError when a key of `walk` lies beyond Blender's frame range."""
    for track in walk.get("tracks", []):
        for key in track.get("keys", []):
            frame = float(key["frame"])
            if not -MAX_FRAME <= frame <= MAX_FRAME:
                raise ValueError("track '%s': frame %.15g is beyond Blender's frame range (-%d "
                                 "to %d); generate it with a start frame nearer 0"
                                 % (track.get("name"), frame, MAX_FRAME, MAX_FRAME))


def clear_keys(objects, from_frame):
    """Removes location/rotation keys at frames >= from_frame from `objects`."""
    for obj in objects:
        action = obj.animation_data.action if obj and obj.animation_data else None
        if action is None:
            continue
        for fc in list(action.fcurves):
            if fc.data_path not in ("location", "rotation_quaternion"):
                continue
            for i in reversed(range(len(fc.keyframe_points))):
                if fc.keyframe_points[i].co[0] >= from_frame - 1e-6:
                    fc.keyframe_points.remove(fc.keyframe_points[i], fast=True)
            fc.update()
            if not fc.keyframe_points:
                action.fcurves.remove(fc)


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
    every insert: a long walk took minutes); earlier frames go through keyframe_insert."""
    width = len(values[0]) if values else 0
    curves = [_fcurve(obj, path, i) for i in range(width)]
    last = max((fc.keyframe_points[-1].co[0] for fc in curves if len(fc.keyframe_points)),
               default=None)
    tail = 0
    while tail < len(frames) and last is not None and frames[tail] <= last:
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
            co[2 * (before + k)] = frames[tail + k]
            co[2 * (before + k) + 1] = values[tail + k][i]
        points.foreach_set("co", co)
        for point in points[before:]:
            point.interpolation = "BEZIER"
            point.handle_left_type = point.handle_right_type = "AUTO_CLAMPED"
        fc.update()
    setattr(obj, path, values[-1])


def key_walk(walk, feet, body, from_frame=None):
    """Keys every track of `walk`: feet {foot name: object} get location keys, `body` gets
    location and quaternion keys (world orientation of the walk). Tracks without an object are
    skipped; with `from_frame`, so are keys before it (keyed already: a longer walk generated
    again keeps the keys of its first steps). Returns the number of keys set."""
    count = 0
    for track in walk.get("tracks", []):
        is_body = track.get("kind") == "body"
        obj = body if is_body else feet.get(track.get("name"))
        if obj is None:
            continue
        if is_body:
            obj.rotation_mode = "QUATERNION"
        frames, locations, rotations = [], [], []
        for key in sorted(track.get("keys", []), key=lambda k: float(k["frame"])):
            frame = float(key["frame"])
            if from_frame is not None and frame < from_frame:
                continue
            loc = Vector(from_ff(key["position"]))
            if is_body and "rotation" in key:
                rot = Quaternion(quat_from_ff(key["rotation"]))
                world = Matrix.Translation(loc) @ rot.to_matrix().to_4x4()
            else:
                world = obj.matrix_world.normalized().copy()
                world.translation = loc
            l, r, _ = _world_to_local(obj, world).decompose()
            if frames and frames[-1] == frame:  # the later key of a frame wins
                frames.pop(), locations.pop(), rotations.pop()
            frames.append(frame)
            locations.append(tuple(l))
            rotations.append(tuple(r))
        if not frames:
            continue
        _key_channel(obj, "location", locations, frames)
        if is_body:
            _key_channel(obj, "rotation_quaternion", rotations, frames)
        count += len(frames)
    return count


def store_walk_text(name, text):
    """Keeps the walk JSON in a text block (for the animator and for exports)."""
    block = bpy.data.texts.get(name) or bpy.data.texts.new(name)
    block.clear()
    block.write(text)
    return block
