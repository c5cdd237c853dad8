"""inscribe.Client: the inscribed service over gRPC (grpcio).

Transport only. Every request is built and every answer read by the extension (_inscribe,
python/src/client_requests.cpp and client_replies.cpp) with wire/'s conversions, the ones the
C++ client and the server use; grpcio carries the serialised bytes. What is here behaves as the
C++ client (client/include/inscribe/client/client.h, routing.h): each call goes to the replica
that owns its mesh (rendezvous hashing on the mesh hash, computed by the same C++ function,
wire::RendezvousOrder, bound in _inscribe); an UNAVAILABLE replica is marked down for
`down_for` seconds and the next attempt goes to the next replica at once; idempotent calls (all
unary ones) are retried on UNAVAILABLE with exponential, jittered backoff within the call's
deadline; a mesh the server lost between its upload and Generate is uploaded once more; TLS,
mutual TLS and bearer tokens as inscribed's flags expect them.
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

from . import _inscribe, _progress
from ._errors import Error


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


@dataclasses.dataclass
class InspectMeshResult:
    """The server's validation of a mesh (nothing stored)."""

    mesh_sha256: str         # "sha256:<64 hex>" of the mesh after the server's fixes
    report: _inscribe.MeshReport


@dataclasses.dataclass
class GenerateResult:
    """A generated set and what the server says about it (mesh units)."""

    spheres: _inscribe.SphereSet  # with .kind, .mesh_sha256, .quality and .certificate
    sphere_set_key: str      # "spheres/v1/<64 hex>"
    mesh_sha256: str
    cache: str               # "memory", "disk", "redis", "computed" or "joined"
    voxel_size: float        # sigma used; 0 for a cover
    seconds: float           # the original run's, when cached
    quality: Optional[_inscribe.QualityReport]          # None when not evaluated
    certificate: Optional[_inscribe.CoverCertificate]   # a cover's; None otherwise
    selection: str           # how the budget was spent: "paper" or "optimised"
    pool_size: int           # optimised: the medial spheres chosen from; 0 otherwise


@dataclasses.dataclass
class DeformationResult:
    """The cached set moved onto new vertices, as inscribe.Deformer.update makes it, and what
    the server adds."""

    spheres: _inscribe.SphereSet  # with contacts, .reference_index and .stats (shrunk, ...)
    bounds: Optional[_inscribe.DeformationErrorBounds]  # when asked (bounds=True)
    reference_spheres: int
    deformed_mesh_sha256: str
    sphere_set_key: str      # the moved set's key when stored (store=True), else ""


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
    answers: list            # "yes" / "no" / "undecided" ("undecided" without closer_than)
    server_seconds: float


