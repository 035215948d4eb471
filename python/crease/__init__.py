"""crease: feature lines, sharp points and edges, analytic surfaces and B-reps of scanned parts.

Plain functions on numpy arrays, returning numpy arrays: each mirrors one command of the
``crease`` CLI with the same defaults and gives the same answers bit for bit (the Rust library
runs underneath, with the GIL released while it computes)::

    import numpy as np, crease
    geom = crease.read("scan.ply")                  # points (n, 3) float64, normals, faces, ...
    s = crease.sharp(geom.points)                   # crease sharp: s.sharp (bool), s.sharpness
    seg = crease.segment(geom.points)               # crease segment: labels, types, surfaces
    net = crease.network(geom.points)               # crease network: polylines + groups
    crease.write("out.ply", geom.points, attributes={"sharp": s.sharp})

Where an array of points is expected, an Open3D ``PointCloud`` / ``TriangleMesh``, a trimesh
``Trimesh`` / ``PointCloud`` or a :class:`Geometry` from :func:`read` is accepted too (duck-typed;
neither package is needed). A mesh given that way is used as a mesh where the CLI would use a
mesh file as one (``sharp``, ``segment``, ``reconstruct``).

Errors are exceptions carrying the CLI's message: ``ValueError`` for bad input (NaN coordinates,
wrong shapes, too few points, invalid parameters), ``OSError`` when a file cannot be opened or
written (``FileNotFoundError``, ``PermissionError``, ...), and :class:`FileFormatError` (both an
``OSError`` and a ``ValueError``) when a file's content is not valid.
"""

from __future__ import annotations

import json
import os
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _crease
from ._batch import BatchReport, batch
from ._tiled import tiled_sharp
from ._errors import CommandError, FileFormatError

__version__ = _crease.__version__

__all__ = [
    "FileFormatError",
    "CommandError",
    "BatchReport",
    "RunResult",
    "Geometry",
    "SharpResult",
    "CurvatureResult",
    "Segmentation",
    "Curves",
    "EdgeResult",
    "Reconstruction",
    "read",
    "write",
    "normals",
    "curvature",
    "sharp",
    "segment",
    "lines",
    "fillets",
    "network",
    "edges",
    "reconstruct",
    "run",
    "command",
    "batch",
    "tiled_sharp",
    "set_num_threads",
    "SURFACE_TYPES",
]

#: ``surface_type`` codes of :func:`segment` (per point or face); 255 means unassigned.
SURFACE_TYPES: Dict[int, str] = {
    0: "plane",
    1: "cylinder",
    2: "cone",
    3: "sphere",
    4: "torus",
    255: "unassigned",
}

PathLike = Union[str, "os.PathLike[str]"]


class _Record:
    """A result: its fields as attributes (and as ``dict(result)`` items)."""

    _fields: Tuple[str, ...] = ()

    def __init__(self, **fields: Any) -> None:
        for k in self._fields:
            setattr(self, k, fields.get(k))

    def keys(self) -> Tuple[str, ...]:
        return self._fields

    def __getitem__(self, key: str) -> Any:
        if key not in self._fields:
            raise KeyError(key)
        return getattr(self, key)

    def __repr__(self) -> str:
        parts = []
        for k in self._fields:
            v = getattr(self, k)
            if isinstance(v, np.ndarray):
                parts.append(f"{k}=<{v.dtype} {v.shape}>")
            elif isinstance(v, (list, tuple)):
                parts.append(f"{k}=<{len(v)} items>")
            elif isinstance(v, dict):
                parts.append(f"{k}=<dict of {len(v)}>")
            else:
                parts.append(f"{k}={v!r}")
        return f"{type(self).__name__}({', '.join(parts)})"


