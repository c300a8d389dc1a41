"""Makes a hair groom with Blender's own procedural hair node assets on the bundled head
scan and exports it, so that `hairloom fit` can be measured on a groom nobody here made.

The groom is a shoulder-length, middle-parted, gently wavy bob: ~9,900 strands of 24
points, grown on a scalp cut from the head scan by the "Generate Hair Curves", "Displace
Hair Curves", "Shrinkwrap Hair Curves", "Smooth Hair Curves", "Create Guide Index Map",
"Clump Hair Curves", "Curl Hair Curves", "Frizz Hair Curves" and "Set Hair Curve Profile"
node groups that ship with Blender (datafiles/assets/nodes/procedural_hair_node_assets.blend),
as a modifier stack on a Curves object. The only input made here is the comb: a per-vertex
target on the scalp saying where each strand should end. Every seed is fixed, so each run
makes the same strands (the .abc differs only in its write date).

Usage: target/bpy-venv/bin/python tools/blender_groom.py --out DIR [--render]
(the Python of target/bpy-venv, which has PyPI `bpy` 5.3). Writes, in metres, +Y up
(the glTF frame, which Hairloom reads), with the head, scalp and groom under a parent
turned 10° about x and 25° about z and moved, so that each file carries a transform its
reader must apply (an Alembic Xform, USD xformOps, the glTF node):

    DIR/blender_groom.abc   the evaluated curves as Alembic ICurves (Blender's exporter)
    DIR/blender_groom.usda  the same curves as a USD BasisCurves prim (catmullRom, pinned)
    DIR/blender_scalp.glb   the scalp the curves grow on (glTF defaults)

The curves carry what Blender gives them: radius (as widths), surface_uv_coordinate,
surface_normal, guide_curve_index, and the scalp's attributes that "Generate Hair Curves"
copies onto them (UVMap, and this script's side and comb).

and with --render, DIR/blender_front.png, _side.png and _back.png (Workbench) to judge
the groom by.

Then e.g.: hairloom fit DIR/blender_groom.abc --scalp DIR/blender_scalp.glb --out FIT.hairloom

The head is "Infinite, 3D Head Scan" by Lee Perry-Smith, licensed under CC BY 3.0, based on
a work at www.triplegangers.com (assets/head/LICENSE.txt).
"""
import argparse
import math
import os
import sys
import time

import bpy  # first: it sets up bmesh and mathutils
import bmesh
import numpy as np
from mathutils import Matrix, Vector

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
HEAD_GLB = os.path.join(REPO, "assets", "head", "LeePerrySmith.glb")

# The scan is not in metres: it measures ~4.9 units from chin to crown, where a head is
# ~0.22 m. The same factor as Hairloom's samples (core/src/samples HEAD_SCALE), applied to
# the mesh in Blender so that every length below, the node assets' defaults and all three
# exported files are in metres.
HEAD_SCALE = 0.045

HAIR_LENGTH = 0.16  # m, as grown; combing and curl change it by a few cm
CONTROL_POINTS = 24
DENSITY = 220_000.0  # strands per m² of scalp: ~0.045 m² gives ~10,000 strands
STRAND_RADIUS = 0.00005  # m at the root (Set Hair Curve Profile tapers it to the tip)


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", required=True, help="folder for the exported files")
    parser.add_argument("--render", action="store_true",
                        help="also render front / side / back views (Workbench) into --out")
    return parser.parse_args(argv)


def import_head():
    """The head scan, scaled to metres, Blender's axes: +Z up, face towards -Y."""
    bpy.ops.import_scene.gltf(filepath=HEAD_GLB)
    head = next(o for o in bpy.context.scene.objects if o.type == "MESH")
    head.data.transform(Matrix.Scale(HEAD_SCALE, 4))
    head.data.update()
    corners = np.array([v.co[:] for v in head.data.vertices])
    lo, hi = corners.min(0), corners.max(0)
    print(f"head: {len(head.data.vertices)} vertices, file units × {HEAD_SCALE} → "
          f"{hi - lo} m (x, y, z); crown at z = {hi[2]:.3f} m")
    # The scan includes neck and shoulders: the head itself is the top ~0.22 m.
    assert 0.3 < hi[2] - lo[2] < 0.5 and 0.15 < hi[2] < 0.2, "unexpected head size"
    return head


def is_scalp(centre, normal):
    """Whether a face of the head (centre in file units, Blender axes) grows hair: the
    hairline of Hairloom's own samples (core/src/samples is_head_scalp), in Blender's axes.

    Chosen by looking at the scan (crown z ≈ 3.98, forehead y ≈ -2.2, back of the skull
    y ≈ 2.0, ears at |x| > 1.35 below z ≈ 2.2): above a hairline plane that rises from the
    nape (z ≈ 0.2 at the back) to the forehead (z ≈ 3.1 at the front), minus the ears and
    any face turned downwards (under the chin, inside the ears)."""
    above_hairline = centre.z > 1.6 - 0.69 * centre.y
    ear = abs(centre.x) > 1.35 and centre.z < 2.2
    return above_hairline and not ear and normal.z > -0.35