class _Replica:
    """One endpoint: its channel and one callable per RPC, carrying serialised messages."""

    _KINDS = {(False, False): "unary_unary", (False, True): "unary_stream",
              (True, False): "stream_unary", (True, True): "stream_stream"}

    def __init__(self, name: str, channel: grpc.Channel):
        self.name = name
        self.channel = channel
        self.rpc = {}
        for method, path, client_streaming, server_streaming in _inscribe._rpc_methods():
            kind = self._KINDS[(client_streaming, server_streaming)]
            self.rpc[method] = getattr(channel, kind)(path)
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

    Results are the in-process API's types (SphereSet, QualityReport, CoverCertificate,
    MeshReport, Hierarchy, DeformationErrorBounds) and numpy arrays.
    Errors: ValueError for INVALID_ARGUMENT (bad settings are refused before anything is
    sent), inscribe.Error with .code otherwise (UNAVAILABLE after the last attempt says
    "(gave up after N attempts)"), messages as the server's. Thread-safe.
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
            target = _inscribe._target_with_default_port(name)
            channel = (grpc.secure_channel(target, credentials, options) if credentials
                       else grpc.insecure_channel(target, options))
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
        """Runs attempt(rpc, seconds_left) on the routed replica's callables until it succeeds,
        fails with another code than UNAVAILABLE, the attempts run out or the deadline would
        pass."""
        deadline = time.monotonic() + (self._timeout if timeout is None else timeout)
        attempts = max(1, self._retry.max_attempts)
        for n in range(1, attempts + 1):
            order = self._order(route_key)
            replica = self._replicas[order[0]]
            try:
                result = attempt(replica.rpc, max(0.0, deadline - time.monotonic()))
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

    def _unary(self, route_key, method: str, request: bytes, timeout) -> bytes:
        return self._call(route_key, lambda rpc, left: rpc[method](
            request, timeout=left, metadata=self._metadata), timeout)

    def _put(self, route_key: str, method: str, request: bytes,
             stored_key: Callable[[bytes], str], timeout) -> str:
        """A put routed by `route_key`, returning the key the server stored it under
        (stored_key reads it from the answer); when that key routes to another replica (a
        repaired mesh, a set without a mesh), put there too and return that answer's, as the
        C++ routed connection does."""
        key = stored_key(self._unary(route_key, method, request, timeout))
        stored_route = _inscribe._route_key(key)
        if stored_route == route_key or len(self._replicas) == 1:
            return key
        if self._order(stored_route)[0] == self._order(route_key)[0]:
            return key
        return stored_key(self._unary(stored_route, method, request, timeout))

    # ---- calls ---------------------------------------------------------------------------

    def put_mesh(self, mesh, *, repair="safe", fill_holes: bool = False,
                 weld_tolerance: float = 0.0, timeout: Optional[float] = None) -> str:
        """Validates and stores `mesh` (an inscribe.Mesh, a path, a (vertices, faces) pair or a
        trimesh, as every in-process call takes a mesh) on its replica; returns its key
        "sha256:<hex>" (of the mesh as the server repaired it: `repair` is an inscribe.Repair
        or a level name, as in inscribe.prepare; fill_holes=True is "fill"; coincident vertices
        are always welded, also those within weld_tolerance). inscribe.Error
        FAILED_PRECONDITION for an unusable mesh."""
        mesh = _inscribe._mesh_of(mesh)
        request = _inscribe._put_mesh_request(
            mesh, repair=_inscribe._repair_argument(repair, fill_holes=fill_holes,
                                                    weld_tolerance=weld_tolerance))
        return self._put(_inscribe._route_key(mesh.sha256), "PutMesh", request,
                         _inscribe._put_mesh_reply, timeout)

    def generate(self, mesh, *, max_spheres: Optional[int] = None,
                 voxel_size: Optional[float] = None, kind: str = "internal",
                 object_angle: Optional[float] = None, epsilon: Optional[float] = None,
                 samples: Optional[int] = None, subdivide_boundary: Optional[bool] = None,
                 max_voxels: Optional[int] = None, dilation_growth: Optional[float] = None,
                 max_protrusion: Optional[float] = None,
                 cover_resolution: Optional[float] = None, evaluate: bool = True,
                 quality_samples: Optional[int] = None, repair="safe",
                 fill_holes: bool = False, selection: Optional[str] = None,
                 progress=None,
                 progress_interval: float = 0.0,
                 timeout: Optional[float] = None) -> GenerateResult:
        """Spheres for `mesh` (the key "sha256:<hex>" of a stored mesh, or any other mesh
        put_mesh takes, uploaded first),
        with the settings of inscribe.generate (None: core's defaults), checked before anything
        is sent (ValueError naming the field); an uploaded mesh is repaired as `repair` says
        (put_mesh). progress(fraction) (or a tqdm bar, as inscribe.generate takes) is called on
        this thread as the server reports it, at most every progress_interval seconds (0: the
        server's 0.5 s). The result's .spheres is the SphereSet inscribe.generate returns.
        The result is cached on the server by content. A mesh uploaded here that the server
        lost before Generate (evicted) is uploaded once more."""
        asked = _inscribe._repair_argument(repair, fill_holes=fill_holes, weld_tolerance=0.0)
        call = _inscribe._GenerateCall(
            max_spheres=max_spheres, voxel_size=voxel_size, kind=kind, object_angle=object_angle,
            epsilon=epsilon, samples=samples, subdivide_boundary=subdivide_boundary,
            max_voxels=max_voxels, dilation_growth=dilation_growth,
            max_protrusion=max_protrusion, cover_resolution=cover_resolution, evaluate=evaluate,
            quality_samples=quality_samples, selection=selection, repair=asked,
            progress_interval=progress_interval)
        report = _progress.progress_callback(progress)
        uploaded = not (isinstance(mesh, str) and mesh.startswith("sha256:"))
        if uploaded:
            mesh = _inscribe._mesh_of(mesh)
        key = self.put_mesh(mesh, repair=asked, timeout=timeout) if uploaded else mesh

        def attempt(rpc, left):
            result = None
            for message in rpc["Generate"](call.request(key), timeout=left,
                                           metadata=self._metadata):
                fraction, answer = call.read(message)
                if fraction is not None and report is not None:
                    report(fraction)
                if answer is not None:
                    result = answer
            if result is None:
                raise Error("malformed Generate response: the stream ended without a result",
                            "INTERNAL")
            return result

        try:
            fields = self._call(_inscribe._route_key(key), attempt, timeout)
        except Error as error:
            if not (uploaded and error.code == "NOT_FOUND"):
                raise
            # The server lost the mesh in between (evicted): upload it once more.
            key = self.put_mesh(mesh, repair=asked, timeout=timeout)
            fields = self._call(_inscribe._route_key(key), attempt, timeout)
        return GenerateResult(**fields)

    def get_sphere_set(self, sphere_set_key: str, *, timeout: Optional[float] = None):
        """The cached set `sphere_set_key` (SphereSet with contacts when it has them).
        inscribe.Error NOT_FOUND for an unknown key."""
        reply = self._unary(_inscribe._route_key(sphere_set_key), "GetSphereSet",
                            _inscribe._get_sphere_set_request(sphere_set_key), timeout)
        return _inscribe._sphere_set_reply(reply)

    def put_sphere_set(self, spheres, *, mesh_sha256: str = "",
                       timeout: Optional[float] = None) -> str:
        """Uploads `spheres` (SphereSet or (N, 4) float64), optionally naming the stored mesh
        they approximate; returns the set's key."""
        request, content_route = _inscribe._put_sphere_set_request(spheres,
                                                                   mesh_sha256=mesh_sha256)
        route = _inscribe._route_key(mesh_sha256) if mesh_sha256 else content_route
        return self._put(route, "PutSphereSet", request, _inscribe._put_sphere_set_reply, timeout)

    def put_certified_cover(self, spheres, certificate: _inscribe.CoverCertificate, *,
                            timeout: Optional[float] = None) -> str:
        """Uploads a cover with the certificate it was made with (inscribe.generate(...,
        kind='cover').certificate, or inscribe.certify's), which Distance then takes on the
        caller's word; returns its key. ValueError when the certificate does not certify, or
        does not name these spheres (its spheres_sha256: they were edited after it was made)
        with one protrusion each."""
        request, route = _inscribe._put_sphere_set_request(spheres, certificate=certificate)
        return self._put(route, "PutSphereSet", request, _inscribe._put_sphere_set_reply, timeout)

    def distance(self, sphere_set_a: str, sphere_set_b: str, poses_b, *, poses_a=None,
                 volume: str = "sphere", abs_err: float = 0.0, rel_err: float = 0.0,
                 closer_than: Optional[float] = None, brute_force: bool = False,
                 cover_a: str = "", cover_b: str = "",
                 timeout: Optional[float] = None) -> DistanceReply:
        """One batch on the server: world poses of B, (7,) or (N, 7) float64 rows
        [qw, qx, qy, qz, tx, ty, tz]; poses_a one pose for all or one per row (default
        identity). With cover_a and cover_b (cover keys of the same solids) each answer also
        holds a certified interval [lower, upper] of the exact distance."""
        request = _inscribe._distance_request(
            sphere_set_a, sphere_set_b, poses_b, poses_a=poses_a, volume=volume,
            abs_err=abs_err, rel_err=rel_err, closer_than=closer_than, brute_force=brute_force,
            cover_a=cover_a, cover_b=cover_b)
        reply = self._unary(_inscribe._route_key(sphere_set_a), "Distance", request, timeout)
        return DistanceReply(**_inscribe._distance_reply(reply, certified=bool(cover_a)))

    def update_deformation(self, sphere_set_key: str, vertices, *, mesh_sha256: str = "",
                           xi: Optional[float] = None, strict: bool = False,
                           interpolated_normal: bool = False, bounds: bool = False,
                           store: bool = False,
                           timeout: Optional[float] = None) -> DeformationResult:
        """Moves the cached internal set onto `vertices` ((V, 3) float64, the stored mesh's
        vertex order), with inscribe.Deformer's settings (xi None: core's default); with
        bounds, also nerr's bounds; with store, the moved set is cached too."""
        request = _inscribe._update_deformation_request(
            sphere_set_key, vertices, mesh_sha256=mesh_sha256, xi=xi, strict=strict,
            interpolated_normal=interpolated_normal, bounds=bounds, store=store)
        reply = self._unary(_inscribe._route_key(sphere_set_key), "UpdateDeformation",
                            request, timeout)
        return DeformationResult(**_inscribe._update_deformation_reply(reply, bounds=bounds))

    def inspect_mesh(self, mesh, *, skip_self_intersections: bool = False,
                     repair="safe", fill_holes: bool = False, weld_tolerance: float = 0.0,
                     timeout: Optional[float] = None) -> InspectMeshResult:
        """The server's validation of `mesh` (nothing stored): its key after the server's
        repairs (`repair` as in put_mesh) and its MeshReport; `mesh` as put_mesh takes it."""
        mesh = _inscribe._mesh_of(mesh)
        request = _inscribe._inspect_mesh_request(
            mesh, skip_self_intersections=skip_self_intersections,
            repair=_inscribe._repair_argument(repair, fill_holes=fill_holes,
                                              weld_tolerance=weld_tolerance))
        reply = self._unary(_inscribe._route_key(mesh.sha256), "InspectMesh", request, timeout)
        return InspectMeshResult(**_inscribe._inspect_mesh_reply(reply))

    def get_hierarchy(self, sphere_set_key: str, *, volume: str = "sphere",
                      timeout: Optional[float] = None) -> _inscribe.Hierarchy:
        """The server's hierarchy of a cached set, checked as it is read
        (Hierarchy.deserialize): usable with inscribe.distance in-process."""
        request = _inscribe._get_hierarchy_request(sphere_set_key, volume=volume)
        reply = self._unary(_inscribe._route_key(sphere_set_key), "GetHierarchy", request,
                            timeout)
        return _inscribe._hierarchy_reply(reply, volume=volume)

    def certify_cover(self, mesh_sha256: str, spheres, *, resolution: Optional[float] = None,
                      timeout: Optional[float] = None) -> _inscribe.CoverCertificate:
        """Whether a cached set (its key) or `spheres` (SphereSet or (N, 4) float64) provably
        hold the whole solid of a stored mesh: its CoverCertificate (the failed cells are
        counted, not sent). resolution as inscribe.certify's (None: core's default)."""
        request = _inscribe._certify_cover_request(mesh_sha256, spheres, resolution=resolution)
        reply = self._unary(_inscribe._route_key(mesh_sha256), "CertifyCover", request,
                            timeout)
        return _inscribe._certify_cover_reply(reply)

    def evaluate(self, mesh_sha256: str, sphere_set_key: str, *,
                 timeout: Optional[float] = None) -> _inscribe.QualityReport:
        """The QualityReport of a cached set against a stored mesh (core's default options)."""
        request = _inscribe._evaluate_request(mesh_sha256, sphere_set_key)
        reply = self._unary(_inscribe._route_key(mesh_sha256), "Evaluate", request, timeout)
        return _inscribe._evaluate_reply(reply)

    def cache_stats(self, *, timeout: Optional[float] = None) -> dict:
        """The first listed replica's cache counters (the next when it is down), as a dict."""
        reply = self._unary(None, "CacheStats", _inscribe._cache_stats_request(), timeout)
        return _inscribe._cache_stats_reply(reply)

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
        self._client = client
        self._frames = _inscribe._DistanceFrames(volume, abs_err, rel_err)
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
        call = replica.rpc["DistanceStream"](iter(requests.get, None),
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
        frame, certified = self._frames.frame(self._next_frame, pairs)
        route = _inscribe._route_key(pairs[0][0] if pairs else "")
        try:
            if self._stream is None:
                self._open(route)
            reply = self._round_trip(frame, route, certified)
        except BaseException as error:
            self._broken = error
            self.close()
            raise
        self._next_frame += 1
        return reply

    def _round_trip(self, frame: bytes, route: str, certified: bool) -> DistanceReply:
        tried = []
        for _ in range(len(self._client._replicas)):
            replica, requests, call, replies = self._stream
            tried.append(replica)
            requests.put(frame)
            try:
                reply = replies.get(timeout=self._frame_timeout)
            except queue.Empty:
                call.cancel()
                raise Error(f"frame {self._next_frame} took longer than {self._frame_timeout} s",
                            "DEADLINE_EXCEEDED") from None
            if isinstance(reply, grpc.RpcError):
                last = len(tried) == len(self._client._replicas)
                if reply.code() != grpc.StatusCode.UNAVAILABLE or last:
                    _raise_rpc_error(reply)
                # A broken routed stream is reopened on the next replica, the frame resent.
                self._client._mark(replica, True)
                requests.put(None)
                self._open(route, tried)
                continue
            if reply is None:
                raise Error("the server ended the stream", "INTERNAL")
            number, fields = _inscribe._distance_frame_reply(reply, certified=certified)
            if number != self._next_frame:
                raise Error(f"reply for frame {number}, expected {self._next_frame}", "INTERNAL")
            return DistanceReply(**fields)
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