class Geometry(_Record):
    """What a file holds (:func:`read`).

    Attributes:
        points: (n, 3) float64 positions (mesh vertices).
        normals: (n, 3) float64, or None.
        colors: (n, 3) uint8, or None.
        attributes: dict name -> 1-D array of the per-point properties, in the file's storage
            type (uint8, int32, float32, float64, ...).
        faces: (m, 3) int64 triangles (polygons fan-triangulated), or None.
        face_attributes: dict name -> 1-D array per face.
        edges: (k, 2) int64 segments (PLY ``edge`` element), or None.
        edge_attributes: dict name -> 1-D array per edge.
        polylines: list of 1-D int64 arrays of point indices (OBJ ``l``); a closed loop repeats
            its first index.
        polyline_groups: the group (OBJ ``g``) of each polyline, or an empty list.
        report: what the reader found and did (``dropped_nonfinite``, ``notes``, ...).
    """

    _fields = (
        "points",
        "normals",
        "colors",
        "attributes",
        "faces",
        "face_attributes",
        "edges",
        "edge_attributes",
        "polylines",
        "polyline_groups",
        "report",
    )


class SharpResult(_Record):
    """Sharp feature points (:func:`sharp`).

    Attributes:
        sharp: (n,) bool, in the input's order.
        sharpness: (n,) float64, >= 1 exactly for the sharp points.
        scales: one report per scale (threshold, normalised threshold, detections).
        noise_ratio: the measured noise ratio (clouds), or None.
        regularized: whether the decisions were regularised (given or automatic).
        surfaces: what the surface stage did, or None.
        mesh: True when the mesh's vertices were classified (faces given).
        method: the measure's name.
        seconds: compute time in Rust (kNN included), as the CLI's ``--json`` ``seconds``.
        timings: ``knn`` and ``detection`` seconds.
    """

    _fields = (
        "sharp",
        "sharpness",
        "scales",
        "noise_ratio",
        "regularized",
        "surfaces",
        "mesh",
        "method",
        "seconds",
        "timings",
    )


class CurvatureResult(_Record):
    """Principal curvatures per point (:func:`curvature`), in the input's order.

    Attributes:
        k1, k2: (n,) float64, the principal curvatures (k2 <= k1); NaN where no fit exists.
        mean_curvature, gaussian_curvature: (n,) float64.
        sharp: the Bézier method's sharp vertices ((n,) bool), or None.
        failed: the number of points without an estimate.
    """

    _fields = ("k1", "k2", "mean_curvature", "gaussian_curvature", "sharp", "failed")


class Segmentation(_Record):
    """Analytic surfaces (:func:`segment`).

    Attributes:
        labels: (n,) int32 surface id per point (per face for a mesh), -1 unassigned.
        types: (n,) uint8 surface type code per point / face (see :data:`SURFACE_TYPES`).
        surfaces: list of dicts as the CLI's ``--primitives`` JSON: ``id``, ``type``, ``params``
            (plane: normal, offset; cylinder: point, direction, radius; cone: apex, axis, half
            angle; sphere: centre, radius; torus: centre, axis, radii), ``area``, ``vertices``
            (point count), ``faces``, ``rms``, ``neighbours``.
        groups: fillets, extrusions and surfaces of revolution.
        mean_edge, epsilon, seeds: as the CLI's JSON.
        mesh: True when a mesh was segmented (labels per face).
        vertex_labels: meshes: surface id per vertex (None for clouds).
        normals_source: clouds: ``"given"`` or ``"estimated"``.
        seconds, timings: compute time in Rust.
    """

    _fields = (
        "labels",
        "types",
        "surfaces",
        "groups",
        "mean_edge",
        "epsilon",
        "seeds",
        "mesh",
        "vertex_labels",
        "normals_source",
        "seconds",
        "timings",
    )


class Curves(_Record):
    """Feature polylines (:func:`lines`, :func:`fillets`, :func:`network`).

    Attributes:
        polylines: list of (m, 3) float64 arrays, one per polyline; a closed loop repeats its
            first point at the end.
        groups: per polyline ``"sharp"``, ``"smooth"`` or ``"boundary"`` (the cloud's open
            border, no feature; the CLI's OBJ groups).
        indices: per polyline, the int64 indices of its points in ``vertices``.
        vertices: (v, 3) float64, every polyline vertex once (the CLI writes these).
        clusters: :func:`lines` only: per input point, its cluster of the first-order
            segmentation (the CLI's ``--segmentation``).
        fillet_label, smooth_edge, patch, region, mean_curvature: :func:`fillets` and
            :func:`network`: the per-point labels of the CLI's ``--labels``.
        summary: the CLI's ``--json`` summary (stages, counts, seconds).
    """

    _fields = (
        "polylines",
        "groups",
        "indices",
        "vertices",
        "clusters",
        "fillet_label",
        "smooth_edge",
        "patch",
        "region",
        "mean_curvature",
        "summary",
    )


