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
    points_attr = curves.GetPointsAttr()
    # An animation (hairloom simulate) has points at each time sample: every sample must
    # hold as many points as the curves need, and the samples must move.
    times = points_attr.GetTimeSamples()
    samples = [points_attr.Get(t) for t in times] if times else [points_attr.Get()]
    points = samples[0]
    animated_ok = all(s is not None and len(s) == len(points) for s in samples)
    if len(samples) > 1:
        animated_ok = animated_ok and any(s != samples[0] for s in samples[1:])
        animated_ok = animated_ok and stage.GetEndTimeCode() == times[-1]
    st = UsdGeom.PrimvarsAPI(prim).GetPrimvar("st").Get()
    ok = (
        prim.GetTypeName() == "BasisCurves"
        and counts is not None
        and points is not None
        and sum(counts) == len(points)
        and len(st) == len(counts)
        and all(c >= 2 for c in counts)
        and UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.y
        and animated_ok
    )
    print(f"{path}: usd-core {Usd.GetVersion()}: {len(counts)} curves, {len(points)} points, {len(samples)} time sample(s){'' if ok else ' INCONSISTENT'}")
    failed |= not ok
sys.exit(1 if failed else 0)
