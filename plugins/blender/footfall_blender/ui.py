"""The sidebar panels: Terrain Setup, Character Setup, Generate Walk (View3D > Sidebar > footfall)."""

import bpy

from . import operators


class _Panel:
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "footfall"


class FOOTFALL_PT_terrain(_Panel, bpy.types.Panel):
    bl_label = "Terrain Setup"

    def draw(self, context):
        s = context.scene.footfall
        col = self.layout.column()
        col.prop(s, "terrain_source", expand=True)
        if s.terrain_source == "FILE":
            col.prop(s, "terrain_file")
        col.prop(s, "separation")
        col.operator("footfall.terrain_setup")
        if s.terrain_name and operators.scene_terrain_loaded(context.scene):
            col.label(text="%s: %d samples" % (s.terrain_name, s.sample_count))
        elif s.terrain_name:
            col.label(text="%s: not loaded in this session" % s.terrain_name)
        else:
            col.label(text="No terrain in this scene")
        col.label(text="Server: " + operators.describe_connection())


class FOOTFALL_PT_character(_Panel, bpy.types.Panel):
    bl_label = "Character Setup"

    def draw(self, context):
        s = context.scene.footfall
        col = self.layout.column()
        col.prop(s, "character_file")
        col.prop(s, "character_unit")
        op = col.operator("footfall.character_setup", text="Create Empties at Cursor")
        op.mode = "CREATE"
        op = col.operator("footfall.character_setup", text="Use Selected (active = body)")
        op.mode = "PICK"
        col.prop(s, "rig")
        try:  # the rig Generate Walk keys: the active object's, else the field's
            rig = operators.walk_rig(context)
        except ValueError:
            rig = None
        if rig is not None:
            if rig != s.rig:
                col.label(text="Active rig: " + rig.name)
            col.prop(rig.footfall_rig, "body")
            for foot in rig.footfall_rig.feet:
                col.prop(foot, "target", text=foot.name)


class FOOTFALL_PT_walk(_Panel, bpy.types.Panel):
    bl_label = "Generate Walk"

    def draw(self, context):
        s = context.scene.footfall
        col = self.layout.column()
        for name in ("steps", "start_frame", "frames_per_step", "step_length", "step_height",
                     "foot_length", "foot_rotations", "path"):
            col.prop(s, name)
        col.operator("footfall.generate_walk")
        col.operator("footfall.import_walk")




classes = [FOOTFALL_PT_terrain, FOOTFALL_PT_character, FOOTFALL_PT_walk]