class EdgeResult(_Record):
    """Mesh feature edges (:func:`edges`).

    Attributes:
        edges: (e, 2) int64 vertex pairs, the smaller index first, one per undirected edge (the
            CLI's PLY ``edge`` element rows, in its order).
        sharp: (e,) bool.
        sharpness: (e,) float64 (degrees, or the decision value of the learned methods).
        lines: the sharp edges chained into polylines of vertex indices (the CLI's ``--lines``).
        method, flipped_faces, boundary_edges, timings, seconds: as the CLI's ``--json``.
    """

    _fields = (
        "edges",
        "sharp",
        "sharpness",
        "lines",
        "method",
        "flipped_faces",
        "boundary_edges",
        "timings",
        "seconds",
    )


class Reconstruction(_Record):
    """A B-rep (:func:`reconstruct`).

    Attributes:
        step: the STEP (AP214) text, as the CLI writes it.
        solid: True for a closed solid, False for an open shell.
        faces, edges: counts.
        report: the CLI's ``--json`` ``report`` (gaps, distances, what was left out and why).
        topology: the B-rep's faces, edges and vertices (the CLI's ``--topology`` JSON).
        uncertainty: the STEP file's uncertainty.
        seconds: compute time in Rust (writing included).
    """

    _fields = (
        "step",
        "solid",
        "faces",
        "edges",
        "report",
        "topology",
        "uncertainty",
        "seconds",
    )


class RunResult(_Record):
    """The whole job (:func:`run`, the CLI's ``crease run``) from one shared analysis.

    Attributes:
        mesh: True for a mesh (per-edge and per-face results), False for a cloud (per point).
        sharp, sharpness: cloud: per point (``labels.ply``'s ``sharp``, ``sharpness``); mesh: per
            edge of ``edges``.
        edges: mesh: (m, 2) int64 vertex indices of every edge (None for a cloud).
        labels, types: surface id (-1: none) and type code (:data:`SURFACE_TYPES`) per point or
            per face.
        surfaces, surface_groups: the surfaces with their parameters (``surfaces.json``).
        fillet_label, smooth_edge: cloud: the per-point fillet labels (None for a mesh).
        polylines, polyline_groups, polyline_indices, polyline_vertices: the curve network
            (``network.obj``): per polyline an (m, 3) array and its group (``"sharp"``,
            ``"smooth"``, ``"boundary"``).
        step: the B-rep as STEP text (``part.step``), None when none could be built.
        brep: ``solid``, ``faces``, ``edges``, ``report``; or ``error`` saying why there is none.
        noise_ratio, regularized, analysis: cloud: the measured noise, whether the sharp labels
            were regularised, and how often each shared piece was computed (1 each).
        timings, seconds: seconds per stage and in all.
    """

    _fields = (
        "mesh",
        "sharp",
        "sharpness",
        "edges",
        "labels",
        "types",
        "surfaces",
        "surface_groups",
        "fillet_label",
        "smooth_edge",
        "polylines",
        "polyline_groups",
        "polyline_indices",
        "polyline_vertices",
        "step",
        "brep",
        "noise_ratio",
        "regularized",
        "analysis",
        "timings",
        "seconds",
    )


# ---------------------------------------------------------------------------------------------
# Input coercion


