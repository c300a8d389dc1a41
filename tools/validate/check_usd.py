"""Opens Hairloom .usda exports with Pixar's USD (PyPI usd-core) and checks their curves.

Usage: python check_usd.py FILE.usda...   Exits 1 on any problem."""
import sys

from pxr import Usd, UsdGeom

failed = False
for path in sys.argv[1:]:
    stage = Usd.Stage.Open(path)
    if stage is None:
        print(f"{path}: USD cannot open the stage")
        failed = True
        continue
    prim = stage.GetDefaultPrim()
    curves = UsdGeom.BasisCurves(prim)
    counts = curves.GetCurveVertexCountsAttr().Get()
    points = curves.GetPointsAttr().Get()
    st = UsdGeom.PrimvarsAPI(prim).GetPrimvar("st").Get()
    ok = (
        prim.GetTypeName() == "BasisCurves"
        and counts is not None
        and points is not None
        and sum(counts) == len(points)
        and len(st) == len(counts)
        and all(c >= 2 for c in counts)
        and UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.y
    )
    print(f"{path}: usd-core {Usd.GetVersion()}: {len(counts)} curves, {len(points)} points{'' if ok else ' INCONSISTENT'}")
    failed |= not ok
sys.exit(1 if failed else 0)
