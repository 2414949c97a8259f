# Builds the glTF test room in Blender and exports it as .glb and .gltf (run through
# scripts/blender/make_gltf_assets.sh: `blender -b --factory-startup --python this.py -- OUT_DIR`).
#
# The room: a floor and a back wall, a glass of water (a glass cylinder, water inside), a metal
# sphere, an emissive panel, a spot light and a camera. Every value is written out below so the
# hand-written twin (tests/data/gltf/room_twin.ron) can be read off this file, not off the
# export: the test compares caustic's import of the export with that twin.
#
# Blender 3.4's exporter (default lighting mode "Standard"): a point or spot light of P watts
# is written as P / (4π) · 683 candela, which caustic reads back as P / (4π) W/sr (power P);
# Principled "Emission" colour × strength is written as emissiveFactor × emissiveStrength.

import math
import os
import sys

import bpy

out_dir = sys.argv[sys.argv.index("--") + 1] if "--" in sys.argv else "."
os.makedirs(out_dir, exist_ok=True)

# An empty scene.
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene


def principled(name, base=(0.8, 0.8, 0.8), metallic=0.0, roughness=0.5, transmission=0.0,
               ior=1.5, emission=None, strength=1.0):
    """A Principled BSDF material with the values the glTF exporter reads."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*base, 1.0)
    bsdf.inputs["Metallic"].default_value = metallic
    bsdf.inputs["Roughness"].default_value = roughness
    bsdf.inputs["Transmission"].default_value = transmission
    bsdf.inputs["IOR"].default_value = ior
    bsdf.inputs["Specular"].default_value = 0.5
    if emission is not None:
        bsdf.inputs["Emission"].default_value = (*emission, 1.0)
        bsdf.inputs["Emission Strength"].default_value = strength
    return mat


def place(obj, material, location=(0, 0, 0), rotation=(0, 0, 0), scale=(1, 1, 1), smooth=False):
    obj.location = location
    obj.rotation_euler = [math.radians(a) for a in rotation]
    obj.scale = scale
    obj.data.materials.append(material)
    if smooth:
        for p in obj.data.polygons:
            p.use_smooth = True
    return obj


floor_mat = principled("Floor", base=(0.6, 0.5, 0.4), roughness=1.0)
wall_mat = principled("Wall", base=(0.7, 0.7, 0.7), roughness=1.0)
glass_mat = principled("Glass", base=(1, 1, 1), roughness=0.0, transmission=1.0, ior=1.5)
water_mat = principled("Water", base=(1, 1, 1), roughness=0.0, transmission=1.0, ior=1.33)
metal_mat = principled("Metal", base=(0.9, 0.6, 0.4), metallic=1.0, roughness=0.25)
panel_mat = principled("Panel", base=(0, 0, 0), roughness=1.0, emission=(1.0, 0.9, 0.8),
                       strength=6.0)

# Blender is z-up; the exporter turns it into glTF's y-up (+Y up: x, z, -y).
bpy.ops.mesh.primitive_plane_add(size=4)
place(bpy.context.object, floor_mat).name = "Floor"
bpy.ops.mesh.primitive_plane_add(size=4)
place(bpy.context.object, wall_mat, location=(0, 1.5, 2), rotation=(90, 0, 0)).name = "Wall"
bpy.ops.mesh.primitive_cylinder_add(vertices=32, radius=0.3, depth=0.8)
place(bpy.context.object, glass_mat, location=(-0.6, -0.2, 0.4), smooth=False).name = "Glass"
bpy.ops.mesh.primitive_cylinder_add(vertices=32, radius=0.25, depth=0.6)
place(bpy.context.object, water_mat, location=(-0.6, -0.2, 0.35)).name = "Water"
bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24, radius=0.4)
place(bpy.context.object, metal_mat, location=(0.6, 0.2, 0.4), smooth=True).name = "Ball"
bpy.ops.mesh.primitive_plane_add(size=1)
place(bpy.context.object, panel_mat, location=(0, 0.5, 2.4), rotation=(180, 0, 0)).name = "Panel"

spot = bpy.data.lights.new("Spot", type="SPOT")
spot.energy = 300.0  # W
spot.color = (1.0, 1.0, 1.0)
spot.spot_size = math.radians(60)  # full angle: outer half-angle 30°
spot.spot_blend = 0.25  # inner half-angle 30° · (1 − 0.25) = 22.5°
spot_obj = bpy.data.objects.new("Spot", spot)
spot_obj.location = (1.2, -1.2, 2.6)
spot_obj.rotation_euler = [math.radians(a) for a in (35, 0, 45)]
scene.collection.objects.link(spot_obj)

cam = bpy.data.cameras.new("Camera")
cam.sensor_fit = "VERTICAL"
cam.angle_y = math.radians(45)
cam_obj = bpy.data.objects.new("Camera", cam)
cam_obj.location = (0, -4.0, 1.2)
cam_obj.rotation_euler = [math.radians(a) for a in (85, 0, 0)]
scene.collection.objects.link(cam_obj)
scene.camera = cam_obj

common = dict(export_cameras=True, export_lights=True, export_yup=True, export_apply=True,
              export_normals=True, export_texcoords=True, export_materials="EXPORT")
bpy.ops.export_scene.gltf(filepath=os.path.join(out_dir, "room.glb"), export_format="GLB",
                          **common)
bpy.ops.export_scene.gltf(filepath=os.path.join(out_dir, "room.gltf"),
                          export_format="GLTF_EMBEDDED", **common)
print("wrote", os.path.join(out_dir, "room.glb"), "and room.gltf")