def _unpack(obj: Any) -> Tuple[Any, Any, Any]:
    """(points, faces, normals) of an array or a duck-typed geometry object."""
    if isinstance(obj, np.ndarray):
        return obj, None, None
    if isinstance(obj, Geometry):
        return obj.points, obj.faces, obj.normals
    # Open3D TriangleMesh: vertices + triangles.
    if hasattr(obj, "vertices") and hasattr(obj, "triangles"):
        faces = np.asarray(obj.triangles)
        return np.asarray(obj.vertices), (faces if len(faces) else None), None
    # Open3D PointCloud: points (+ normals when it has them).
    if hasattr(obj, "points") and hasattr(obj, "has_normals"):
        nr = np.asarray(obj.normals) if obj.has_normals() else None
        return np.asarray(obj.points), None, nr
    # trimesh Trimesh: vertices + faces.
    if hasattr(obj, "vertices") and hasattr(obj, "faces"):
        faces = np.asarray(obj.faces)
        return np.asarray(obj.vertices), (faces if len(faces) else None), None
    # trimesh PointCloud and the like.
    if hasattr(obj, "vertices"):
        return np.asarray(obj.vertices), None, None
    if hasattr(obj, "points"):
        return np.asarray(obj.points), None, None
    return obj, None, None


def _points(a: Any, name: str = "points") -> np.ndarray:
    """An (n, 3) C-contiguous float64 array, or ValueError."""
    try:
        arr = np.asarray(a)
    except Exception as e:  # ragged lists and the like
        raise ValueError(f"{name}: cannot be read as an (n, 3) array: {e}") from None
    if arr.dtype == object or not (
        np.issubdtype(arr.dtype, np.floating) or np.issubdtype(arr.dtype, np.integer)
    ):
        raise ValueError(f"{name}: expected an (n, 3) array of numbers, got dtype {arr.dtype}")
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ValueError(f"{name}: expected an (n, 3) array, got shape {arr.shape}")
    return np.ascontiguousarray(arr, dtype=np.float64)


def _faces(a: Any) -> Optional[np.ndarray]:
    """An (m, 3) C-contiguous int64 array, None, or ValueError."""
    if a is None:
        return None
    arr = np.asarray(a)
    if arr.size == 0 and arr.ndim != 2:
        arr = arr.reshape(0, 3)
    if not np.issubdtype(arr.dtype, np.integer):
        if arr.size and np.issubdtype(arr.dtype, np.floating) and np.all(arr == np.round(arr)):
            arr = arr.astype(np.int64)
        else:
            raise ValueError(f"faces: expected an (m, 3) array of integers, got dtype {arr.dtype}")
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ValueError(f"faces: expected an (m, 3) array of vertex indices, got shape {arr.shape}")
    if arr.dtype == np.uint64 and arr.size and arr.max() > np.iinfo(np.int64).max:
        raise ValueError("faces: a vertex index does not fit in int64")
    return np.ascontiguousarray(arr, dtype=np.int64)


def _shape(obj: Any, faces: Any = None, normals: Any = None):
    """Points, faces and normals of ``obj``, the explicit arguments taking precedence."""
    p, f, n = _unpack(obj)
    return (
        _points(p),
        _faces(faces if faces is not None else f),
        None if (normals if normals is not None else n) is None
        else _points(normals if normals is not None else n, "normals"),
    )


# ---------------------------------------------------------------------------------------------
# Files


def read(path: PathLike, strict: bool = False) -> Geometry:
    """Reads a point cloud or mesh file, the format chosen by the extension (``crease convert``'s
    reader): PLY, OBJ, OFF, STL, XYZ/TXT/CSV/PTS, PCD, LAS/LAZ, E57.

    Points with NaN or infinite coordinates are dropped and counted in ``report`` (``strict``
    refuses such a file instead, as the CLI's ``--strict``).

    Raises:
        OSError: the file cannot be opened (``FileNotFoundError``, ...).
        FileFormatError: its content is not valid, or the extension is unknown.
    """
    d = _crease.read(os.fspath(path), strict)
    return Geometry(**d)


_KINDS = {
    np.dtype(np.bool_): "uchar",
    np.dtype(np.uint8): "uchar",
    np.dtype(np.int8): "char",
    np.dtype(np.int16): "short",
    np.dtype(np.uint16): "ushort",
    np.dtype(np.int32): "int",
    np.dtype(np.uint32): "uint",
    np.dtype(np.float32): "float",
    np.dtype(np.float64): "double",
}


