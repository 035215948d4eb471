"""Type stub of the native module crease._crease (src/lib.rs). Use the functions of the `crease`
package, which accept Open3D / trimesh objects and wrap these dicts in result classes."""

from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

__version__: str

def read(path: str, strict: bool = ...) -> Dict[str, Any]: ...
def write(
    path: str,
    points: npt.NDArray[np.float64],
    normals: Optional[npt.NDArray[np.float64]] = ...,
    colors: Optional[npt.NDArray[np.uint8]] = ...,
    faces: Optional[npt.NDArray[np.int64]] = ...,
    attributes: Sequence[Tuple[str, str, npt.NDArray[np.float64]]] = ...,
    face_attributes: Sequence[Tuple[str, str, npt.NDArray[np.float64]]] = ...,
    ascii: bool = ...,
) -> None: ...
def normals(
    points: npt.NDArray[np.float64],
    k: int = ...,
    method: str = ...,
    orient: bool = ...,
    faces: Optional[npt.NDArray[np.int64]] = ...,
    weighting: str = ...,
) -> Dict[str, Any]: ...
def curvature(
    points: npt.NDArray[np.float64],
    k: int = ...,
    method: str = ...,
    normals: Optional[npt.NDArray[np.float64]] = ...,
    faces: Optional[npt.NDArray[np.int64]] = ...,
    sharp_threshold: Optional[float] = ...,
) -> Dict[str, Any]: ...
def sharp(
    points: npt.NDArray[np.float64],
    faces: Optional[npt.NDArray[np.int64]] = ...,
    method: str = ...,
    scales: Optional[List[int]] = ...,
    threshold: Optional[float] = ...,
    upper_quantile: Optional[float] = ...,
    raw: bool = ...,
    regularize: Optional[float] = ...,
    surfaces: bool = ...,
) -> Dict[str, Any]: ...
def segment(
    points: npt.NDArray[np.float64],
    normals: Optional[npt.NDArray[np.float64]] = ...,
    faces: Optional[npt.NDArray[np.int64]] = ...,
    distance_tolerance: float = ...,
    angle_tolerance: float = ...,
    k: int = ...,
) -> Dict[str, Any]: ...
def lines(
    points: npt.NDArray[np.float64],
    k: int = ...,
    region_angle: float = ...,
    spur_length: int = ...,
    denoise: bool = ...,
    close_candidates: Optional[int] = ...,
    close_path: Optional[int] = ...,
    boundary: bool = ...,
    smooth: bool = ...,
) -> Dict[str, Any]: ...
def fillets(
    points: npt.NDArray[np.float64],
    network: bool,
    k: int = ...,
    region_angle: float = ...,
    spur_length: int = ...,
    curvature_k: int = ...,
    smoothing: int = ...,
    median: int = ...,
    trim: float = ...,
    bins: int = ...,
    one_run: bool = ...,
    thresholds: Optional[int] = ...,
    max_thresholds: int = ...,
    tau: Optional[List[float]] = ...,
    coarse_retry: bool = ...,
    boundary: bool = ...,
    lines_from: str = ...,
) -> Dict[str, Any]: ...
def edges(
    vertices: npt.NDArray[np.float64],
    faces: npt.NDArray[np.int64],
    method: str = ...,
    threshold: Optional[float] = ...,
    scales: Optional[List[float]] = ...,
    mu: Optional[float] = ...,
    model: Optional[str] = ...,
    bias: Optional[float] = ...,
) -> Dict[str, Any]: ...
def reconstruct(
    points: npt.NDArray[np.float64],
    faces: Optional[npt.NDArray[np.int64]] = ...,
    normals: Optional[npt.NDArray[np.float64]] = ...,
    out: Optional[str] = ...,
    name: str = ...,
    units: str = ...,
    distance_tolerance: float = ...,
    angle_tolerance: float = ...,
    topology: Optional[str] = ...,
    mesh: Optional[str] = ...,
) -> Dict[str, Any]: ...
def set_num_threads(n: int) -> None: ...
def run(
    points: npt.NDArray[np.float64],
    faces: Optional[npt.NDArray[np.int64]] = ...,
    name: str = ...,
    units: str = ...,
) -> Dict[str, Any]: ...
def command(args: Sequence[str], check: bool = ...) -> int: ...
def split_tiles(path: str, dir: str, size: float, halo: float) -> Dict[str, Any]: ...
def sample_spacing(path: str, limit: int = ...) -> float: ...
def halo_width(spacing: float, surfaces: bool) -> float: ...
def tile_noise(tile: str, total: int) -> npt.NDArray[np.float64]: ...
def noise_ratio_of(samples: npt.NDArray[np.float64]) -> float: ...
def tile_measures(tile: str, cache: str, ratio: float, surfaces: bool) -> List[Tuple[float, float]]: ...
def tile_histograms(
    tile: str, cache: str, ranges: Sequence[Tuple[float, float]], surfaces: bool
) -> List[List[int]]: ...
def sharp_thresholds(
    histograms: Sequence[Sequence[int]], ranges: Sequence[Tuple[float, float]], surfaces: bool
) -> List[Tuple[float, float]]: ...
def tile_labels(
    tile: str,
    cache: str,
    thresholds: Sequence[Tuple[float, float]],
    ratio: float,
    surfaces: bool,
    out: str,
) -> Dict[str, Any]: ...
