"""inscribe.Client: the inscribed service over gRPC (grpcio and the stubs generated from proto/).

It behaves as the C++ client (client/include/inscribe/client/client.h, routing.h): each call
goes to the replica that owns its mesh (rendezvous hashing on the mesh hash, computed by the
same C++ function, wire::RendezvousOrder, bound in _inscribe); an UNAVAILABLE replica is marked
down for `down_for` seconds and the next attempt goes to the next replica at once; idempotent
calls (all unary ones) are retried on UNAVAILABLE with exponential, jittered backoff within
the call's deadline; TLS, mutual TLS and bearer tokens as inscribed's flags expect them.
"""

from __future__ import annotations

import dataclasses
import queue
import random
import threading
import time
from typing import Callable, Optional, Sequence

import grpc
import numpy as np

from . import _inscribe
from ._errors import Error
from .v1 import mesh_pb2, service_pb2, service_pb2_grpc, spheres_pb2


@dataclasses.dataclass(frozen=True)
class RetryPolicy:
    """Retries of idempotent calls, as the C++ client's RetryPolicy: at most `max_attempts`
    RPCs per call (the first included; give at least the number of replicas to let a call
    reach every one); waits of initial_backoff * multiplier**(n-1) seconds, capped at
    max_backoff, each drawn from [50%, 100%] of that. Only UNAVAILABLE is retried."""

    max_attempts: int = 3
    initial_backoff: float = 0.1
    max_backoff: float = 2.0
    multiplier: float = 2.0

    def backoff(self, attempt: int) -> float:
        wait = min(self.initial_backoff * self.multiplier ** (attempt - 1), self.max_backoff)
        return wait * random.uniform(0.5, 1.0)


def _raise_rpc_error(error: grpc.RpcError, note: str = "") -> None:
    code = error.code()
    message = (error.details() or "") + note
    if code == grpc.StatusCode.INVALID_ARGUMENT:
        raise ValueError(message) from None
    raise Error(message, code.name) from None


def _pose_array(poses, name: str) -> spheres_pb2.PoseArray:
    array = np.asarray(poses, dtype=np.float64) if not isinstance(poses, np.ndarray) else poses
    if array.dtype != np.float64:
        raise TypeError(f"{name} must be a float64 array, got {array.dtype}")
    if array.ndim == 1:
        array = array.reshape(1, -1)
    if array.ndim != 2 or array.shape[1] != 7:
        raise ValueError(f"{name} must have shape (7,) or (N, 7), got {array.shape}")
    return spheres_pb2.PoseArray(values=array.ravel())


def _pose(pose, name: str) -> spheres_pb2.Pose:
    values = _pose_array(pose, name).values
    if len(values) != 7:
        raise ValueError(f"{name} must be one pose of 7 numbers")
    qw, qx, qy, qz, tx, ty, tz = values
    return spheres_pb2.Pose(qw=qw, qx=qx, qy=qy, qz=qz, tx=tx, ty=ty, tz=tz)


def _sphere_set_to_proto(spheres) -> spheres_pb2.SphereSet:
    if not isinstance(spheres, _inscribe.SphereSet):
        spheres = _inscribe.SphereSet(spheres)
    array = spheres.spheres
    message = spheres_pb2.SphereSet(centers=array[:, :3].ravel(), radii=array[:, 3])
    if spheres.contact_triangles is not None:
        message.contact_triangles.extend(spheres.contact_triangles)
        message.contact_barycentrics.extend(spheres.contact_barycentrics.ravel())
    return message


_KINDS = {spheres_pb2.SPHERE_SET_KIND_INTERNAL: "internal",
          spheres_pb2.SPHERE_SET_KIND_DILATED: "dilated",
          spheres_pb2.SPHERE_SET_KIND_COVER: "cover"}