def _attributes(attrs: Optional[Dict[str, Any]], count: int, what: str) -> List[Tuple[str, str, np.ndarray]]:
    out = []
    for name, values in (attrs or {}).items():
        v = np.asarray(values)
        if v.ndim != 1 or len(v) != count:
            raise ValueError(
                f"{what} attribute {name!r}: expected a 1-D array of {count} values, got shape {v.shape}"
            )
        kind = _KINDS.get(v.dtype)
        if kind is None:
            if np.issubdtype(v.dtype, np.integer):
                lo, hi = (int(v.min()), int(v.max())) if len(v) else (0, 0)
                if lo < np.iinfo(np.int32).min or hi > np.iinfo(np.int32).max:
                    raise ValueError(
                        f"{what} attribute {name!r}: values outside int32 (PLY has no 64-bit integers)"
                    )
                kind = "int"
            elif np.issubdtype(v.dtype, np.floating):
                kind = "double"
            else:
                raise ValueError(f"{what} attribute {name!r}: unsupported dtype {v.dtype}")
        out.append((str(name), kind, np.ascontiguousarray(v, dtype=np.float64)))
    return out


def write(
    path: PathLike,
    points: Any,
    normals: Any = None,
    faces: Any = None,
    attributes: Optional[Dict[str, Any]] = None,
    ascii: bool = False,
    colors: Any = None,
    face_attributes: Optional[Dict[str, Any]] = None,
) -> None:
    """Writes points (a cloud, or a mesh with ``faces``) to a file, the format chosen by the
    extension; the file is replaced atomically (written beside it, then renamed), as the CLI
    does.

    ``points`` may also be a :class:`Geometry` (its normals, colours, faces and attributes are
    written unless given here) or an Open3D / trimesh object. ``attributes`` (per point) and
    ``face_attributes`` map names to 1-D arrays, stored with their dtype's PLY type (bool and
    uint8 as ``uchar``, int32 as ``int``, float32 as ``float``, float64 as ``double``, ...).
    ``colors`` is (n, 3) uint8. ``ascii`` writes text where the format has both.

    Raises:
        ValueError: wrong shapes, NaN coordinates, indices out of range.
        OSError: the file cannot be written; FileFormatError: unknown extension.
    """
    if isinstance(points, Geometry):
        g = points
        normals = g.normals if normals is None else normals
        faces = g.faces if faces is None else faces
        colors = g.colors if colors is None else colors
        attributes = g.attributes if attributes is None else attributes
        face_attributes = g.face_attributes if face_attributes is None else face_attributes
        p, f, n = _points(g.points), _faces(faces), normals
    else:
        p, f, n = _shape(points, faces, normals)
    if n is not None:
        n = _points(n, "normals")
        if len(n) != len(p):
            raise ValueError(f"normals: {len(n)} rows for {len(p)} points")
    c = None
    if colors is not None:
        c = np.asarray(colors)
        if c.ndim != 2 or c.shape[1] != 3 or len(c) != len(p):
            raise ValueError(f"colors: expected an ({len(p)}, 3) array, got shape {c.shape}")
        c = np.ascontiguousarray(c, dtype=np.uint8)
    nf = 0 if f is None else len(f)
    _crease.write(
        os.fspath(path),
        p,
        normals=n,
        colors=c,
        faces=f,
        attributes=_attributes(attributes, len(p), "point"),
        face_attributes=_attributes(face_attributes, nf, "face"),
        ascii=ascii,
    )


# ---------------------------------------------------------------------------------------------
# Computations


def normals(
    points: Any,
    k: int = 20,
    method: str = "pca",
    orient: bool = False,
    faces: Any = None,
    weighting: str = "uniform",
) -> np.ndarray:
    """Normals per point, as ``crease normals``: (n, 3) float64 in the input's order.

    ``method``: ``"pca"`` (weighted PCA over the k nearest neighbours, the default), ``"ring"``
    (least-squares plane of the Delaunay 1-ring), ``"mesh"`` (vertex normals from ``faces``,
    combined with ``weighting``: uniform, area, angle). ``orient`` makes the signs consistent
    (Hoppe: minimum spanning tree over the kNN graph); without it PCA and ring normals have
    arbitrary signs. Normals the input carries are ignored, as the CLI ignores a file's.
    """
    p, f, _ = _shape(points, faces)
    return _crease.normals(p, k=int(k), method=method, orient=bool(orient), faces=f, weighting=weighting)["normals"]


