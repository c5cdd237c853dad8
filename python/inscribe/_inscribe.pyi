# Type stubs of the _inscribe extension (python/src/*.cpp), for editors and type checkers.
# Shapes: (N, 4) float64 [x, y, z, r]; poses (7,) or (N, 7) float64 [qw, qx, qy, qz, tx, ty, tz].
import os
from typing import Any, Callable, Iterator, Mapping, Optional, Protocol, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

Float64Array = npt.NDArray[np.float64]
Int32Array = npt.NDArray[np.int32]
class ProgressBar(Protocol):  # tqdm.tqdm: advanced to fraction * total
    total: Optional[float]
    def update(self, n: float) -> Any: ...

Progress = Union[None, Callable[[float], None], ProgressBar]
PathLike = Union[str, os.PathLike]
Spheres = Union["SphereSet", Float64Array]

DEFAULT_MAX_SPHERES_PER_LINK: int

class Severity:
    ERROR: Severity
    WARNING: Severity
    FIXED: Severity

class MeshIssue:
    severity: Severity
    code: str
    message: str
    count: int

class MeshReport:
    vertices: int
    triangles: int
    non_finite_vertices: int
    out_of_range_indices: int
    degenerate_triangles: int
    duplicate_triangles: int
    unreferenced_vertices: int
    border_edges: int
    non_manifold_edges: int
    non_manifold_vertices: int
    inconsistent_edges: int
    components: int
    flipped_triangles: int
    flat_shells: int
    self_intersections_checked: bool
    self_intersecting_pairs: int
    welded_vertices: int
    weld_collapsed_triangles: int
    weld_moved_within: float
    holes_filled: int
    hole_triangles_added: int
    duplicate_triangles_removed: int
    double_walls_removed: int
    crack_weld_tolerance: float
    crack_vertices_welded: int
    wrapped: bool
    wrap_alpha: float
    wrap_offset: float
    wrap_input_triangles: int
    wrap_triangles: int
    wrap_reach: float
    volume: float
    bbox_min: Float64Array
    bbox_max: Float64Array
    issues: list[MeshIssue]
    closed: bool
    usable: bool
    geometry_repaired: bool
    repairs: str
    first_error: str

class MeshWarning(UserWarning): ...

class Repair:
    def __init__(self, level: str = "safe", *, weld_tolerance: float = 0.0,
                 wrap_alpha: float = 0.0, wrap_offset: float = 0.0) -> None: ...
    @property
    def level(self) -> str: ...
    weld_tolerance: float
    wrap_alpha: float
    wrap_offset: float

RepairLike = Union[Repair, str]

class HasVerticesAndFaces(Protocol):  # trimesh.Trimesh
    @property
    def vertices(self) -> npt.ArrayLike: ...
    @property
    def faces(self) -> npt.ArrayLike: ...

class Mesh:
    # vertices: any float dtype, triangles: any integer dtype; converted once to float64, int32.
    def __init__(self, vertices: npt.ArrayLike, triangles: npt.ArrayLike) -> None: ...
    @property
    def vertices(self) -> Float64Array: ...
    @property
    def triangles(self) -> Int32Array: ...
    @property
    def faces(self) -> Int32Array: ...
    @property
    def num_vertices(self) -> int: ...
    @property
    def num_triangles(self) -> int: ...
    @property
    def sha256(self) -> str: ...
    def validate(self, *, check_self_intersections: bool = True, repair: RepairLike = "safe",
                 fill_holes: bool = False, weld_tolerance: float = 0.0) -> MeshReport: ...
    def repaired(self, repair: RepairLike = "safe", *,
                 check_self_intersections: bool = True) -> Tuple[Mesh, MeshReport]: ...

class Solid:
    @property
    def report(self) -> MeshReport: ...
    @property
    def sha256(self) -> str: ...
    @property
    def mesh(self) -> Mesh: ...

# Every argument taking a mesh takes these.
MeshLike = Union[Mesh, PathLike, Tuple[npt.ArrayLike, npt.ArrayLike], HasVerticesAndFaces]
MeshOrSolid = Union[MeshLike, Solid]