def _sphere_set_from_proto(message, kind: str = "", mesh_sha256: str = ""):
    n = len(message.radii)
    array = np.empty((n, 4), dtype=np.float64)
    array[:, :3] = np.asarray(message.centers, dtype=np.float64).reshape(n, 3)
    array[:, 3] = message.radii
    triangles = barycentrics = None
    if len(message.contact_triangles):
        triangles = np.asarray(message.contact_triangles, dtype=np.int32)
        barycentrics = np.asarray(message.contact_barycentrics, dtype=np.float64).reshape(n, 3)
    return _inscribe.SphereSet(array, triangles, barycentrics, kind=kind, mesh_sha256=mesh_sha256)


def _fields(message) -> dict:
    """Every field of a response message by name, zeros included (proto3 leaves them out of
    ListFields); unset sub-messages and optional scalars are left out, repeated ones listed."""
    out = {}
    for field in message.DESCRIPTOR.fields:
        value = getattr(message, field.name)
        if field.label == field.LABEL_REPEATED:
            out[field.name] = [_fields(v) if field.message_type else v for v in value]
        elif field.message_type is not None or field.has_presence:
            if message.HasField(field.name):
                out[field.name] = _fields(value) if field.message_type else value
        else:
            out[field.name] = value
    return out


@dataclasses.dataclass
class GenerateResult:
    """A generated set and what the server says about it (mesh units)."""

    spheres: _inscribe.SphereSet
    sphere_set_key: str      # "spheres/v1/<64 hex>"
    mesh_sha256: str
    cache: str               # "memory", "disk", "redis", "computed" or "joined"
    voxel_size: float        # sigma used; 0 for a cover
    seconds: float           # the original run's, when cached
    quality: dict            # QualityReport fields ({} when not evaluated)
    certificate: dict        # a cover's CoverCertificate fields ({} otherwise)
    selection: str           # how the budget was spent: "paper" or "optimised"
    pool_size: int           # optimised: the medial spheres chosen from; 0 otherwise


@dataclasses.dataclass
class DistanceReply:
    """Answers of one Distance call, entry i for pose pair i (mesh units, world frame).
    lower, upper and answers are filled for certified queries (covers named) only."""

    distance: np.ndarray     # (N,) float64
    sphere_a: np.ndarray     # (N,) int32
    sphere_b: np.ndarray     # (N,) int32
    point_a: np.ndarray      # (N, 3) float64
    point_b: np.ndarray      # (N, 3) float64
    closer: np.ndarray       # (N,) bool
    lower: np.ndarray        # (N,) float64, certified only
    upper: np.ndarray        # (N,) float64, certified only
    answers: list            # "yes" / "no" / "undecided", certified with closer_than only
    server_seconds: float


def _distance_reply(results, seconds: float = 0.0) -> DistanceReply:
    n = len(results.distances)
    names = {spheres_pb2.CLOSER_YES: "yes", spheres_pb2.CLOSER_NO: "no",
             spheres_pb2.CLOSER_UNDECIDED: "undecided"}
    return DistanceReply(
        distance=np.asarray(results.distances, dtype=np.float64),
        sphere_a=np.asarray(results.spheres_a, dtype=np.int32),
        sphere_b=np.asarray(results.spheres_b, dtype=np.int32),
        point_a=np.asarray(results.points_a, dtype=np.float64).reshape(n, 3),
        point_b=np.asarray(results.points_b, dtype=np.float64).reshape(n, 3),
        closer=np.asarray(results.closer, dtype=bool),
        lower=np.asarray(results.lower, dtype=np.float64),
        upper=np.asarray(results.upper, dtype=np.float64),
        answers=[names.get(a, "undecided") for a in results.answers],
        server_seconds=seconds)


class _Replica:
    def __init__(self, name: str, channel: grpc.Channel):
        self.name = name
        self.channel = channel
        self.stub = service_pb2_grpc.InscribeStub(channel)
        self.down_until = 0.0


