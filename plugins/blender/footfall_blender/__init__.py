"""footfall for Blender: Terrain Setup, Character Setup and Generate Walk over footfalld (RPC),
through libfootfall's C ABI (the shared ctypes package footfall_client)."""

bl_info = {
    "name": "footfall",
    "author": "footfall",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "3D Viewport > Sidebar > footfall",
    "description": "Footstep placement on terrain: keys IK targets and the body of bipeds and "
                   "multipeds with the footfall step generator",
    "category": "Animation",
}

import bpy  # noqa: E402

from . import keying, operators, props, ui  # noqa: E402,F401

_classes = props.classes + operators.classes + ui.classes


@bpy.app.handlers.persistent
def _file_loaded(*_):
    """A file opened (or File > New): its scenes' terrains stay, the others are unloaded."""
    operators.file_loaded()


@bpy.app.handlers.persistent
def _depsgraph_updated(*_):
    """A scene deleted: its terrains are unloaded (soon after, in the background)."""
    operators.scenes_changed()


def register():
    for cls in _classes:
        bpy.utils.register_class(cls)
    props.attach()
    bpy.app.handlers.load_post.append(_file_loaded)
    bpy.app.handlers.depsgraph_update_post.append(_depsgraph_updated)


def unregister():
    if _file_loaded in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.remove(_file_loaded)
    if _depsgraph_updated in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.remove(_depsgraph_updated)
    operators.shutdown()
    props.detach()
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
