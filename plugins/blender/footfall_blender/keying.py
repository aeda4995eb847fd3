"""Keys a footfall walk (the walk JSON as a dict) onto Blender objects, in world space."""

import bpy
from mathutils import Matrix, Quaternion, Vector

from .axes import from_ff, quat_from_ff


def _world_to_local(obj, world):
    """The matrix_basis that puts `obj` at world matrix `world` given its parent."""
    if obj.parent is None:
        return world
    return (obj.parent.matrix_world @ obj.matrix_parent_inverse).inverted() @ world


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


def key_walk(walk, feet, body):
    """Keys every track of `walk`: feet {foot name: object} get location keys, `body` gets
    location and quaternion keys (world orientation of the walk). Tracks without an object are
    skipped. Returns the number of keys set."""
    count = 0
    for track in walk.get("tracks", []):
        is_body = track.get("kind") == "body"
        obj = body if is_body else feet.get(track.get("name"))
        if obj is None:
            continue
        if is_body:
            obj.rotation_mode = "QUATERNION"
        for key in track.get("keys", []):
            frame = float(key["frame"])
            loc = Vector(from_ff(key["position"]))
            if is_body and "rotation" in key:
                rot = Quaternion(quat_from_ff(key["rotation"]))
                world = Matrix.Translation(loc) @ rot.to_matrix().to_4x4()
            else:
                world = obj.matrix_world.normalized().copy()
                world.translation = loc
            basis = _world_to_local(obj, world)
            l, r, _ = basis.decompose()
            obj.location = l
            obj.keyframe_insert("location", frame=frame, group=obj.name)
            if is_body:
                obj.rotation_quaternion = r
                obj.keyframe_insert("rotation_quaternion", frame=frame, group=obj.name)
            count += 1
    return count


def store_walk_text(name, text):
    """Keeps the walk JSON in a text block (for the animator and for exports)."""
    block = bpy.data.texts.get(name) or bpy.data.texts.new(name)
    block.clear()
    block.write(text)
    return block