class Client:
    """The inscribed service at one or several endpoints ("host:port").

    Client(endpoints, *, timeout=30.0, retry=RetryPolicy(), down_for=2.0, token=None,
    tls=False, ca_file=None, cert_file=None, key_file=None, max_message_bytes=256 MiB)

    endpoints: a "host:port" string, a comma-separated list of them, or a sequence. With
    several, each mesh's calls go to its replica by rendezvous hashing on the mesh hash
    (the C++ client's rule and order); a replica answering UNAVAILABLE is tried last for
    `down_for` seconds and the call moves to the next one at once.
    timeout: seconds allowed for a call (all its attempts) unless the call says otherwise.
    token: sent as "authorization: Bearer <token>" (inscribed --auth-tokens).
    tls / ca_file: TLS, the server's certificate checked against ca_file (PEM; None = the
    system's roots); cert_file and key_file: a client certificate for mutual TLS.

    Errors: ValueError for INVALID_ARGUMENT, inscribe.Error with .code otherwise (UNAVAILABLE
    after the last attempt says "(gave up after N attempts)"), messages as the server's.
    Thread-safe.
    """

    def __init__(self, endpoints, *, timeout: float = 30.0, retry: RetryPolicy = RetryPolicy(),
                 down_for: float = 2.0, token: Optional[str] = None, tls: bool = False,
                 ca_file: Optional[str] = None, cert_file: Optional[str] = None,
                 key_file: Optional[str] = None, max_message_bytes: int = 256 * 1024 * 1024):
        if isinstance(endpoints, str):
            endpoints = [e.strip() for e in endpoints.split(",") if e.strip()]
        names = list(endpoints)
        if not names:
            raise ValueError("Client needs at least one endpoint")
        if len(set(names)) != len(names):
            raise ValueError(f"duplicate endpoints: {names}")
        if (cert_file is None) != (key_file is None):
            raise ValueError("cert_file and key_file go together: both or neither")
        credentials = None
        if tls or ca_file or cert_file:
            credentials = grpc.ssl_channel_credentials(
                root_certificates=_read(ca_file), private_key=_read(key_file),
                certificate_chain=_read(cert_file))
        options = [("grpc.max_send_message_length", max_message_bytes),
                   ("grpc.max_receive_message_length", max_message_bytes)]
        self._replicas = []
        for name in names:
            channel = (grpc.secure_channel(name, credentials, options) if credentials
                       else grpc.insecure_channel(name, options))
            self._replicas.append(_Replica(name, channel))
        self._names = names
        self._metadata = (("authorization", f"Bearer {token}"),) if token else ()
        self._timeout = timeout
        self._retry = retry
        self._down_for = down_for
        self._lock = threading.Lock()

    def close(self) -> None:
        for replica in self._replicas:
            replica.channel.close()

    def __enter__(self) -> "Client":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # ---- routing and retries -------------------------------------------------------------

    def _order(self, route_key: Optional[str]) -> list:
        """Replicas to try, best first: rendezvous order for the key (listed order without
        one), those marked down last, the one marked longest ago first."""
        if route_key is None:
            order = list(range(len(self._replicas)))
        else:
            order = _inscribe._rendezvous_order(route_key, self._names)
        now = time.monotonic()
        with self._lock:
            up = [i for i in order if self._replicas[i].down_until <= now]
            down = sorted((i for i in order if self._replicas[i].down_until > now),
                          key=lambda i: self._replicas[i].down_until)
        return up + down

    def _mark(self, replica: _Replica, down: bool) -> None:
        with self._lock:
            replica.down_until = time.monotonic() + self._down_for if down else 0.0

    def _call(self, route_key: Optional[str], attempt: Callable, timeout: Optional[float]):
        """Runs attempt(stub, seconds_left) on the routed replica until it succeeds, fails with
        another code than UNAVAILABLE, the attempts run out or the deadline would pass."""
        deadline = time.monotonic() + (self._timeout if timeout is None else timeout)
        attempts = max(1, self._retry.max_attempts)
        for n in range(1, attempts + 1):
            order = self._order(route_key)
            replica = self._replicas[order[0]]
            try:
                result = attempt(replica.stub, max(0.0, deadline - time.monotonic()))
                self._mark(replica, False)
                return result
            except grpc.RpcError as error:
                if error.code() != grpc.StatusCode.UNAVAILABLE:
                    self._mark(replica, False)  # any answer proves the replica up
                    _raise_rpc_error(error)
                # As the C++ routed connection: mark it down, name it, and with another replica
                # to take the call, retry at once.
                self._mark(replica, True)
                several = len(self._replicas) > 1
                note = f" (replica {replica.name}, one of {len(self._replicas)})" if several else ""
                wait = 0.0 if several else self._retry.backoff(n)
                if n == attempts or time.monotonic() + wait >= deadline:
                    _raise_rpc_error(error, note + ("" if n == 1 else
                                                    f" (gave up after {n} attempts)"))
                time.sleep(wait)

    def _unary(self, route_key, method: str, request, timeout):
        return self._call(route_key, lambda stub, left: getattr(stub, method)(
            request, timeout=left, metadata=self._metadata), timeout)

    def _put(self, route_key: str, method: str, request, key_of: Callable, timeout):
        """A put routed by `route_key`; when the key the server answers with routes to another
        replica (a repaired mesh, a set without a mesh), put there too and return that answer,
        as the C++ routed connection does."""
        response = self._unary(route_key, method, request, timeout)
        stored_route = _inscribe._route_key(key_of(response))
        if stored_route == route_key or len(self._replicas) == 1:
            return response
        if self._order(stored_route)[0] == self._order(route_key)[0]:
            return response
        return self._unary(stored_route, method, request, timeout)

    # ---- calls ---------------------------------------------------------------------------

    def put_mesh(self, mesh: _inscribe.Mesh, *, fill_holes: bool = False,
                 weld_tolerance: float = 0.0, timeout: Optional[float] = None) -> str:
        """Validates and stores `mesh` on its replica; returns its key "sha256:<hex>" (of the
        mesh as the server fixed it: coincident vertices welded, also those within
        weld_tolerance). inscribe.Error FAILED_PRECONDITION for an unusable mesh."""
        request = service_pb2.PutMeshRequest(
            mesh=mesh_pb2.Mesh(vertices=mesh.vertices.ravel(), triangles=mesh.triangles.ravel()),
            fill_holes=fill_holes, weld_tolerance=weld_tolerance)
        response = self._put(_inscribe._route_key(mesh.sha256), "PutMesh", request,
                             lambda r: r.mesh_sha256, timeout)
        return response.mesh_sha256

    def generate(self, mesh, *, max_spheres: Optional[int] = None,
                 voxel_size: Optional[float] = None, kind: str = "internal",
                 object_angle: Optional[float] = None, epsilon: Optional[float] = None,
                 samples: Optional[int] = None, subdivide_boundary: bool = False,
                 max_protrusion: Optional[float] = None,
                 cover_resolution: Optional[float] = None, evaluate: bool = True,
                 fill_holes: bool = False, selection: Optional[str] = None, progress: Optional[Callable[[float], None]] = None,
                 progress_interval: float = 0.0,
                 timeout: Optional[float] = None) -> GenerateResult:
        """Spheres for `mesh` (an inscribe.Mesh, uploaded first, or the key of a stored one),
        with the settings of inscribe.generate (None: the server's defaults, which are core's).
        progress(fraction) is called on this thread as the server reports it, at most every
        progress_interval seconds (0: the server's 0.5 s). The result is cached on the server
        by content."""
        if kind not in ("internal", "dilated", "cover"):
            raise ValueError(f"kind must be 'internal', 'dilated' or 'cover', got {kind!r}")
        parameters = spheres_pb2.GenerateParameters(
            voxel_size=voxel_size or 0.0, max_spheres=max_spheres or 0,
            object_angle=object_angle or 0.0, epsilon=epsilon or 0.0, samples=samples or 0,
            subdivide_boundary=subdivide_boundary, dilate=kind == "dilated",
            cover=kind == "cover", fill_holes=fill_holes)
        if max_protrusion is not None:
            parameters.max_protrusion = max_protrusion
        if cover_resolution is not None:
            parameters.cover_resolution = cover_resolution
        if selection is not None:
            parameters.selection = selection  # the server names a bad one
        uploaded = isinstance(mesh, _inscribe.Mesh)
        key = self.put_mesh(mesh, fill_holes=fill_holes, timeout=timeout) if uploaded else mesh
        request = service_pb2.GenerateRequest(mesh_sha256=key, parameters=parameters,
                                              skip_quality=not evaluate,
                                              progress_interval=progress_interval)

        def attempt(stub, left):
            result = None
            for response in stub.Generate(request, timeout=left, metadata=self._metadata):
                if response.HasField("progress"):
                    if progress is not None:
                        progress(response.progress.fraction)
                elif response.HasField("result"):
                    result = response.result
            if result is None:
                raise Error("malformed Generate response: the stream ended without a result",
                            "INTERNAL")
            return result

        try:
            result = self._call(_inscribe._route_key(key), attempt, timeout)
        except Error as error:
            if not (uploaded and error.code == "NOT_FOUND"):
                raise
            # The server lost the mesh in between (evicted): upload it once more.
            self.put_mesh(mesh, fill_holes=fill_holes, timeout=timeout)
            result = self._call(_inscribe._route_key(key), attempt, timeout)
        kind_name = _KINDS.get(result.kind, "")
        return GenerateResult(
            spheres=_sphere_set_from_proto(result.spheres, kind_name, result.mesh_sha256),
            sphere_set_key=result.sphere_set_key, mesh_sha256=result.mesh_sha256,
            cache=result.cache, voxel_size=result.voxel_size, seconds=result.seconds,
            quality=_fields(result.quality) if result.HasField("quality") else {},
            certificate=(_fields(result.cover.certificate)
                         if result.HasField("cover") and result.cover.HasField("certificate")
                         else {}),
            selection=result.selection, pool_size=result.pool_size)

    def get_sphere_set(self, sphere_set_key: str, *, timeout: Optional[float] = None):
        """The cached set `sphere_set_key` (SphereSet with contacts when it has them).
        inscribe.Error NOT_FOUND for an unknown key."""
        response = self._unary(_inscribe._route_key(sphere_set_key), "GetSphereSet",
                               service_pb2.GetSphereSetRequest(sphere_set_key=sphere_set_key),
                               timeout)
        return _sphere_set_from_proto(response.spheres, mesh_sha256=response.mesh_sha256)

    def put_sphere_set(self, spheres, *, mesh_sha256: str = "",
                       timeout: Optional[float] = None) -> str:
        """Uploads `spheres` (SphereSet or (N, 4) float64), optionally naming the stored mesh
        they approximate; returns the set's key."""
        message = _sphere_set_to_proto(spheres)
        route = (_inscribe._route_key(mesh_sha256) if mesh_sha256
                 else _inscribe._content_route_key(message.SerializeToString()))
        request = service_pb2.PutSphereSetRequest(spheres=message, mesh_sha256=mesh_sha256)
        return self._put(route, "PutSphereSet", request, lambda r: r.sphere_set_key,
                         timeout).sphere_set_key

    def put_certified_cover(self, spheres, certificate: _inscribe.CoverCertificate, *,
                            timeout: Optional[float] = None) -> str:
        """Uploads a cover with the certificate it was made with (inscribe.generate(...,
        kind='cover').certificate, or inscribe.certify's), which Distance then takes on the
        caller's word; returns its key. ValueError when the certificate does not certify, or
        does not name these spheres (its spheres_sha256: they were edited after it was made)
        with one protrusion each."""
        message = _sphere_set_to_proto(spheres)
        proof = spheres_pb2.CoverCertificate(
            certified=certificate.certified, delta=certificate.delta,
            resolution=certificate.resolution, cells=certificate.cells,
            cells_in_sphere=certificate.cells_in_sphere,
            cells_outside=certificate.cells_outside, failed_cells=certificate.failed_cells,
            uncovered_depth=certificate.uncovered_depth,
            uncovered_gap=certificate.uncovered_gap, seconds=certificate.seconds,
            protrusions=list(certificate.protrusions), mesh_sha256=certificate.mesh_sha256,
            spheres_sha256=certificate.spheres_sha256)
        if certificate.uncovered_point is not None:
            proof.uncovered_point.extend(certificate.uncovered_point)
        request = service_pb2.PutSphereSetRequest(spheres=message, certificate=proof)
        route = _inscribe._content_route_key(message.SerializeToString())
        return self._put(route, "PutSphereSet", request, lambda r: r.sphere_set_key,
                         timeout).sphere_set_key

    def distance(self, sphere_set_a: str, sphere_set_b: str, poses_b, *, poses_a=None,
                 volume: str = "sphere", abs_err: float = 0.0, rel_err: float = 0.0,
                 closer_than: Optional[float] = None, brute_force: bool = False,
                 cover_a: str = "", cover_b: str = "",
                 timeout: Optional[float] = None) -> DistanceReply:
        """One batch on the server: world poses of B, (7,) or (N, 7) float64 rows
        [qw, qx, qy, qz, tx, ty, tz]; poses_a one pose for all or one per row (default
        identity). With cover_a and cover_b (cover keys of the same solids) each answer also
        holds a certified interval [lower, upper] of the exact distance."""
        volumes = {"sphere": service_pb2.SPHERE, "rss": service_pb2.RSS}
        if volume not in volumes:
            raise ValueError(f"volume must be 'sphere' or 'rss', got {volume!r}")
        tolerance = spheres_pb2.DistanceTolerance(abs_err=abs_err, rel_err=rel_err)
        if closer_than is not None:
            tolerance.closer_than = closer_than
        request = service_pb2.DistanceRequest(
            sphere_set_a=sphere_set_a, sphere_set_b=sphere_set_b, volume=volumes[volume],
            poses_a=_pose_array(np.array([1.0, 0, 0, 0, 0, 0, 0]) if poses_a is None else poses_a,
                                "poses_a"),
            poses_b=_pose_array(poses_b, "poses_b"), tolerance=tolerance,
            brute_force=brute_force, cover_a=cover_a, cover_b=cover_b)
        response = self._unary(_inscribe._route_key(sphere_set_a), "Distance", request, timeout)
        return _distance_reply(response.results, response.seconds)

    def update_deformation(self, sphere_set_key: str, vertices, *, mesh_sha256: str = "",
                           xi: float = 0.0, strict: bool = False, bounds: bool = False,
                           store: bool = False, timeout: Optional[float] = None):
        """Moves the cached internal set onto `vertices` ((V, 3) float64, the stored mesh's
        vertex order); returns (SphereSet, response fields as a dict)."""
        vertices = np.asarray(vertices)
        if vertices.dtype != np.float64:
            raise TypeError(f"vertices must be a float64 array, got {vertices.dtype}")
        if vertices.ndim != 2 or vertices.shape[1] != 3:
            raise ValueError(f"vertices must have shape (V, 3), got {vertices.shape}")
        request = service_pb2.UpdateDeformationRequest(
            mesh_sha256=mesh_sha256, sphere_set_key=sphere_set_key, vertices=vertices.ravel(),
            xi=xi, strict=strict, bounds=bounds, store=store)
        response = self._unary(_inscribe._route_key(sphere_set_key), "UpdateDeformation",
                               request, timeout)
        figures = _fields(response)
        figures.pop("spheres", None)
        return _sphere_set_from_proto(response.spheres, "internal"), figures

    def inspect_mesh(self, mesh: _inscribe.Mesh, *, skip_self_intersections: bool = False,
                     fill_holes: bool = False, weld_tolerance: float = 0.0,
                     timeout: Optional[float] = None) -> dict:
        """The server's validation of `mesh` (nothing stored): {"mesh_sha256": ..., "report":
        the MeshReport's fields as a dict, its "issues" a list of dicts}."""
        request = service_pb2.InspectMeshRequest(
            mesh=mesh_pb2.Mesh(vertices=mesh.vertices.ravel(), triangles=mesh.triangles.ravel()),
            skip_self_intersections=skip_self_intersections, fill_holes=fill_holes,
            weld_tolerance=weld_tolerance)
        response = self._unary(_inscribe._route_key(mesh.sha256), "InspectMesh", request, timeout)
        return _fields(response)

    def get_hierarchy(self, sphere_set_key: str, *, volume: str = "sphere",
                      timeout: Optional[float] = None) -> _inscribe.Hierarchy:
        """The server's hierarchy of a cached set, checked as it is read
        (Hierarchy.deserialize): usable with inscribe.distance in-process."""
        volumes = {"sphere": service_pb2.SPHERE, "rss": service_pb2.RSS}
        if volume not in volumes:
            raise ValueError(f"volume must be 'sphere' or 'rss', got {volume!r}")
        request = service_pb2.GetHierarchyRequest(sphere_set_key=sphere_set_key,
                                                  volume=volumes[volume])
        response = self._unary(_inscribe._route_key(sphere_set_key), "GetHierarchy", request,
                               timeout)
        return _inscribe.Hierarchy.deserialize(response.hierarchy)

    def certify_cover(self, mesh_sha256: str, spheres, *, resolution: Optional[float] = None,
                      timeout: Optional[float] = None) -> dict:
        """Whether a cached set (its key) or `spheres` (SphereSet or (N, 4) float64) provably
        hold the whole solid of a stored mesh: the CoverCertificate's fields as a dict."""
        request = service_pb2.CertifyCoverRequest(mesh_sha256=mesh_sha256)
        if isinstance(spheres, str):
            request.sphere_set_key = spheres
        else:
            request.sphere_set.CopyFrom(_sphere_set_to_proto(spheres))
        if resolution is not None:
            request.resolution = resolution
        response = self._unary(_inscribe._route_key(mesh_sha256), "CertifyCover", request,
                               timeout)
        return _fields(response.certificate) if response.HasField("certificate") else {}

    def evaluate(self, mesh_sha256: str, sphere_set_key: str, *,
                 timeout: Optional[float] = None) -> dict:
        """The QualityReport of a cached set against a stored mesh, as a dict."""
        request = service_pb2.EvaluateRequest(mesh_sha256=mesh_sha256,
                                              sphere_set_key=sphere_set_key)
        response = self._unary(_inscribe._route_key(mesh_sha256), "Evaluate", request, timeout)
        return _fields(response.quality)

    def cache_stats(self, *, timeout: Optional[float] = None) -> dict:
        """The first listed replica's cache counters (the next when it is down), as a dict."""
        response = self._unary(None, "CacheStats", service_pb2.CacheStatsRequest(), timeout)
        return _fields(response)

    def open_distance_session(self, *, volume: str = "sphere", abs_err: float = 0.0,
                              rel_err: float = 0.0, frame_timeout: float = 10.0,
                              session_timeout: Optional[float] = None) -> "DistanceSession":
        """A DistanceStream call for a simulator loop: one query() per frame over one HTTP/2
        stream. Not retried as a whole; routed by its first frame's first set."""
        return DistanceSession(self, volume, abs_err, rel_err, frame_timeout, session_timeout)