def curvature(
    points: Any,
    k: int = 20,
    method: str = "quadric",
    use_normals: bool = False,
    normals: Any = None,
    faces: Any = None,
    sharp_threshold: Optional[float] = None,
) -> CurvatureResult:
    """Principal curvatures, as ``crease curvature``.

    ``method``: ``"quadric"`` (a quadric fitted in the local PCA frame of the k nearest
    neighbours, the default; exact duplicates fitted once) or ``"bezier"`` (the two-pass Bézier
    fit of Mizoguchi et al. on a mesh's vertices, with sharp vertices above ``sharp_threshold``
    times the mean edge length). ``use_normals``: orient the quadric by the normals (``normals``,
    or the input object's), giving signed curvatures, as ``--use-normals``; without it each
    point's mean curvature is made >= 0.
    """
    p, f, n = _shape(points, faces, normals)
    if use_normals and n is None:
        raise ValueError("use_normals given but the input has no normals")
    d = _crease.curvature(
        p, k=int(k), method=method, normals=n if use_normals else None, faces=f,
        sharp_threshold=sharp_threshold,
    )
    return CurvatureResult(**d)


def sharp(
    points: Any,
    faces: Any = None,
    method: str = "projected-distance",
    scales: Optional[Sequence[int]] = None,
    threshold: Optional[float] = None,
    upper_quantile: Optional[float] = None,
    raw: bool = False,
    regularize: Optional[float] = None,
    surfaces: bool = True,
    points_only: bool = False,
) -> SharpResult:
    """Sharp feature points, as ``crease sharp``: per point ``sharp`` (bool) and ``sharpness``.

    On a cloud (the default): multi-scale projected distance with Otsu thresholds at k = 12, 16,
    ..., 40 (``scales``), then the decisions of the segmentation's analytic surfaces where they
    explain the points (``surfaces=False`` skips that stage, as ``--no-surfaces``). With
    ``faces`` (or a mesh object), the mesh's vertices over 1- to 4-rings, unless
    ``points_only``. ``method``: projected-distance, normal-variation, mean-curvature,
    surface-variation. ``threshold``: a fixed threshold in (0, 1] instead of Otsu's.
    ``regularize``: the Potts weight lambda. ``raw``: the paper's length-valued measures.
    """
    p, f, _ = _shape(points, faces)
    if points_only:
        f = None
    d = _crease.sharp(
        p,
        faces=f,
        method=method,
        scales=None if scales is None else [int(s) for s in scales],
        threshold=threshold,
        upper_quantile=upper_quantile,
        raw=bool(raw),
        regularize=regularize,
        surfaces=bool(surfaces),
    )
    return SharpResult(**d)


def segment(
    points: Any,
    normals: Any = None,
    faces: Any = None,
    distance_tolerance: float = 0.5,
    angle_tolerance: float = 8.0,
    k: int = 8,
    estimate_normals: bool = False,
) -> Segmentation:
    """Planes, cylinders, cones, spheres and tori, as ``crease segment``.

    A cloud (the default) gets a label per point; with ``faces`` (or a mesh object) the mesh is
    segmented and the labels are per face. ``normals`` (or those an Open3D cloud carries) are
    used as a file's normals are; ``None`` or ``estimate_normals`` estimates them (PCA +
    orientation). ``distance_tolerance`` in mean edge lengths, ``angle_tolerance`` in degrees,
    ``k`` the neighbours of the cloud's kNN graph.
    """
    p, f, n = _shape(points, faces, normals)
    if estimate_normals:
        n = None
    d = _crease.segment(
        p,
        normals=n,
        faces=f,
        distance_tolerance=float(distance_tolerance),
        angle_tolerance=float(angle_tolerance),
        k=int(k),
    )
    return Segmentation(**d)


