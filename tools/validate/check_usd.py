"""Opens Hairloom .usda exports with Pixar's USD (PyPI usd-core) and checks their curves,
then runs every validator usd-core registers (UsdValidation) on the stage.

Usage: python check_usd.py FILE.usda...   Exits 1 on any problem."""
import sys

from pxr import Usd, UsdGeom, UsdValidation

VALIDATORS = UsdValidation.ValidationRegistry().GetOrLoadAllValidators()

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
    primvars = UsdGeom.PrimvarsAPI(prim)
    st = primvars.GetPrimvar("st").Get()
    surface_uv = primvars.GetPrimvar("surface_uv_coordinate").Get()
    # Boundable: an extent at every time the points have, holding every point.
    extent_attr = curves.GetExtentAttr()
    extents = [extent_attr.Get(t) for t in times] if times else [extent_attr.Get()]
    extent_ok = all(
        e is not None
        and all(e[0][k] <= p[k] <= e[1][k] for p in s for k in range(3))
        for e, s in zip(extents, samples)
    )
    # Widths and colour per point: widths taper from root to tip, colours in [0, 1].
    widths = curves.GetWidthsAttr().Get()
    colors = primvars.GetPrimvar("displayColor").Get()
    look_ok = (
        widths is not None
        and colors is not None
        and curves.GetWidthsInterpolation() == UsdGeom.Tokens.vertex
        and primvars.GetPrimvar("displayColor").GetInterpolation() == UsdGeom.Tokens.vertex
        and len(widths) == len(colors) == len(points)
        and all(0.0 <= c[k] <= 1.0 for c in colors for k in range(3))
    )
    if look_ok:
        start = 0
        for count in counts:
            look_ok = look_ok and widths[start] > widths[start + count - 1] > 0
            start += count
    # The scalp the curves grow from: a mesh whose face-varying st holds every root uv.
    scalp = UsdGeom.Mesh(stage.GetPrimAtPath("/Scalp"))
    scalp_ok = scalp.GetPrim().IsValid()
    if scalp_ok:
        face_counts = scalp.GetFaceVertexCountsAttr().Get()
        face_indices = scalp.GetFaceVertexIndicesAttr().Get()
        scalp_points = scalp.GetPointsAttr().Get(times[0] if times else Usd.TimeCode.Default())
        scalp_st = UsdGeom.PrimvarsAPI(scalp.GetPrim()).GetPrimvar("st").Get() or []
        if not scalp_st:
            scalp_st = [(0.0, 0.0)]
        lo = [min(uv[k] for uv in scalp_st) - 1e-5 for k in range(2)]
        hi = [max(uv[k] for uv in scalp_st) + 1e-5 for k in range(2)]
        scalp_extent = scalp.GetExtentAttr().Get(times[0] if times else Usd.TimeCode.Default())
        scalp_ok = (
            scalp_extent is not None
            and all(scalp_extent[0][k] <= p[k] <= scalp_extent[1][k] for p in scalp_points for k in range(3))
            and sum(face_counts) == len(face_indices) == len(scalp_st)
            and all(0 <= i < len(scalp_points) for i in face_indices)
            and all(lo[k] <= uv[k] <= hi[k] for uv in st for k in range(2))
        )
    ok = (
        prim.GetTypeName() == "BasisCurves"
        and counts is not None
        and points is not None
        and sum(counts) == len(points)
        and len(st) == len(counts)
        and surface_uv is not None
        and list(surface_uv) == list(st)
        and extent_ok
        and scalp_ok
        and all(c >= 2 for c in counts)
        and UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.y
        and animated_ok
        and look_ok
    )
    issues = [
        e for e in UsdValidation.ValidationContext(VALIDATORS).Validate(stage)
        if e.GetType() == UsdValidation.ValidationErrorType.Error
    ]
    ok = ok and not issues
    print(f"{path}: usd-core {Usd.GetVersion()}: {len(counts)} curves, {len(points)} points, {len(samples)} time sample(s), {len(VALIDATORS)} validators: {len(issues)} errors{'' if ok else ' INCONSISTENT'}")
    for e in issues[:10]:
        print(f"  {e.GetName()}: {e.GetMessage()}")
    failed |= not ok
sys.exit(1 if failed else 0)