class DistanceSession:
    """One DistanceStream call: query(pairs) per frame, answered in order. Not thread-safe.
    Any error ends the session (later queries raise the same error). Use as a context manager
    or call close()."""

    def __init__(self, client: Client, volume: str, abs_err: float, rel_err: float,
                 frame_timeout: float, session_timeout: Optional[float]):
        volumes = {"sphere": service_pb2.SPHERE, "rss": service_pb2.RSS}
        if volume not in volumes:
            raise ValueError(f"volume must be 'sphere' or 'rss', got {volume!r}")
        self._client = client
        self._volume = volumes[volume]
        self._tolerance = spheres_pb2.DistanceTolerance(abs_err=abs_err, rel_err=rel_err)
        self._frame_timeout = frame_timeout
        self._session_timeout = session_timeout
        self._next_frame = 0
        self._stream = None
        self._broken: Optional[BaseException] = None

    def _open(self, route_key: str, tried: Sequence[_Replica] = ()) -> None:
        """Opens the stream on the first replica of the key's order not tried yet."""
        replica = next(r for r in (self._client._replicas[i]
                                   for i in self._client._order(route_key)) if r not in tried)
        requests: queue.Queue = queue.Queue()
        call = replica.stub.DistanceStream(iter(requests.get, None),
                                           timeout=self._session_timeout,
                                           metadata=self._client._metadata)
        replies: queue.Queue = queue.Queue()

        def read():
            try:
                for reply in call:
                    replies.put(reply)
                replies.put(None)
            except grpc.RpcError as error:
                replies.put(error)

        threading.Thread(target=read, daemon=True).start()
        self._stream = (replica, requests, call, replies)

    def query(self, pairs: Sequence[tuple]) -> DistanceReply:
        """Distances of one frame: pairs of (set_key_a, set_key_b, pose_a, pose_b), poses
        (7,) float64 [qw, qx, qy, qz, tx, ty, tz] in the world frame; or, for certified
        intervals, (set_key_a, set_key_b, pose_a, pose_b, cover_a, cover_b) with the covers'
        keys (a frame's pairs are all certified or none). Returns a DistanceReply (entry i
        answers pairs[i]; lower and upper filled when certified)."""
        if self._broken is not None:
            raise self._broken
        frame = service_pb2.DistanceFrame(frame=self._next_frame, volume=self._volume,
                                          tolerance=self._tolerance)
        for i, pair in enumerate(pairs):
            if len(pair) not in (4, 6):
                raise ValueError(f"pairs[{i}] must be (key_a, key_b, pose_a, pose_b[, cover_a, "
                                 f"cover_b]), got {len(pair)} items")
            key_a, key_b, pose_a, pose_b = pair[:4]
            cover_a, cover_b = pair[4:] if len(pair) == 6 else ("", "")
            frame.pairs.append(service_pb2.DistancePair(
                sphere_set_a=key_a, sphere_set_b=key_b, pose_a=_pose(pose_a, f"pairs[{i}] pose_a"),
                pose_b=_pose(pose_b, f"pairs[{i}] pose_b"), cover_a=cover_a, cover_b=cover_b))
        try:
            if self._stream is None:
                self._open(_inscribe._route_key(frame.pairs[0].sphere_set_a if frame.pairs else ""))
            reply = self._round_trip(frame)
        except BaseException as error:
            self._broken = error
            self.close()
            raise
        self._next_frame += 1
        return _distance_reply(reply.results)

    def _round_trip(self, frame):
        tried = []
        for _ in range(len(self._client._replicas)):
            replica, requests, call, replies = self._stream
            tried.append(replica)
            requests.put(frame)
            try:
                reply = replies.get(timeout=self._frame_timeout)
            except queue.Empty:
                call.cancel()
                raise Error(f"frame {frame.frame} took longer than {self._frame_timeout} s",
                            "DEADLINE_EXCEEDED") from None
            if isinstance(reply, grpc.RpcError):
                last = len(tried) == len(self._client._replicas)
                if reply.code() != grpc.StatusCode.UNAVAILABLE or last:
                    _raise_rpc_error(reply)
                # A broken routed stream is reopened on the next replica, the frame resent.
                self._client._mark(replica, True)
                requests.put(None)
                self._open(_inscribe._route_key(frame.pairs[0].sphere_set_a), tried)
                continue
            if reply is None:
                raise Error("the server ended the stream", "INTERNAL")
            if reply.frame != frame.frame:
                raise Error(f"reply for frame {reply.frame}, expected {frame.frame}", "INTERNAL")
            return reply
        raise Error("no replica took the stream", "UNAVAILABLE")

    def close(self) -> None:
        """Ends the stream (half-close)."""
        if self._stream is not None:
            _, requests, call, _ = self._stream
            requests.put(None)
            self._stream = None

    def __enter__(self) -> "DistanceSession":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _read(path: Optional[str]) -> Optional[bytes]:
    if path is None:
        return None
    with open(path, "rb") as f:
        return f.read()
