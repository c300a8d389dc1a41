"""Imports Hairloom strand exports into Blender (PyPI `bpy`) with Blender's default import
settings and checks that the groom lands as Hairloom draws it.

Usage: python check_blender.py REFERENCE.hair FILE.abc|FILE.usda...   Exits 1 on any problem.

REFERENCE.hair holds the same strands in Hairloom's model space (metres, y up, the face
toward +z; cyHair, with per-point thickness). Blender is z up with the face toward -y, so a
model point (x, y, z) must land at (x, -z, y) in Blender's world: upright, facing front,
not mirrored, at its size. For each file the check compares every point of every curve
Blender made (world space, after the object's own transform), each point's radius with
half the reference thickness (the taper), and reports which of the file's attributes
Blender kept: Blender's Alembic importer keeps no custom attributes (no groom_*), its USD
importer keeps primvars (the root uv as `surface_uv_coordinate`, `displayColor`).
"""
import json
import struct
import sys

import bpy
import numpy as np

TOLERANCE_M = 1e-5


def read_hair(path):
    """Points (n, 3) and per-point thickness of a cyHair file as Hairloom writes it."""
    data = open(path, "rb").read()
    magic, strands, points, arrays, default_segments = struct.unpack_from("<4sIIII", data, 0)
    if magic != b"HAIR":
        raise ValueError(f"{path}: not a .hair file")
    at = 128
    if arrays & 1:
        segments = np.frombuffer(data, "<u2", strands, at).astype(int)
        at += 2 * strands
    else:
        segments = np.full(strands, default_segments)
    xyz = np.frombuffer(data, "<f4", 3 * points, at).reshape(-1, 3)
    at += 12 * points
    if not arrays & 4:
        raise ValueError(f"{path}: no thickness array")
    thickness = np.frombuffer(data, "<f4", points, at)
    return xyz, thickness, segments + 1


def import_file(path):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    if path.endswith(".abc"):
        bpy.ops.wm.alembic_import(filepath=path)
    else:
        bpy.ops.wm.usd_import(filepath=path)
    bpy.context.view_layer.update()


def check(reference, path):
    xyz, thickness, counts = reference
    expected = np.stack([xyz[:, 0], -xyz[:, 2], xyz[:, 1]], axis=1)
    import_file(path)
    problems = []
    hair = [o for o in bpy.data.objects if o.type == "CURVES" and o.name.lower() == "hair"]
    if len(hair) != 1:
        return {"problems": [f"{len(hair)} hair curves objects (of {[o.name for o in bpy.data.objects]})"]}
    ob = hair[0]
    curves = ob.data
    n = len(curves.points)
    local = np.empty(3 * n, np.float32)
    curves.attributes["position"].data.foreach_get("vector", local)
    matrix = np.array(ob.matrix_world)
    world = local.reshape(-1, 3) @ matrix[:3, :3].T + matrix[:3, 3]
    sizes = np.array([c.points_length for c in curves.curves])
    if len(sizes) != len(counts) or not np.array_equal(sizes, counts):
        problems.append(f"{len(sizes)} curves, expected {len(counts)} with the reference's counts")
        return {"problems": problems}
    deviation = float(np.abs(world - expected).max())
    if deviation > TOLERANCE_M:
        problems.append(f"points land up to {deviation:.3g} m from where Hairloom draws them")
    radius = np.empty(n, np.float32)
    curves.attributes["radius"].data.foreach_get("value", radius)
    # The object's scale applies to the radius too (Blender draws it in object space).
    scale = float(np.cbrt(abs(np.linalg.det(matrix[:3, :3]))))
    radius_error = float(np.abs(radius * scale - 0.5 * thickness).max() / thickness.max())
    if radius_error > 1e-3:
        problems.append(f"radii differ from the taper by up to {radius_error:.3g} of the width")
    heights = world[:, 2]
    roots = np.concatenate([[0], np.cumsum(counts)[:-1]])
    tips = roots + counts - 1
    attributes = sorted(a.name for a in curves.attributes if not a.name.startswith("."))
    return {
        "problems": problems,
        "curves": int(len(counts)),
        "points": int(n),
        "max_deviation_m": deviation,
        "crown_z_m": float(heights.max()),
        "roots_above_tips": float(np.mean(heights[roots] > heights[tips])),
        "radius_root_tip_m": [float(radius[0] * scale), float(radius[counts[0] - 1] * scale)],
        "attributes": attributes,
        "surface": curves.surface.name if curves.surface else None,
    }


def main():
    reference = read_hair(sys.argv[1])
    failed = False
    for path in sys.argv[2:]:
        try:
            report = check(reference, path)
        except Exception as error:  # Blender's own message names the problem
            report = {"problems": [f"cannot import: {error}"]}
        print(f"{path}: Blender {bpy.app.version_string}: {json.dumps(report)}")
        failed |= bool(report["problems"])
    sys.exit(1 if failed else 0)


main()
