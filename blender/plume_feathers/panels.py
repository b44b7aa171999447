"""Sidebar panels (View3D > Sidebar > plume): one per model, the coat and the simulation."""

import bpy


class _Panel:
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "plume"


class PLUME_PT_franco_walter(_Panel, bpy.types.Panel):
    bl_label = "Franco & Walter"

    def draw(self, context):
        s = context.scene.plume
        col = self.layout.column()
        col.prop(s, "fw_preset")
        col.prop(s, "fw_barbs_lower")
        col.prop(s, "fw_barbs_upper")
        col.prop(s, "seed")
        col.prop(s, "geometry")
        op = col.operator("plume.add_feather", text="Add feather")
        op.model, op.preset, op.seed, op.geometry = "franco-walter", s.fw_preset, s.seed, s.geometry
        op.barbs_lower, op.barbs_upper = s.fw_barbs_lower, s.fw_barbs_upper


class PLUME_PT_streit_heidrich(_Panel, bpy.types.Panel):
    bl_label = "Streit & Heidrich"

    def draw(self, context):
        s = context.scene.plume
        col = self.layout.column()
        col.prop(s, "sh_preset")
        col.prop(s, "sh_stage")
        col.prop(s, "seed")
        col.prop(s, "geometry")
        op = col.operator("plume.add_feather", text="Add feather")
        op.model, op.preset, op.seed, op.stage = "streit-heidrich", s.sh_preset, s.seed, s.sh_stage
        op.geometry = s.geometry


class PLUME_PT_zhang_kanai(_Panel, bpy.types.Panel):
    bl_label = "Zhang & Kanai"

    def draw(self, context):
        s = context.scene.plume
        col = self.layout.column()
        col.prop(s, "zk_preset")
        col.prop(s, "zk_stage")
        col.prop(s, "seed")
        col.prop(s, "geometry")
        op = col.operator("plume.add_feather", text="Add feather")
        op.model, op.preset, op.seed, op.stage = "zhang-kanai", s.zk_preset, s.seed, s.zk_stage
        op.geometry = s.geometry


class PLUME_PT_coat(_Panel, bpy.types.Panel):
    bl_label = "Coat"

    def draw(self, context):
        s = context.scene.plume
        col = self.layout.column()
        col.prop(s, "spacing")
        col.prop(s, "key_feathers")
        op = col.operator("plume.groom_coat")
        op.spacing, op.key_feathers = s.spacing, s.key_feathers


class PLUME_PT_simulation(_Panel, bpy.types.Panel):
    bl_label = "Simulation"

    def draw(self, context):
        s = context.scene.plume
        col = self.layout.column()
        col.prop(s, "frames")
        col.prop(s, "edge_length")
        op = col.operator("plume.simulate")
        op.frames, op.edge_length = s.frames, s.edge_length


_classes = (PLUME_PT_franco_walter, PLUME_PT_streit_heidrich, PLUME_PT_zhang_kanai, PLUME_PT_coat,
            PLUME_PT_simulation)


def register():
    for c in _classes:
        bpy.utils.register_class(c)


def unregister():
    for c in reversed(_classes):
        bpy.utils.unregister_class(c)
