"""Renders a Hairloom strand export as Blender imports it (default import settings), for the
README's side-by-side with Hairloom's own render: Cycles on the CPU, the hair coloured by
the file's per-point colour (USD displayColor), the head from the runtime bundle's body.

Usage: python tools/blender_render.py HAIR.usda BODY.glb OUT.png [SIZE]
(the Python of target/bpy-venv, which `make test` installs)."""
import math
import sys

import bpy
from mathutils import Vector

hair_path, body_path, out = sys.argv[1:4]
size = int(sys.argv[4]) if len(sys.argv) > 4 else 480

bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.wm.usd_import(filepath=hair_path)
bpy.ops.import_scene.gltf(filepath=body_path)
scene = bpy.context.scene
hair = next(o for o in bpy.data.objects if o.type == "CURVES")

material = bpy.data.materials.new("Hair")
material.use_nodes = True
nodes, links = material.node_tree.nodes, material.node_tree.links
nodes.clear()
bsdf = nodes.new("ShaderNodeBsdfHairPrincipled")
bsdf.parametrization = "COLOR"
color = nodes.new("ShaderNodeAttribute")
color.attribute_name = "displayColor"
output = nodes.new("ShaderNodeOutputMaterial")
links.new(color.outputs["Color"], bsdf.inputs["Color"])
links.new(bsdf.outputs[0], output.inputs["Surface"])
hair.data.materials.append(material)

# Frame the hair from the front (Blender's front view looks along +y).
corners = [hair.matrix_world @ Vector(c) for c in hair.bound_box]
lo = Vector([min(c[k] for c in corners) for k in range(3)])
hi = Vector([max(c[k] for c in corners) for k in range(3)])
centre, extent = (lo + hi) / 2, max(hi - lo)
camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
scene.collection.objects.link(camera)
camera.data.lens = 85
distance = 1.3 * extent / (2 * math.tan(camera.data.angle / 2))
camera.location = centre + Vector((0, -distance, 0))
camera.rotation_euler = (math.pi / 2, 0, 0)
scene.camera = camera
for name, energy, rotation in [("Key", 3.0, (0.9, 0.2, 0.6)), ("Fill", 1.0, (1.2, -0.3, -1.2))]:
    light = bpy.data.objects.new(name, bpy.data.lights.new(name, "SUN"))
    light.data.energy = energy
    light.rotation_euler = rotation
    scene.collection.objects.link(light)
world = bpy.data.worlds.new("World")
world.color = (0.05, 0.05, 0.06)
scene.world = world

scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = 16
scene.render.resolution_x = scene.render.resolution_y = size
scene.render.filepath = out
bpy.ops.render.render(write_still=True)
print(f"{out}: Blender {bpy.app.version_string}, {len(hair.data.curves)} curves")