def make_scalp(head):
    """A copy of the head's hair-growing faces, with its UV map (curves on a surface need
    one), keeping only the largest edge-connected piece so no stray island grows hair.

    The scalp is cut along the middle parting (x = 0, in front of the crown) and the cut
    opened, so that no face spans the parting: each side's strands take that side's comb
    and clump among themselves ("side" = 0 left, 1 right, per vertex)."""
    bm = bmesh.new()
    bm.from_mesh(head.data)
    keep = {f for f in bm.faces if is_scalp(f.calc_center_median() / HEAD_SCALE, f.normal)}
    pieces = []
    unvisited = set(keep)
    while unvisited:
        stack, piece = [unvisited.pop()], set()
        while stack:
            face = stack.pop()
            piece.add(face)
            for edge in face.edges:
                for other in edge.link_faces:
                    if other in unvisited:
                        unvisited.remove(other)
                        stack.append(other)
        pieces.append(piece)
    largest = max(pieces, key=len)
    bmesh.ops.delete(bm, geom=[f for f in bm.faces if f not in largest], context="FACES")
    cut = bmesh.ops.bisect_plane(bm, geom=bm.verts[:] + bm.edges[:] + bm.faces[:],
                                 plane_co=(0.0, 0.0, 0.0), plane_no=(1.0, 0.0, 0.0))
    # The parting runs from the forehead back to the crown (y = 0); behind it the hair
    # falls back from both sides alike, so the cut stays closed there.
    bmesh.ops.split_edges(bm, edges=[e for e in cut["geom_cut"]
                                     if isinstance(e, bmesh.types.BMEdge)
                                     and max(v.co.y for v in e.verts) < 0.0])
    side = [int(sum(f.calc_center_median().x for f in v.link_faces) > 0.0) for v in bm.verts]
    mesh = bpy.data.meshes.new("Scalp")
    bm.to_mesh(mesh)
    bm.free()
    mesh.attributes.new("side", "INT", "POINT").data.foreach_set("value", side)
    scalp = bpy.data.objects.new("Scalp", mesh)
    bpy.context.scene.collection.objects.link(scalp)
    area = sum(p.area for p in mesh.polygons)
    print(f"scalp: {len(largest)} of {len(head.data.polygons)} head faces "
          f"(pieces {sorted(map(len, pieces), reverse=True)}), {len(mesh.polygons)} after the "
          f"cut at the parting, {area:.4f} m², UV maps {mesh.uv_layers.keys()}")
    return scalp


def add_comb(scalp):
    """Stores on the scalp, per vertex, where a strand rooted there should end (the tip's
    offset from the root, in m): down and a little away from the head's vertical axis, and
    for roots in front of the crown sideways, away from the parting, so the front hair
    frames the face instead of falling over it. "Generate Hair Curves" carries the
    scalp's attributes onto the curves it grows, where "Displace Hair Curves" reads it."""
    mesh = scalp.data
    co = np.array([v.co[:] for v in mesh.vertices])
    side = np.empty(len(co), np.int32)
    mesh.attributes["side"].data.foreach_get("value", side)
    front = np.clip(-co[:, 1] / 0.09, 0.0, 1.0)  # 0 behind the crown, 1 at the forehead
    # Away from the parting, more so towards the forehead; behind the crown (front = 0) the
    # comb is the same on both sides of x = 0, where there is no parting.
    away = np.stack([(2 * side - 1) * (np.abs(co[:, 0]) + 0.08 * front),
                     np.maximum(co[:, 1], 0.0) + 0.005], 1)
    away /= np.linalg.norm(away, axis=1, keepdims=True)
    spread = 0.3 + 0.8 * front
    tip = np.stack([spread * away[:, 0], spread * away[:, 1], -np.ones(len(co))], 1)
    tip *= 0.9 * HAIR_LENGTH / np.linalg.norm(tip, axis=1, keepdims=True)
    attribute = mesh.attributes.new("comb", "FLOAT_VECTOR", "POINT")
    attribute.data.foreach_set("vector", tip.astype(np.float32).ravel())


def hair_assets_blend():
    # bpy.__file__ lies in bpy/5.3/scripts/modules/bpy/; the assets under bpy/5.3/datafiles.
    version = "%d.%d" % bpy.app.version[:2]
    base = os.path.dirname(bpy.__file__)
    while os.path.basename(base) != version and base != "/":
        base = os.path.dirname(base)
    path = os.path.join(base, "datafiles", "assets", "nodes",
                        "procedural_hair_node_assets.blend")
    if not os.path.isfile(path):
        sys.exit(f"no hair node assets at {path}")
    return path


