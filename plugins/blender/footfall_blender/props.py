"""Add-on preferences (server), scene settings (terrain, walk) and the rig data on objects."""

import bpy
from bpy.props import (BoolProperty, CollectionProperty, EnumProperty, FloatProperty,
                       IntProperty, PointerProperty, StringProperty)

try:  # inside the add-on zip
    from . import footfall_client as ffc
except ImportError:  # the source tree: plugins/python on sys.path
    import footfall_client as ffc

ADDON = __package__


class FootfallPreferences(bpy.types.AddonPreferences):
    bl_idname = ADDON

    host: StringProperty(name="Host", default="127.0.0.1",
                         description="footfalld host to connect to")
    port: IntProperty(name="Port", default=7407, min=1, max=65535,
                      description="footfalld port (7407 by default)")
    start_local: BoolProperty(name="Start a local footfalld", default=True,
                              description="When no server answers at host:port, start footfalld "
                                          "on this machine on a free port")
    footfalld: StringProperty(name="footfalld", subtype="FILE_PATH", default="",
                              description="footfalld to start (empty: the bundled one, "
                                          "$FOOTFALLD or PATH)")
    timeout: FloatProperty(name="Timeout (s)", default=10.0, min=0.5, max=600.0,
                           description="Seconds per server call, and the longest wait for "
                                       "a local footfalld to start listening")

    def draw(self, context):
        col = self.layout.column()
        row = col.row()
        row.prop(self, "host")
        row.prop(self, "port")
        col.prop(self, "start_local")
        col.prop(self, "footfalld")
        col.prop(self, "timeout")


def preferences(context):
    addon = context.preferences.addons.get(ADDON)
    return addon.preferences if addon else None


class FootfallFoot(bpy.types.PropertyGroup):
    # name: the foot's name in the character file (PropertyGroup.name)
    target: PointerProperty(type=bpy.types.Object, name="IK target",
                            description="Object keyed as this foot's IK target")


class FootfallRig(bpy.types.PropertyGroup):
    """On the rig's root empty: which character, which body and which foot targets."""
    is_rig: BoolProperty(default=False)
    # On the central and target locators Character Setup makes under the root: the rig's own,
    # removed with it when Character Setup is run again on its body or IK targets.
    is_locator: BoolProperty(default=False)
    character_path: StringProperty(name="Character file", subtype="FILE_PATH")
    character_json: StringProperty(name="Character", description="The character file's JSON")
    body: PointerProperty(type=bpy.types.Object, name="Body")
    feet: CollectionProperty(type=FootfallFoot)
    # The last frame Generate Walk may have keyed on this rig, when known (rigs set up by this
    # version): a new walk replaces keys only up to the later of its end and this; keys the
    # user set after both are kept.
    walk_end_known: BoolProperty(default=False)
    walk_end: FloatProperty(default=0.0)
    # Its last walk keyed the IK targets' rotations (Foot rotations): a walk again replaces
    # them, with or without.
    walk_turned_feet: BoolProperty(default=False)


class FootfallScene(bpy.types.PropertyGroup):
    # Terrain Setup
    terrain_source: EnumProperty(name="Source", items=[
        ("MESH", "Selected mesh", "Resample the active object's faces at the point separation "
                                  "(a mesh, or a curve, text or collection instance)"),
        ("FILE", "Point file", "Load a terrain file (.pts)")], default="MESH")
    # In scene units (shown in the scene's): down to a micrometre in a scene of 1 unit = 1 m,
    # 0.1 mm at 100 m a unit (a minimum of 0.001 held it at 10 cm there).
    separation: FloatProperty(name="Point separation", default=0.25, min=1e-6, soft_max=5.0,
                              unit="LENGTH", description="Distance between terrain samples")
    terrain_file: StringProperty(name="Terrain file", subtype="FILE_PATH")
    terrain_name: StringProperty(name="Terrain", default="")
    # The scene's terrain in the add-on's connection (a new key at each Terrain Setup); empty:
    # none yet. Another scene, or another file, has its own.
    terrain_key: StringProperty(name="Terrain key", default="", options={"HIDDEN"})
    sample_count: IntProperty(name="Samples", default=0)
    # Character Setup / Generate Walk
    character_file: StringProperty(name="Character file", subtype="FILE_PATH",
                                   description="The character file (JSON) Character Setup "
                                               "reads")
    # The unit the character file's lengths are in (footfall_client.character.UNIT_MENU):
    # Character Setup keeps the character in metres on the rig.
    character_unit: EnumProperty(
        name="Character file unit", default="m",
        items=[(u, u, "The character file's lengths are in %s" % u)
               for u in ffc.character.UNIT_MENU],
        description="The unit the character file's lengths are in (metres for the shipped "
                    "characters)")
    rig: PointerProperty(type=bpy.types.Object, name="Rig",
                         poll=lambda self, obj: obj.footfall_rig.is_rig)
    steps: IntProperty(name="Steps", default=8, min=1, max=100000)
    start_frame: IntProperty(name="Start frame", default=1, min=-1048574, max=1048574)
    frames_per_step: IntProperty(name="Frames per step", default=0, min=0,
                                 description="0: the character file's value")
    step_length: FloatProperty(name="Step length", default=0.0, min=0.0, unit="LENGTH",
                               description="0: the character file's value")
    step_height: FloatProperty(name="Step height", default=0.0, min=0.0, unit="LENGTH",
                               description="0: the character file's value")
    foot_length: FloatProperty(name="Foot length", default=0.0, min=0.0, unit="LENGTH",
                               description="The sole's length along the heading, fitted onto "
                                           "stair treads; 0: the character file's value")
    foot_rotations: BoolProperty(name="Foot rotations", default=False,
                                 description="Key each IK target's rotation too: on its ground, "
                                             "facing the body's heading (off: locations only, "
                                             "and their own rotations are left alone)")
    path: PointerProperty(type=bpy.types.Object, name="Path",
                          poll=lambda self, obj: obj.type == "CURVE",
                          description="Optional curve the walk follows")


classes = [FootfallPreferences, FootfallFoot, FootfallRig, FootfallScene]


def attach():
    bpy.types.Scene.footfall = PointerProperty(type=FootfallScene)
    bpy.types.Object.footfall_rig = PointerProperty(type=FootfallRig)


def detach():
    del bpy.types.Object.footfall_rig
    del bpy.types.Scene.footfall
