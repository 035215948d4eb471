#!/usr/bin/env python3
"""Independent check of a STEP file with OpenCASCADE (the `cadquery-ocp-novtk` wheel).

Usage: check_step.py PART.step [POINTS.xyz [EVERY]]

Prints one JSON object: whether the reader transferred a shape, the shape's validity
(BRepCheck_Analyzer), its solids, shells (and whether each is closed), faces per surface type,
edges per curve type, volume and area (BRepGProp), and with POINTS (one "x y z" per line) the
largest and mean distance from those points (every EVERY-th line, default 1) to the shape
(BRepExtrema). Nothing in it knows how
crease built the file.
"""
import json
import sys

from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Surface
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.BRepGProp import BRepGProp
from OCP.GeomAbs import (GeomAbs_BSplineCurve, GeomAbs_BSplineSurface, GeomAbs_Circle,
                         GeomAbs_Cone, GeomAbs_Cylinder, GeomAbs_Ellipse, GeomAbs_Line,
                         GeomAbs_Plane, GeomAbs_Sphere, GeomAbs_Torus)
from OCP.GProp import GProp_GProps
from OCP.gp import gp_Pnt
from OCP.IFSelect import IFSelect_RetDone
from OCP.STEPControl import STEPControl_Reader
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_SHELL, TopAbs_SOLID
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS

SURFACES = {GeomAbs_Plane: "plane", GeomAbs_Cylinder: "cylinder", GeomAbs_Cone: "cone",
            GeomAbs_Sphere: "sphere", GeomAbs_Torus: "torus",
            GeomAbs_BSplineSurface: "bspline"}
CURVES = {GeomAbs_Line: "line", GeomAbs_Circle: "circle", GeomAbs_Ellipse: "ellipse",
          GeomAbs_BSplineCurve: "bspline"}


def cast(name):
    """cast("Solid") in older OCP wheels, TopoDS.Solid in newer ones."""
    return getattr(TopoDS, name + "_s", None) or getattr(TopoDS, name)


def items(shape, kind, to):
    out = []
    exp = TopExp_Explorer(shape, kind)
    while exp.More():
        out.append(to(exp.Current()))
        exp.Next()
    return out


def main():
    reader = STEPControl_Reader()
    status = reader.ReadFile(sys.argv[1])
    result = {"read": status == IFSelect_RetDone}
    if not result["read"]:
        print(json.dumps(result))
        return
    reader.TransferRoots()
    shape = reader.OneShape()
    result["valid"] = bool(BRepCheck_Analyzer(shape).IsValid())
    solids = items(shape, TopAbs_SOLID, cast("Solid"))
    shells = items(shape, TopAbs_SHELL, cast("Shell"))
    faces = items(shape, TopAbs_FACE, cast("Face"))
    edges = items(shape, TopAbs_EDGE, cast("Edge"))
    result["solids"] = len(solids)
    result["shells"] = len(shells)
    result["closed_shells"] = sum(1 for s in shells if s.Closed())
    by_type = {}
    for f in faces:
        t = SURFACES.get(BRepAdaptor_Surface(f).GetType(), "other")
        by_type[t] = by_type.get(t, 0) + 1
    result["faces"] = by_type
    # Seam edges appear twice in the explorer; count each edge once.
    seen = set()
    curves = {}
    for e in edges:
        h = e.HashCode(1 << 30) if hasattr(e, "HashCode") else hash(e)
        if h in seen:
            continue
        seen.add(h)
        t = CURVES.get(BRepAdaptor_Curve(e).GetType(), "other")
        curves[t] = curves.get(t, 0) + 1
    result["edges"] = curves
    # Adaptive integration (relative error 1e-9): the default fixed-order rule misjudges faces
    # bounded by many-span curves.
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props, 1e-9)
    result["volume"] = props.Mass()
    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(shape, props, 1e-9)
    result["area"] = props.Mass()
    if len(sys.argv) > 2:
        dists = []
        every = int(sys.argv[3]) if len(sys.argv) > 3 else 1
        with open(sys.argv[2]) as f:
            for i, line in enumerate(f):
                if i % every:
                    continue
                xyz = line.split()
                if len(xyz) < 3:
                    continue
                v = BRepBuilderAPI_MakeVertex(gp_Pnt(*map(float, xyz[:3]))).Vertex()
                d = BRepExtrema_DistShapeShape(v, shape)
                dists.append(d.Value())
        result["max_distance"] = max(dists) if dists else None
        result["mean_distance"] = sum(dists) / len(dists) if dists else None
    print(json.dumps(result))


if __name__ == "__main__":
    main()
