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


def _draw_grown_model(layout, s, model, prefix):
    """The panel of a model grown in stages: its preset and stage (the scene's PREFIX_preset
    and PREFIX_stage), the seed, the geometry and the button that adds the feather."""
    col = layout.column()
    col.prop(s, prefix + "_preset")
    col.prop(s, prefix + "_stage")
    col.prop(s, "seed")
    col.prop(s, "geometry")
    op = col.operator("plume.add_feather", text="Add feather")
    op.model, op.preset, op.seed = model, getattr(s, prefix + "_preset"), s.seed
    op.stage, op.geometry = getattr(s, prefix + "_stage"), s.geometry


class PLUME_PT_streit_heidrich(_Panel, bpy.types.Panel):
    bl_label = "Streit & Heidrich"

    def draw(self, context):
        _draw_grown_model(self.layout, context.scene.plume, "streit-heidrich", "sh")


class PLUME_PT_zhang_kanai(_Panel, bpy.types.Panel):
    bl_label = "Zhang & Kanai"

    def draw(self, context):
        _draw_grown_model(self.layout, context.scene.plume, "zhang-kanai", "zk")


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