def append_hair_assets():
    with bpy.data.libraries.load(hair_assets_blend(), link=False) as (source, target):
        target.node_groups = [n for n in source.node_groups
                              if "Hair Curve" in n or n == "Create Guide Index Map"]
    print("node assets:", ", ".join(sorted(g.name for g in bpy.data.node_groups
                                              if g.is_modifier)))


def add_asset(obj, group_name, **inputs):
    """Adds a geometry-nodes modifier running the appended asset `group_name` and sets its
    inputs by their names as the modifier panel shows them ("Panel/Name" for inputs in a
    panel whose name is not unique; `_` stands for a space). A value ("attribute", NAME)
    feeds a field input from the named attribute."""
    group = bpy.data.node_groups[group_name]
    modifier = obj.modifiers.new(group_name, "NODES")
    modifier.node_group = group
    identifiers = {}
    for item in group.interface.items_tree:
        # Geometry inputs cannot be set on a modifier; skipping them also disambiguates
        # assets that offer a surface both as geometry and as object under one name.
        if (item.item_type != "SOCKET" or item.in_out != "INPUT"
                or item.socket_type == "NodeSocketGeometry"):
            continue
        if item.parent and item.parent.name:
            identifiers.setdefault(f"{item.parent.name}/{item.name}", item.identifier)
        identifiers.setdefault(item.name, item.identifier)
    for name, value in inputs.items():
        name = name.replace("_", " ")
        if name not in identifiers:
            sys.exit(f"{group_name} has no input {name!r} (has {sorted(identifiers)})")
        # Blender 5's modifier inputs are RNA (modifier.properties.inputs), no longer ID
        # properties (modifier[identifier]).
        socket = getattr(modifier.properties.inputs, identifiers[name])
        if isinstance(value, tuple) and value[0] == "attribute":
            socket.type = "ATTRIBUTE"
            socket.attribute_name = value[1]
        else:
            socket.value = value
    return modifier


def make_groom(head, scalp):
    curves = bpy.data.hair_curves.new("Hair")
    hair = bpy.data.objects.new("Hair", curves)
    bpy.context.scene.collection.objects.link(hair)
    curves.surface = scalp
    curves.surface_uv_map = "UVMap"
    # Straight strands along the scalp's normals, attached (surface_uv_coordinate).
    add_asset(hair, "Generate Hair Curves", Surface=scalp, Surface_UV_Map=("attribute", "UVMap"),
              Hair_Length=HAIR_LENGTH, Control_Points=CONTROL_POINTS, Density=DENSITY, Seed=7)
    # Combing: the displacement grows along each strand from 0 at the root to, at the tip,
    # the comb target minus the strand as grown (its length along the surface normal), so
    # every tip lands on its target. Shape 0.5 keeps the first part of the strand close to
    # the normal, so the hair rises off the scalp before it falls, as real hair does.
    add_asset(hair, "Displace Hair Curves", Displace_Vector=("attribute", "comb"), Shape=0.5,
              **{"Surface Normal/Surface Normal": True,
                 "Surface Normal/Surface Input Type": "Object",
                 "Surface Normal/Surface": scalp,
                 "Surface Normal/Surface Normal Distance": -HAIR_LENGTH})
    # The straight paths from root to tip cross the skull; push what is inside out to
    # 4 mm above the whole head (ears and neck included), roots kept.
    add_asset(hair, "Shrinkwrap Hair Curves", Surface=head, Offset_Distance=0.004,
              Smoothing_Steps=3)
    add_asset(hair, "Smooth Hair Curves", Iterations=10)
    # Guides 12 mm apart, chosen on each side of the parting separately, so no clump
    # pulls strands across it; clumping and curl both follow this map (guide_curve_index).
    add_asset(hair, "Create Guide Index Map", Guide_Distance=0.012,
              Group_ID=("attribute", "side"), Seed=2)
    add_asset(hair, "Clump Hair Curves", Factor=0.5, Shape=0.3, Preserve_Length=True,
              Seed=1)
    # Gentle waves (3 mm radius) from a third of the way down; no subdivision, so the
    # strands keep their 24 points.
    add_asset(hair, "Curl Hair Curves", Subdivision=0, Curl_Start=0.35, Radius=0.003,
              Frequency=2.5, Seed=3)
    add_asset(hair, "Frizz Hair Curves", Distance=0.001, Seed=11)
    add_asset(hair, "Set Hair Curve Profile", Radius=STRAND_RADIUS)
    return hair