def load_mesh(path: PathLike) -> Mesh: ...
def write_mesh(mesh: MeshLike, path: PathLike) -> None: ...
def prepare(mesh: MeshLike, *, repair: RepairLike = "safe", fill_holes: bool = False,
            check_self_intersections: bool = True) -> Solid: ...

class QualityReport:
    spheres: int
    volume_mesh: float
    volume_union: float
    nerr: float
    nerr_is_exact: bool
    protrusion_max: float
    protrusion_mean: float
    protrusion_p95: float
    protruding_spheres: int
    protrusion_tolerance: float
    bbox_diagonal: float
    surface_samples: int
    coverage: float
    coverage_tolerance: float
    boundary_to_union_mean: float
    boundary_to_union_hausdorff: float
    radius_min: float
    radius_max: float
    fat_up_to_voxel_size: float
    voxel_size: float
    fat: bool
    fraction_radius_over_sqrt3_sigma: float
    seconds: float

class CoverCertificate:
    certified: bool
    mesh_sha256: str
    spheres_sha256: str
    delta: float
    resolution: float
    cells: int
    cells_in_sphere: int
    cells_outside: int
    failed_cells: int
    uncovered_point: Optional[Float64Array]
    uncovered_depth: float
    uncovered_gap: float
    seconds: float
    @property
    def protrusions(self) -> Float64Array: ...

class SphereSet:
    def __init__(self, spheres: Float64Array, contact_triangles: Optional[Int32Array] = None,
                 contact_barycentrics: Optional[Float64Array] = None, *, kind: str = "",
                 mesh_sha256: str = "") -> None: ...
    @property
    def spheres(self) -> Float64Array: ...
    @property
    def centers(self) -> Float64Array: ...
    @property
    def radii(self) -> Float64Array: ...
    @property
    def contact_triangles(self) -> Optional[Int32Array]: ...
    @property
    def contact_barycentrics(self) -> Optional[Float64Array]: ...
    @property
    def kind(self) -> str: ...
    mesh_sha256: str
    params: dict[str, Union[bool, int, float, str]]
    stats: dict[str, Union[bool, int, float, str]]
    @property
    def quality(self) -> Optional[QualityReport]: ...
    @property
    def certificate(self) -> Optional[CoverCertificate]: ...
    @property
    def reference_index(self) -> Optional[Int32Array]: ...
    def __len__(self) -> int: ...
    def __array__(self, dtype: Optional[npt.DTypeLike] = None,
                  copy: Optional[bool] = None) -> Float64Array: ...
    @property
    def shape(self) -> Tuple[int, int]: ...
    def __getitem__(self, index: Any) -> Any: ...
    def __iter__(self) -> Iterator[Float64Array]: ...
    def to_mesh(self, subdivision: int = 1) -> Mesh: ...

def generate(mesh: MeshOrSolid, *, max_spheres: Optional[int] = None,
             voxel_size: Optional[float] = None, kind: str = "internal",
             object_angle: Optional[float] = None, epsilon: Optional[float] = None,
             samples: Optional[int] = None, subdivide_boundary: Optional[bool] = None,
             max_voxels: Optional[int] = None, dilation_growth: Optional[float] = None,
             max_protrusion: Optional[float] = None, cover_resolution: Optional[float] = None,
             evaluate: bool = True, quality_samples: Optional[int] = None,
             selection: Optional[str] = None, progress: Progress = None) -> SphereSet: ...
def evaluate(mesh: MeshOrSolid, spheres: Spheres, *,
             surface_samples: Optional[int] = None, voxel_size: Optional[float] = None,
             coverage_tolerance: Optional[float] = None,
             seed: Optional[int] = None) -> QualityReport: ...
def certify(mesh: MeshOrSolid, spheres: Spheres, *, resolution: Optional[float] = None,
            stop_at_witness: Optional[bool] = None,
            progress: Progress = None) -> CoverCertificate: ...
def read_spheres(path: PathLike, *, format: Optional[str] = None, sph_level: int = -1,
                 yaml_link: str = "") -> SphereSet: ...
def write_spheres(sphere_set: SphereSet, path: PathLike, *, format: Optional[str] = None,
                  csv_header: bool = True, obj_subdivision: int = 1,
                  yaml_link_name: str = "mesh") -> None: ...
