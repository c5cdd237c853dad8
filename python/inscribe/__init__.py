"""inscribe: unions of spheres approximating closed triangle meshes.

In-process (the C++ core, bound with pybind11): load_mesh, write_mesh, Mesh, Repair, prepare,
generate, evaluate,
certify, read_spheres, write_spheres, write_mesh, Hierarchy, distance, certified_distance, Scene,
Deformer, spherize_robot (URDF or MJCF), spherize_urdf. Over the service (grpcio): Client, DistanceSession.

Units and frames: every length is in the mesh's own units, every point in the mesh's own frame
unless a docstring says "world frame"; poses are rows [qw, qx, qy, qz, tx, ty, tz] (unit
quaternion, then translation), mapping body coordinates to world ones.

Meshes are taken as an inscribe.Mesh, a path (str or os.PathLike), a (vertices, faces) pair of
arrays or an object with .vertices and .faces (a trimesh.Trimesh); vertices of any float dtype
and faces of any integer dtype are converted once (Mesh's docstring). inscribe.Client and its
result types need grpcio, imported when first used.
"""

from . import _inscribe, _keywords
from ._errors import Error
from ._version import __version__

# pybind11's refusal of a mistyped keyword lists every signature: name the keyword instead.
_keywords.name_unknown_keywords(_inscribe)

from ._inscribe import (  # noqa: E402 (after the keyword errors are in place)
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

# The service client's names, from inscribe._client on first use: it needs grpcio, which
# `import inscribe` does not.
_CLIENT_NAMES = ("Client", "DeformationResult", "DistanceReply", "DistanceSession",
                 "GenerateResult", "InspectMeshResult", "RetryPolicy")


def __getattr__(name):
    if name not in _CLIENT_NAMES:
        raise AttributeError(f"module 'inscribe' has no attribute {name!r}")
    try:
        from . import _client
    except ModuleNotFoundError as error:
        if error.name != "grpc":
            raise
        raise ImportError(f"inscribe.{name} needs grpcio, which is not installed: "
                          "pip install grpcio (or inscribe[client]; Debian: python3-grpcio)",
                          name="grpc") from None
    return getattr(_client, name)


__all__ = [
    "DEFAULT_MAX_SPHERES_PER_LINK", "CertifiedDistances", "CertifiedObject", "Client",
    "DeformationResult", "DistanceReply", "GenerateResult", "InspectMeshResult",
    "CoverCertificate", "DeformationErrorBounds", "Deformer", "DistanceBatch", "DistanceResult",
    "DistanceSession", "Error", "Hierarchy", "LinkSpheres", "Mesh", "MeshIssue", "MeshReport",
    "MeshWarning",
    "QualityReport", "Repair", "RetryPolicy", "Scene", "SceneFrame", "Severity", "Solid", "SphereSet", "SpherizedRobot",
    "certified_distance", "certify", "distance", "evaluate", "format_curobo_yaml", "generate",
    "load_mesh", "parse_curobo_yaml", "prepare", "read_robot_sphere_file", "read_robot_spheres", "read_spheres", "spherize_robot", "spherize_urdf",
    "write_mesh", "write_robot_spheres", "write_spheres", "__version__",
]
