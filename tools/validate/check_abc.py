"""Opens Hairloom .abc grooms with the Alembic C++ library (PyPI alembic3d) and checks them as
Unreal's Groom importer reads them.

Usage: python check_abc.py FILE.abc...   Exits 1 on any problem.

For each file: two ICurves objects, `hair` and `guides`, that the library recognises as curves
(by schemaObjTitle, as Unreal does); linear curves whose vertex counts add up to the points;
self bounds that hold every point; and the groom attributes (Epic's "Alembic for Grooms" 1.5):
per-curve groom_guide (0 on strands, 1 on guides), groom_id (unique), groom_group_id,
groom_root_uv, and on strands groom_closest_guides naming guide ids of the same group with
groom_guide_weights summing to one; per-point groom_width (and width) tapering from root to
tip, and on strands a per-point groom_color in [0, 1]; groom_version_major/minor in user
properties."""
import sys

from alembic3d import Abc, AbcGeom

failed = False


def arrays(compound):
    out = {}
    for k in range(compound.getNumProperties()):
        header = compound.getPropertyHeader(k)
        prop = Abc.IArrayProperty(compound, header.getName())
        out[header.getName()] = (header.getMetaData().get("geoScope"), list(prop.getValue()))
    return out


for path in sys.argv[1:]:
    problems = []
    try:
        archive = Abc.IArchive(path)
        top = archive.getTop()
        curves = {}
        for i in range(top.getNumChildren()):
            child = top.getChild(i)
            if not AbcGeom.ICurves.matches(child.getMetaData()):
                problems.append(f"{child.getName()} is not recognised as curves")
                continue
            schema = AbcGeom.ICurves(child, Abc.WrapExistingFlag.kWrapExisting).getSchema()
            sample = schema.getValue()
            points = sample.getPositions()
            counts = list(sample.getCurvesNumVertices())
            bounds = sample.getSelfBounds()
            if sum(counts) != len(points) or any(c < 2 for c in counts):
                problems.append(f"{child.getName()}: vertex counts do not add up to {len(points)} points")
            lo, hi = bounds.min(), bounds.max()
            if any(not (lo[k] <= p[k] <= hi[k]) for p in points for k in range(3)):
                problems.append(f"{child.getName()}: a point lies outside .selfBnds")
            if sample.getType() != AbcGeom.CurveType.kLinear:
                problems.append(f"{child.getName()}: not linear curves")
            user = schema.getUserProperties()
            version = [Abc.IScalarProperty(user, n).getValue() for n in ("groom_version_major", "groom_version_minor")]
            if version != [1, 5]:
                problems.append(f"{child.getName()}: groom version {version}")
            attributes = arrays(schema.getArbGeomParams())
            per_point = {"groom_width", "groom_color"}
            for name, values in attributes.items():
                scope, expected = ("vtx", len(points)) if name in per_point else ("uni", len(counts))
                if values[0] != scope or len(values[1]) != expected:
                    problems.append(f"{child.getName()}.{name}: {len(values[1])} values at scope {values[0]} for {expected} at {scope}")
            widths = list(schema.getWidthsParam().getExpandedValue().getVals())
            if len(widths) != len(points) or not all(w > 0 for w in widths):
                problems.append(f"{child.getName()}: {len(widths)} widths for {len(points)} points")
            else:
                start = 0
                for count in counts:
                    if not all(a > b for a, b in zip(widths[start:start + count], widths[start + 1:start + count])):
                        problems.append(f"{child.getName()}: widths do not taper from root to tip")
                        break
                    start += count
            if child.getName() == "hair":
                colors = attributes.get("groom_color", (None, []))[1]
                if not colors or not all(0.0 <= c[k] <= 1.0 for c in colors for k in range(3)):
                    problems.append("hair: no groom_color in [0, 1] per point")
            samples = schema.getNumSamples()
            if samples > 1:
                # An animation: the last sample moved, holds the same curves, and its bounds too.
                last = schema.getValue(Abc.ISampleSelector(samples - 1))
                moved = last.getPositions()
                if len(moved) != len(points) or all(a == b for a, b in zip(moved, points)):
                    problems.append(f"{child.getName()}: the last of {samples} samples did not move")
                lo, hi = last.getSelfBounds().min(), last.getSelfBounds().max()
                if any(not (lo[k] <= p[k] <= hi[k]) for p in moved for k in range(3)):
                    problems.append(f"{child.getName()}: a point of the last sample lies outside its .selfBnds")
            curves[child.getName()] = (counts, attributes, len(points), samples)
        if sorted(curves) != ["guides", "hair"]:
            raise ValueError(f"objects {sorted(curves)}, expected hair and guides")
        hair, guides = curves["hair"][1], curves["guides"][1]
        if set(hair["groom_guide"][1]) - {0} or set(guides["groom_guide"][1]) - {1}:
            problems.append("groom_guide is not 0 on strands and 1 on guides")
        ids = guides["groom_id"][1] + hair["groom_id"][1]
        if len(set(ids)) != len(ids):
            problems.append("groom_id repeats")
        guide_group = dict(zip(guides["groom_id"][1], guides["groom_group_id"][1]))
        for closest, weights, group in zip(hair["groom_closest_guides"][1], hair["groom_guide_weights"][1], hair["groom_group_id"][1]):
            if any(guide_group.get(g) != group for g in closest) or abs(sum(weights) - 1) > 1e-5:
                problems.append(f"a strand's guides {closest} (weights {weights}) are not guides of its group {group}")
                break
        summary = f"{len(curves['hair'][0])} strands, {len(curves['guides'][0])} guides, {curves['hair'][2]} points, {curves['hair'][3]} sample(s)"
    except Exception as error:  # the library's own message names the problem
        problems.append(f"cannot read: {error}")
        summary = "unreadable"
    print(f"{path}: alembic3d (Alembic {Abc.GetLibraryVersionShort() if hasattr(Abc, 'GetLibraryVersionShort') else '1.8'}): {summary}{'' if not problems else ' INCONSISTENT'}")
    for problem in problems:
        print(f"  {problem}")
    failed |= bool(problems)
sys.exit(1 if failed else 0)
