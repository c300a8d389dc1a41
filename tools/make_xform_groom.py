"""Writes `assets/grooms/xform_groom.abc` with the Alembic C++ library (PyPI alembic3d): curves
under nested transforms, as Maya, Houdini and Blender write grooms (an object's transform
above its curves), and `xform_groom.json` with every curve point in world space as the
library itself composes the transforms (IXform samples, Imath's row-vector convention,
`inheritsXforms` honoured). Hairloom's reader must land on those points.

Usage: python make_xform_groom.py OUT_DIR   (the validate venv of `make test` has alembic3d)
"""
import json
import math
import os
import sys

import imath
from alembic3d import Abc, AbcGeom

out_dir = sys.argv[1]
abc_path = os.path.join(out_dir, "xform_groom.abc")

# Two short curves per curves object, in the object's own space (centimetres, say).
LOCAL = [
    [(0.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.2, 2.0, 0.1)],
    [(1.0, 0.0, 0.0), (1.0, 1.5, 0.5)],
]


def curves(parent, name):
    obj = AbcGeom.OCurves(parent, name)
    points = imath.V3fArray(sum(len(c) for c in LOCAL))
    i = 0
    for curve in LOCAL:
        for p in curve:
            points[i] = imath.V3f(*p)
            i += 1
    counts = imath.IntArray(len(LOCAL))
    for k, curve in enumerate(LOCAL):
        counts[k] = len(curve)
    sample = AbcGeom.OCurvesSchemaSample(
        points, counts, AbcGeom.CurveType.kLinear, AbcGeom.CurvePeriodicity.kNonPeriodic
    )
    obj.getSchema().set(sample)
    return obj


def xform(parent, name, ops, inherits=True):
    obj = AbcGeom.OXform(parent, name)
    sample = AbcGeom.XformSample()
    for kind, value in ops:
        if kind == "translate":
            sample.setTranslation(imath.V3d(*value))
        elif kind == "rotate":
            axis, degrees = value
            sample.setRotation(imath.V3d(*axis), degrees)
        elif kind == "rotate_x":
            sample.setXRotation(value)
        elif kind == "scale":
            sample.setScale(imath.V3d(*value))
        elif kind == "matrix":
            m = imath.M44d()
            for r in range(4):
                for c in range(4):
                    m[r][c] = value[r][c]
            sample.setMatrix(m)
    sample.setInheritsXforms(inherits)
    obj.getSchema().set(sample)
    return obj


archive = Abc.OArchive(abc_path)
top = archive.getTop()
# A Maya-style stack (translate, rotate about a tilted axis, scale by 0.01: centimetres to
# metres) over a child with a matrix op (a quarter turn about x and a shift), and a sibling
# that does not inherit its parent's transform.
a = xform(
    top,
    "groom_xform",
    [("translate", (0.1, 1.6, -0.05)), ("rotate", ((0.0, 1.0, 0.2), 30.0)), ("scale", (0.01, 0.01, 0.01))],
)
b_matrix = [[1, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0], [5, 0, 2, 1]]
b = xform(a, "tilted", [("matrix", b_matrix), ("rotate_x", 10.0)])
curves(b, "hair")
c = xform(a, "detached", [("translate", (0.0, 1.0, 0.0))], inherits=False)
curves(c, "strays")
del archive, top, a, b, c

# Read back with the library: world = local × parent world (row vectors), unless the
# transform does not inherit.
expected = {}


def visit(obj, parent_world):
    world = parent_world
    if AbcGeom.IXform.matches(obj.getHeader()):
        x = AbcGeom.IXform(obj, Abc.WrapExistingFlag.kWrapExisting)
        value = x.getSchema().getValue()
        local = value.getMatrix()
        world = local * parent_world if value.getInheritsXforms() else local
    if AbcGeom.ICurves.matches(obj.getHeader()):
        c = AbcGeom.ICurves(obj, Abc.WrapExistingFlag.kWrapExisting)
        positions = c.getSchema().getValue().getPositions()
        expected[obj.getFullName()] = [
            list(imath.V3d(p[0], p[1], p[2]) * world) for p in positions
        ]
    for i in range(obj.getNumChildren()):
        visit(obj.getChild(i), world)


identity = imath.M44d()
visit(Abc.IArchive(abc_path).getTop(), identity)
with open(os.path.join(out_dir, "xform_groom.json"), "w") as f:
    json.dump(expected, f, indent=1)
print(abc_path, {k: len(v) for k, v in expected.items()})