def format_curobo_yaml(links: Sequence[Tuple[str, Spheres]],
                       comment: str = "inscribe spheres") -> str: ...
def parse_curobo_yaml(text: str) -> dict[str, SphereSet]: ...

class Hierarchy:
    def __init__(self, spheres: Spheres, volume: str = "sphere") -> None: ...
    @property
    def volume(self) -> str: ...
    @property
    def depth(self) -> int: ...
    @property
    def num_nodes(self) -> int: ...
    def __len__(self) -> int: ...
    def serialize(self) -> bytes: ...
    @staticmethod
    def deserialize(data: bytes) -> Hierarchy: ...

class DistanceResult:
    distance: float
    sphere_a: int
    sphere_b: int
    point_a: Float64Array
    point_b: Float64Array
    closer: bool

class DistanceBatch:
    @property
    def distance(self) -> Float64Array: ...
    @property
    def sphere_a(self) -> Int32Array: ...
    @property
    def sphere_b(self) -> Int32Array: ...
    @property
    def point_a(self) -> Float64Array: ...
    @property
    def point_b(self) -> Float64Array: ...
    @property
    def closer(self) -> npt.NDArray[np.bool_]: ...
    def __len__(self) -> int: ...

def distance(a: Union[Hierarchy, Spheres], b: Union[Hierarchy, Spheres], poses: Float64Array,
             *, pose_a: Optional[Float64Array] = None, abs_err: Optional[float] = None,
             rel_err: Optional[float] = None, closer_than: Optional[float] = None,
             progress: Progress = None) -> Union[DistanceResult, DistanceBatch]: ...

class CertifiedObject:
    def __init__(self, internal: Union[Hierarchy, Spheres], cover: Union[Hierarchy, Spheres],
                 delta: Optional[float] = None,
                 protrusions: Optional[Sequence[float]] = None) -> None: ...

class CertifiedDistances:
    @property
    def lower(self) -> Float64Array: ...
    @property
    def upper(self) -> Float64Array: ...
    closer: list[str]
    def __len__(self) -> int: ...

def certified_distance(a: CertifiedObject, b: CertifiedObject, poses: Float64Array, *,
                       pose_a: Optional[Float64Array] = None,
                       closer_than: Optional[float] = None) -> CertifiedDistances: ...

class SceneFrame:
    @property
    def a(self) -> npt.NDArray[np.uint64]: ...
    @property
    def b(self) -> npt.NDArray[np.uint64]: ...
    @property
    def distance(self) -> Float64Array: ...
    @property
    def sphere_a(self) -> Int32Array: ...
    @property
    def sphere_b(self) -> Int32Array: ...
    @property
    def point_a(self) -> Float64Array: ...
    @property
    def point_b(self) -> Float64Array: ...
    @property
    def certified(self) -> npt.NDArray[np.bool_]: ...
    @property
    def lower(self) -> Float64Array: ...
    @property
    def upper(self) -> Float64Array: ...
    @property
    def candidate_pairs(self) -> int: ...
    @property
    def close_pairs(self) -> int: ...
    @property
    def truncated(self) -> bool: ...
    def __len__(self) -> int: ...

class Scene:
    def __init__(self) -> None: ...
    def add(self, id: int, spheres: Union[Hierarchy, Spheres],
            pose: Optional[Float64Array] = None, *, certified: Optional[CertifiedObject] = None,
            group: int = 1, mask: int = 0xFFFFFFFF) -> None: ...
    def remove(self, id: int) -> None: ...
    def set_poses(self, ids: Sequence[int], poses: Float64Array) -> None: ...
    def ignore(self, a: int, b: int) -> None: ...
    def __len__(self) -> int: ...
    def __contains__(self, id: int) -> bool: ...
    def close_pairs(self, threshold: float = 0.0, *, abs_err: float = 0.0, rel_err: float = 0.0,
                    max_pairs: int = 100000, stop_at_first: bool = False,
                    progress: Progress = None) -> SceneFrame: ...

class DeformationErrorBounds:
    volume_mesh: float
    volume_union: float
    nerr_lower: float
    nerr_upper: float
    nerr_upper_uniform_xi: float
    uniform_xi_holds: bool
    exact: bool
    seconds: float