def lines(
    points: Any,
    k: int = 20,
    region_angle: float = 8.0,
    spur_length: int = 5,
    denoise: bool = True,
    close_candidates: Optional[int] = None,
    close_path: Optional[int] = None,
    boundary: bool = True,
    smooth: bool = True,
) -> Curves:
    """Closed sharp feature lines of a cloud, as ``crease lines`` (a mesh's vertices are used as
    points): ``polylines`` (list of (m, 3) arrays), all in group ``"sharp"``."""
    p, _, _ = _shape(points)
    d = _crease.lines(
        p,
        k=int(k),
        region_angle=float(region_angle),
        spur_length=int(spur_length),
        denoise=bool(denoise),
        close_candidates=close_candidates,
        close_path=close_path,
        boundary=bool(boundary),
        smooth=bool(smooth),
    )
    return Curves(**d)


def _fillets(points: Any, network: bool, thresholds: Union[str, int] = "auto", **kw: Any) -> Curves:
    p, _, _ = _shape(points)
    if thresholds == "auto":
        count = None
    else:
        try:
            count = int(thresholds)
        except (TypeError, ValueError):
            raise ValueError(f"thresholds must be 'auto' or a number, got {thresholds!r}") from None
    tau = kw.pop("tau", None)
    d = _crease.fillets(
        p, network, thresholds=count, tau=None if tau is None else [float(t) for t in tau], **kw
    )
    return Curves(**d)


def fillets(
    points: Any,
    k: int = 20,
    region_angle: float = 8.0,
    spur_length: int = 5,
    curvature_k: int = 20,
    smoothing: int = 0,
    median: int = 1,
    trim: float = 0.005,
    bins: int = 50,
    one_run: bool = False,
    thresholds: Union[str, int] = "auto",
    max_thresholds: int = 4,
    tau: Optional[Sequence[float]] = None,
    coarse_retry: bool = False,
    boundary: bool = True,
) -> Curves:
    """Fillet (smooth-edge) lines of a cloud, as ``crease fillets``: ``polylines`` in group
    ``"smooth"``, and the per-point labels of ``--labels`` (``fillet_label``: 0 low, 1 inner,
    2 border, 3 noisy, 255 outside the smooth regions; ``smooth_edge``, ``patch``, ``region``,
    ``mean_curvature``)."""
    return _fillets(
        points, False, thresholds, k=k, region_angle=region_angle, spur_length=spur_length,
        curvature_k=curvature_k, smoothing=smoothing, median=median, trim=trim, bins=bins,
        one_run=one_run, max_thresholds=max_thresholds, tau=tau, coarse_retry=coarse_retry,
        boundary=boundary,
    )


def network(
    points: Any,
    k: int = 20,
    region_angle: float = 8.0,
    spur_length: int = 5,
    curvature_k: int = 20,
    smoothing: int = 0,
    median: int = 1,
    trim: float = 0.005,
    bins: int = 50,
    one_run: bool = False,
    thresholds: Union[str, int] = "auto",
    max_thresholds: int = 4,
    tau: Optional[Sequence[float]] = None,
    coarse_retry: bool = False,
    boundary: bool = True,
    lines_from: str = "surfaces",
) -> Curves:
    """The whole curve network of a cloud, as ``crease network``: sharp and fillet polylines,
    ``groups`` saying which (``"sharp"`` / ``"smooth"`` / ``"boundary"``, the CLI's OBJ
    groups), and the per-point labels of :func:`fillets`. ``lines_from="surfaces"`` (default)
    anchors the lines on the fitted surfaces (the B-rep's edges; Demarsin's lines where no
    surface explains the points), ``"points"`` gives Demarsin's graph lines only."""
    return _fillets(
        points, True, thresholds, k=k, region_angle=region_angle, spur_length=spur_length,
        curvature_k=curvature_k, smoothing=smoothing, median=median, trim=trim, bins=bins,
        one_run=one_run, max_thresholds=max_thresholds, tau=tau, coarse_retry=coarse_retry,
        boundary=boundary, lines_from=lines_from,
    )


