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


def register():
    for cls in _classes:
        bpy.utils.register_class(cls)
    props.attach()


def unregister():
    operators.shutdown()
    props.detach()
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