class Deformer:
    def __init__(self, reference: MeshOrSolid, spheres: SphereSet, *,
                 xi: Optional[float] = None, strict: bool = False,
                 interpolated_normal: bool = False) -> None: ...
    @property
    def xi(self) -> float: ...
    def update(self, vertices: Float64Array) -> SphereSet: ...
    def bounds(self, spheres: Spheres) -> DeformationErrorBounds: ...

class LinkSpheres:
    link: str
    @property
    def status(self) -> str: ...
    from_visual: bool
    elements: int
    @property
    def spheres(self) -> Float64Array: ...
    @property
    def kind(self) -> str: ...
    delta: Optional[float]
    @property
    def certified(self) -> bool: ...
    @property
    def cores(self) -> Float64Array: ...
    budget: int
    error: str
    warnings: list[str]
    seconds: float

class SelfCollision:
    @property
    def samples(self) -> int: ...
    @property
    def seed(self) -> int: ...
    @property
    def certified(self) -> bool: ...
    @property
    def seconds(self) -> float: ...
    @property
    def pairs(self) -> list[dict]: ...
    def srdf(self) -> str: ...

class SpherizedRobot:
    name: str
    format: str  # "urdf" or "mjcf"
    links: list[LinkSpheres]
    spheres: dict[str, Float64Array]  # spherized link or body -> (N, 4) [x, y, z, r]
    warnings: list[str]
    def urdf(self, directory: Optional[str] = None) -> str: ...
    def mjcf(self, directory: str) -> str: ...
    def self_collision(self, *, samples: int = 10000, seed: int = 0,
                       always_fraction: float = 0.95,
                       progress: Optional[Callable[[float], object]] = None) -> SelfCollision: ...
    def curobo_yaml(self, self_collision: Optional[SelfCollision] = None) -> str: ...
    # format: "curobo", "xrdf", "srdf", "urdf" (VAMP), "morphit"; default: path's extension.
    def write(self, path: PathLike, *, format: Optional[str] = None,
              self_collision: Optional[SelfCollision] = None) -> None: ...

# Robot sphere files in every planner format (robot_spheres.h): link -> (N, 4) [x, y, z, r].
def read_robot_spheres(path: PathLike, *, format: Optional[str] = None) -> dict[str, Float64Array]: ...
# {"format", "robot_name", "spheres", "self_collision_ignore": [(a, b, reason)],
#  "self_collision_buffer": {link: m}, "collision_buffer": {link: m}}
def read_robot_sphere_file(path: PathLike, *, format: Optional[str] = None) -> dict: ...
def write_robot_spheres(path: PathLike, spheres: Mapping[str, Float64Array], *,
                        format: Optional[str] = None, robot: str = "", robot_name: str = "",
                        self_collision_ignore: Sequence[tuple[str, str, str]] = (),
                        self_collision_buffer: Mapping[str, float] = ...,
                        collision_buffer: Mapping[str, float] = ...) -> None: ...

def spherize_robot(path: PathLike, *, kind: str = "cover", max_spheres: Optional[int] = None,
                   max_spheres_per_link: Optional[int] = None,
                   max_protrusion: Optional[float] = None,
                   voxel_size: Optional[float] = None,
                   link_max_spheres: Mapping[str, int] = ...,
                   padding: float = 0.0,
                   clip_planes: Sequence[tuple[str, tuple[float, float, float], float]] = (),
                   package_paths: Sequence[str] = (),
                   solid_classes: Sequence[str] = (),
                   solid_groups: Sequence[int] = (),
                   repair: RepairLike = "safe",
                   link_repair: Mapping[str, RepairLike] = ...,
                   progress: Optional[Callable[[float], object]] = None) -> SpherizedRobot: ...

def spherize_urdf(path: PathLike, *, kind: str = "cover", max_spheres: Optional[int] = None,
                  max_spheres_per_link: Optional[int] = None,
                  max_protrusion: Optional[float] = None,
                  voxel_size: Optional[float] = None,
                  link_max_spheres: Mapping[str, int] = ...,
                  padding: float = 0.0,
                  clip_planes: Sequence[tuple[str, tuple[float, float, float], float]] = (),
                  package_paths: Sequence[str] = (),
                  repair: RepairLike = "safe",
                  link_repair: Mapping[str, RepairLike] = ...,
                  progress: Optional[Callable[[float], object]] = None) -> SpherizedRobot: ...