def edges(
    vertices: Any,
    faces: Any = None,
    method: str = "fused",
    threshold: Optional[float] = None,
    scales: Optional[Sequence[float]] = None,
    mu: Optional[float] = None,
    model: Optional[PathLike] = None,
    bias: Optional[float] = None,
) -> EdgeResult:
    """Feature edges of a triangle mesh, as ``crease edges``: per undirected edge its vertex
    pair (``edges``), ``sharp`` and ``sharpness``.

    ``method``: fused (default), dihedral, hysteresis, tangent, potts-dihedral, potts-tangent,
    learned, potts-learned, filtered, potts-filtered. ``model``: an SVM model file written by
    ``crease train`` (default: the built-in one).
    """
    p, f, _ = _shape(vertices, faces)
    if f is None:
        raise ValueError("no faces; feature edges need a triangle mesh")
    d = _crease.edges(
        p,
        f,
        method=method,
        threshold=threshold,
        scales=None if scales is None else [float(s) for s in scales],
        mu=mu,
        model=None if model is None else os.fspath(model),
        bias=bias,
    )
    return EdgeResult(**d)


def reconstruct(
    points: Any,
    faces: Any = None,
    out: Optional[PathLike] = None,
    normals: Any = None,
    units: str = "mm",
    name: Optional[str] = None,
    distance_tolerance: float = 0.5,
    angle_tolerance: float = 8.0,
    estimate_normals: bool = False,
    topology: Optional[PathLike] = None,
    mesh: Optional[PathLike] = None,
) -> Reconstruction:
    """The part as a B-rep, as ``crease reconstruct``: a solid (or an open shell saying what it
    leaves out) in STEP (AP214).

    With ``faces`` (or a mesh object) from the mesh; else from the cloud (its ``normals`` if
    given, else estimated). ``out``: the .step / .stp file to write (atomically); the text is in
    the result's ``step`` either way. ``name``: the product name in the file (default: ``out``'s
    stem, as the CLI takes the input's; ``"part"`` without ``out``). ``topology`` / ``mesh``: also
    write the B-rep as JSON / as a triangle mesh, as ``--topology`` / ``--mesh``.
    """
    p, f, n = _shape(points, faces, normals)
    if estimate_normals:
        n = None
    if name is None:
        name = os.path.splitext(os.path.basename(os.fspath(out)))[0] if out is not None else "part"
    d = _crease.reconstruct(
        p,
        faces=f,
        normals=n,
        out=None if out is None else os.fspath(out),
        name=name,
        units=units,
        distance_tolerance=float(distance_tolerance),
        angle_tolerance=float(angle_tolerance),
        topology=None if topology is None else os.fspath(topology),
        mesh=None if mesh is None else os.fspath(mesh),
    )
    d["topology"] = json.loads(d["topology"])
    return Reconstruction(**d)


def run(points: Any, faces: Any = None, name: str = "part", units: str = "mm") -> RunResult:
    """The whole job, as ``crease run``, from one shared analysis: a cloud's sharp points, curve
    network (sharp, fillet and open-border lines), analytic surfaces and B-rep; a mesh's
    feature edges, their polylines, its surfaces and its B-rep (with ``faces`` or a mesh
    object). ``name`` and ``units``: the STEP file's product name and length unit. Bit for bit
    the values of the files ``crease run`` writes."""
    p, f, _ = _shape(points, faces)
    d = _crease.run(p, faces=f, name=str(name), units=str(units))
    for key in ("edges", "fillet_label", "smooth_edge", "noise_ratio", "regularized", "analysis"):
        d.setdefault(key, None)
    return RunResult(**d)


def command(args: Sequence[str]) -> None:
    """Runs one ``crease`` command line in this process (the CLI's own code; ``args`` without
    the program name), e.g. ``crease.command(["sharp", "scan.ply", "-o", "out.ply"])``.
    Prints what the CLI prints; raises :class:`CommandError` (with the CLI's ``code`` and
    ``message``) when it fails."""
    _crease.command([os.fspath(a) for a in args], True)


def set_num_threads(n: int) -> None:
    """Sets the number of worker threads of every later computation (the CLI's ``--threads``);
    only before the first one. Default: one per core."""
    _crease.set_num_threads(int(n))