def report(hair):
    """Prints the evaluated groom's counts, strand lengths and bounds."""
    evaluated = hair.evaluated_get(bpy.context.evaluated_depsgraph_get()).data
    points = np.empty(len(evaluated.points) * 3, np.float32)
    evaluated.attributes["position"].data.foreach_get("vector", points)
    points = points.reshape(-1, 3)
    offsets = np.empty(len(evaluated.curves) + 1, np.int32)
    evaluated.curve_offset_data.foreach_get("value", offsets)
    segments = np.linalg.norm(np.diff(points, axis=0), axis=1)
    segments[offsets[1:-1] - 1] = 0.0  # the step from one curve's tip to the next root
    lengths = np.add.reduceat(segments, offsets[:-1])
    per_curve = np.diff(offsets)
    lo, hi = points.min(0), points.max(0)
    # The exported frame: Blender's (x, y, z) become (x, z, -y), +Y up, facing +Z.
    lo_y, hi_y = [lo[0], lo[2], -hi[1]], [hi[0], hi[2], -lo[1]]
    print(f"groom: {len(per_curve)} curves, {len(points)} points "
          f"({per_curve.min()}–{per_curve.max()} per curve), "
          f"strand length {lengths.mean():.4f} m mean ({lengths.min():.4f}–{lengths.max():.4f})")
    print(f"bounds (Blender, z up): {np.round(lo, 4)} – {np.round(hi, 4)} m")
    print(f"bounds (exported, y up): {np.round(lo_y, 4)} – {np.round(hi_y, 4)} m")


def select_only(obj):
    bpy.ops.object.select_all(action="DESELECT")
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj


def export(hair, scalp, head, out):
    frame = bpy.context.scene.frame_current
    # The groom and its scalp go out under a moved and turned parent, as a groom
    # on a posed or placed character does: every file then carries that transform (an
    # Alembic Xform, USD xformOps, the glTF node), and Hairloom must apply it to land the
    # curves on the scalp. The head, scalp and hair move together, so the hair the node
    # groups grow (shrinkwrapped to the head) is unchanged.
    pivot = bpy.data.objects.new("groom_pivot", None)
    bpy.context.scene.collection.objects.link(pivot)
    pivot.location = (0.04, -0.03, 0.12)
    pivot.rotation_euler = (math.radians(10.0), 0.0, math.radians(25.0))
    for obj in (head, scalp, hair):
        obj.parent = pivot
    bpy.context.view_layer.update()
    select_only(hair)
    # Alembic is always written +Y up (Blender converts the points and the transforms).
    bpy.ops.wm.alembic_export(filepath=os.path.join(out, "blender_groom.abc"),
                              selected=True, start=frame, end=frame)
    # USD is written +Z up by default (stage upAxis "Z"), which Hairloom does not read:
    # convert to +Y up, facing +Z, like the glTF and Alembic.
    bpy.ops.wm.usd_export(filepath=os.path.join(out, "blender_groom.usda"),
                          selected_objects_only=True, export_materials=False,
                          convert_orientation=True,
                          export_global_forward_selection="NEGATIVE_Z",
                          export_global_up_selection="Y")
    select_only(scalp)
    bpy.ops.export_scene.gltf(filepath=os.path.join(out, "blender_scalp.glb"),
                              export_format="GLB", use_selection=True)


def render(hair, head, out):
    """Front, side and back pictures of the groom on the head, Workbench (no GPU needed)."""
    scene = bpy.context.scene
    hair.color = (0.30, 0.16, 0.07, 1.0)
    head.color = (0.80, 0.66, 0.56, 1.0)
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.display.shading.light = "STUDIO"
    scene.display.shading.color_type = "OBJECT"
    scene.render.resolution_x = scene.render.resolution_y = 480
    scene.world = bpy.data.worlds.new("World")
    scene.world.color = (0.12, 0.12, 0.13)
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(camera)
    scene.camera = camera
    camera.data.type = "ORTHO"
    camera.data.ortho_scale = 0.5
    centre = Vector((0.0, 0.0, 0.03))
    for view, direction, turn in [("front", (0, -1, 0), 0.0), ("side", (1, 0, 0), 0.5),
                                  ("back", (0, 1, 0), 1.0)]:
        camera.location = centre + Vector(direction)
        camera.rotation_euler = (math.pi / 2, 0.0, turn * math.pi)
        scene.render.filepath = os.path.join(out, f"blender_{view}.png")
        bpy.ops.render.render(write_still=True)


def main():
    args = parse_args()
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    started = time.perf_counter()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    head = import_head()
    scalp = make_scalp(head)
    add_comb(scalp)
    append_hair_assets()
    hair = make_groom(head, scalp)
    report(hair)
    export(hair, scalp, head, out)
    print(f"wrote {out}/blender_groom.abc, blender_groom.usda, blender_scalp.glb "
          f"in {time.perf_counter() - started:.1f} s (Blender {bpy.app.version_string})")
    if args.render:
        scalp.hide_render = True
        render(hair, head, out)


if __name__ == "__main__":
    main()