def _route_key(key: str) -> str: ...
def _rendezvous_order(route_key: str, names: Sequence[str]) -> list[int]: ...
def _target_with_default_port(target: str) -> str: ...

# inscribe.Client's messages (client_requests.cpp, client_replies.cpp): requests built and
# answers read with wire/'s conversions; the client carries the bytes.
def _rpc_methods() -> list[Tuple[str, str, bool, bool]]: ...
def _inspect_mesh_request(mesh: Mesh, *, skip_self_intersections: bool,
                          repair: RepairLike) -> bytes: ...
def _put_mesh_request(mesh: Mesh, *, repair: RepairLike) -> bytes: ...
def _mesh_of(mesh: MeshLike) -> Mesh: ...
def _repair_argument(repair: RepairLike, *, fill_holes: bool,
                     weld_tolerance: float) -> Repair: ...

class _GenerateCall:
    def __init__(self, *, max_spheres: Optional[int], voxel_size: Optional[float], kind: str,
                 object_angle: Optional[float], epsilon: Optional[float],
                 samples: Optional[int], subdivide_boundary: Optional[bool],
                 max_voxels: Optional[int], dilation_growth: Optional[float],
                 max_protrusion: Optional[float], cover_resolution: Optional[float],
                 evaluate: bool, quality_samples: Optional[int], selection: Optional[str],
                 repair: RepairLike, progress_interval: float) -> None: ...
    def request(self, mesh_sha256: str) -> bytes: ...
    def read(self, message: bytes) -> Tuple[Optional[float], Optional[dict]]: ...

def _put_sphere_set_request(spheres: Spheres, *, mesh_sha256: str = "",
                            certificate: Optional[CoverCertificate] = None) -> Tuple[bytes, str]: ...
def _get_sphere_set_request(sphere_set_key: str) -> bytes: ...
def _get_hierarchy_request(sphere_set_key: str, *, volume: str) -> bytes: ...
def _update_deformation_request(sphere_set_key: str, vertices: Float64Array, *, mesh_sha256: str,
                                xi: Optional[float], strict: bool, interpolated_normal: bool,
                                bounds: bool, store: bool) -> bytes: ...
def _distance_request(sphere_set_a: str, sphere_set_b: str, poses_b: Float64Array, *,
                      poses_a: Optional[Float64Array], volume: str, abs_err: float,
                      rel_err: float, closer_than: Optional[float], brute_force: bool,
                      cover_a: str, cover_b: str) -> bytes: ...

class _DistanceFrames:
    def __init__(self, volume: str, abs_err: float, rel_err: float) -> None: ...
    def frame(self, number: int, pairs: Sequence[tuple]) -> Tuple[bytes, bool]: ...

def _evaluate_request(mesh_sha256: str, sphere_set_key: str) -> bytes: ...
def _certify_cover_request(mesh_sha256: str, spheres: Union[str, Spheres], *,
                           resolution: Optional[float]) -> bytes: ...
def _cache_stats_request() -> bytes: ...
def _inspect_mesh_reply(data: bytes) -> dict: ...
def _put_mesh_reply(data: bytes) -> str: ...
def _put_sphere_set_reply(data: bytes) -> str: ...
def _sphere_set_reply(data: bytes) -> SphereSet: ...
def _hierarchy_reply(data: bytes, *, volume: str) -> Hierarchy: ...
def _update_deformation_reply(data: bytes, *, bounds: bool) -> dict: ...
def _distance_reply(data: bytes, *, certified: bool) -> dict: ...
def _distance_frame_reply(data: bytes, *, certified: bool) -> Tuple[int, dict]: ...
def _evaluate_reply(data: bytes) -> QualityReport: ...
def _certify_cover_reply(data: bytes) -> CoverCertificate: ...
def _cache_stats_reply(data: bytes) -> dict[str, int]: ...
