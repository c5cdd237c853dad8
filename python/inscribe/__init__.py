"""inscribe: unions of spheres approximating closed triangle meshes.

In-process (the C++ core, bound with pybind11): load_mesh, write_mesh, Mesh, Repair, prepare,
generate, evaluate,
certify, read_spheres, write_spheres, write_mesh, Hierarchy, distance, certified_distance, Scene,
Deformer, spherize_robot (URDF or MJCF), spherize_urdf. Over the service (grpcio): Client, DistanceSession.

Units and frames: every length is in the mesh's own units, every point in the mesh's own frame
unless a docstring says "world frame"; poses are rows [qw, qx, qy, qz, tx, ty, tz] (unit
quaternion, then translation), mapping body coordinates to world ones.
"""

from ._errors import Error
from ._inscribe import (
    DEFAULT_MAX_SPHERES_PER_LINK,
    CertifiedDistances,
    CertifiedObject,
    CoverCertificate,
    DeformationErrorBounds,
    Deformer,
    DistanceBatch,
    DistanceResult,
    Hierarchy,
    LinkSpheres,
    Mesh,
    MeshIssue,
    MeshReport,
    MeshWarning,
    QualityReport,
    Repair,
    Scene,
    SceneFrame,
    Severity,
    Solid,
    SphereSet,
    SpherizedRobot,
    certified_distance,
    certify,
    distance,
    evaluate,
    format_curobo_yaml,
    generate,
    load_mesh,
    parse_curobo_yaml,
    prepare,
    read_robot_sphere_file,
    read_robot_spheres,
    read_spheres,
    spherize_robot,
    spherize_urdf,
    write_mesh,
    write_robot_spheres,
    write_spheres,
)
from ._client import (
    Client,
    DeformationResult,
    DistanceReply,
    DistanceSession,
    GenerateResult,
    InspectMeshResult,
    RetryPolicy,
)

__all__ = [
    "DEFAULT_MAX_SPHERES_PER_LINK", "CertifiedDistances", "CertifiedObject", "Client",
    "DeformationResult", "DistanceReply", "GenerateResult", "InspectMeshResult",
    "CoverCertificate", "DeformationErrorBounds", "Deformer", "DistanceBatch", "DistanceResult",
    "DistanceSession", "Error", "Hierarchy", "LinkSpheres", "Mesh", "MeshIssue", "MeshReport",
    "MeshWarning",
    "QualityReport", "Repair", "RetryPolicy", "Scene", "SceneFrame", "Severity", "Solid", "SphereSet", "SpherizedRobot",
    "certified_distance", "certify", "distance", "evaluate", "format_curobo_yaml", "generate",
    "load_mesh", "parse_curobo_yaml", "prepare", "read_robot_sphere_file", "read_robot_spheres", "read_spheres", "spherize_robot", "spherize_urdf",
    "write_mesh", "write_robot_spheres", "write_spheres",
]
