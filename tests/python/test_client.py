"""inscribe.Client against real inscribed servers: the same spheres and distances as in-process,
errors, a DistanceSession, failover and routing as the C++ client, bearer tokens and mTLS."""

import itertools
import json
import socket
import subprocess
import time

import grpc
import numpy as np
import pytest

import inscribe
from conftest import Server, mesh_path, run_cli


def free_dead_endpoint():
    # A port that was free a moment ago and has nobody listening: UNAVAILABLE.
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return f"127.0.0.1:{s.getsockname()[1]}"


def dead_endpoint_routed_first(route, live, tries=1_000_000):
    # A refusing endpoint that rendezvous routing ranks above `live` for `route`, and the socket
    # that keeps it refusing until closed. The port is held bound on every address without
    # listening, and the name varies over loopback hosts 127.x.y.z: each name has a fresh score,
    # so one beats `live` unless live's score is in the top 1/`tries` of all.
    held = socket.socket()
    held.bind(("0.0.0.0", 0))
    port = held.getsockname()[1]
    hosts = (f"127.{a}.{b}.{c}" for a in range(256) for b in range(256) for c in range(1, 255))
    for host in itertools.islice(hosts, tries):
        dead = f"{host}:{port}"
        if inscribe._inscribe._rendezvous_order(route, [dead, live])[0] == 0:
            return held, dead
    held.close()
    pytest.fail(f"none of {tries} dead endpoints routed before {live}")


@pytest.fixture(scope="module")
def eight():
    return inscribe.load_mesh(mesh_path("eight.off"))


def test_generate_on_the_server_is_in_process_generation_bit_for_bit(server, eight):
    with inscribe.Client(server.address) as client:
        seen = []
        result = client.generate(eight, max_spheres=60, progress=seen.append)
        local = inscribe.generate(eight, max_spheres=60)
        assert np.array_equal(result.spheres.spheres, local.spheres)
        assert np.array_equal(result.spheres.contact_triangles, local.contact_triangles)
        assert result.mesh_sha256 == local.mesh_sha256 and result.spheres.kind == "internal"
        assert result.quality.nerr == local.quality.nerr
        again = client.generate(eight, max_spheres=60)
        assert again.cache == "memory" and again.sphere_set_key == result.sphere_set_key
        stored = client.get_sphere_set(result.sphere_set_key)
        assert np.array_equal(stored.spheres, local.spheres)
        assert result.selection == "optimised" and result.pool_size > 60
        paper = client.generate(eight, max_spheres=60, selection="paper")
        local_paper = inscribe.generate(eight, max_spheres=60, selection="paper")
        assert paper.selection == "paper" and paper.sphere_set_key != result.sphere_set_key
        assert np.array_equal(paper.spheres.spheres, local_paper.spheres)
        with pytest.raises(ValueError, match="unknown sphere selection 'greedy'"):
            client.generate(eight, max_spheres=60, selection="greedy")


class TrimeshLike:
    def __init__(self, mesh):
        self.vertices = np.array(mesh.vertices)
        self.faces = np.array(mesh.triangles, dtype=np.int64)


def test_the_client_takes_every_mesh_form_and_gives_the_same_sphere_set(server, eight, tmp_path):
    local = inscribe.generate(eight, max_spheres=30, evaluate=False)
    path = tmp_path / "eight.ply"
    inscribe.write_mesh(eight, path)
    with inscribe.Client(server.address) as client:
        for mesh in (path, (np.array(eight.vertices), np.array(eight.triangles, dtype=np.int64)),
                     TrimeshLike(eight)):
            result = client.generate(mesh, max_spheres=30, evaluate=False)
            # The same type as in-process: a SphereSet, array-like as local.spheres is.
            assert type(result.spheres) is type(local)
            assert np.array_equal(np.asarray(result.spheres), np.asarray(local))
            assert result.spheres.shape == local.spheres.shape
            assert np.array_equal(result.spheres[:, 3], local.spheres[:, 3])
        assert client.put_mesh(path) == inscribe.prepare(eight).sha256
        assert client.inspect_mesh(str(path)).mesh_sha256 == inscribe.prepare(eight).sha256


def test_distance_batch_and_session_match_in_process(server, eight):
    with inscribe.Client(server.address) as client:
        key = client.generate(eight, max_spheres=60).sphere_set_key
        local = inscribe.generate(eight, max_spheres=60, evaluate=False)
        rng = np.random.default_rng(3)
        q = rng.normal(size=(200, 4))
        poses = np.hstack([q / np.linalg.norm(q, axis=1, keepdims=True),
                           rng.uniform(-2, 2, size=(200, 3))])
        remote = client.distance(key, key, poses)
        ours = inscribe.distance(local, local, poses)
        assert np.array_equal(remote.distance, ours.distance)
        assert np.array_equal(remote.point_b, ours.point_b)
        identity = np.array([1.0, 0, 0, 0, 0, 0, 0])
        with client.open_distance_session() as session:
            for frame in range(3):
                reply = session.query([(key, key, identity, poses[frame])])
                assert reply.distance[0] == ours.distance[frame]


def test_every_other_call_agrees_with_in_process(server, eight):
    with inscribe.Client(server.address) as client:
        solid = inscribe.prepare(eight)
        inspected = client.inspect_mesh(eight)
        assert inspected.mesh_sha256 == solid.sha256
        assert inspected.report.volume == solid.report.volume
        generated = client.generate(eight, max_spheres=60)
        key, mesh_key = generated.sphere_set_key, generated.mesh_sha256
        local = inscribe.generate(solid, max_spheres=60)
        # Evaluation with the same settings as in-process.
        assert client.evaluate(mesh_key, key).nerr == local.quality.nerr
        # The server's hierarchy answers as one built here.
        pose = np.array([1.0, 0, 0, 0, 0.7, 0.1, 0])
        remote_h = client.get_hierarchy(key)
        assert inscribe.distance(remote_h, remote_h, pose).distance == \
            inscribe.distance(local, local, pose).distance
        # Deformation frames as inscribe.Deformer makes them.
        vertices = np.ascontiguousarray(solid.mesh.vertices * np.array([1.03, 1.0, 0.98]))
        moved = client.update_deformation(key, vertices, bounds=True)
        deformer = inscribe.Deformer(solid, local)
        ours = deformer.update(vertices)
        assert np.array_equal(moved.spheres.spheres, ours.spheres)
        assert np.array_equal(moved.spheres.reference_index, ours.reference_index)
        assert moved.spheres.stats == {**ours.stats, "seconds": moved.spheres.stats["seconds"]}
        assert moved.bounds.nerr_upper == deformer.bounds(ours).nerr_upper
        # Uploads and certificates.
        uploaded = client.put_sphere_set(local, mesh_sha256=mesh_key)
        assert np.array_equal(client.get_sphere_set(uploaded).spheres, local.spheres)
        assert client.certify_cover(mesh_key, uploaded).certified is False
        cover = inscribe.generate(solid, max_spheres=80, kind="cover", evaluate=False)
        assert client.certify_cover(mesh_key, cover).certified is True


def test_answers_are_the_in_process_types(server, eight):
    with inscribe.Client(server.address) as client:
        internal = client.generate(eight, max_spheres=60)
        assert isinstance(internal.quality, inscribe.QualityReport)
        assert internal.spheres.quality.nerr == internal.quality.nerr
        assert internal.certificate is None and internal.spheres.certificate is None
        assert isinstance(client.inspect_mesh(eight).report, inscribe.MeshReport)
        assert isinstance(client.evaluate(internal.mesh_sha256, internal.sphere_set_key),
                          inscribe.QualityReport)
        cover = client.generate(eight, max_spheres=80, kind="cover", evaluate=False)
        assert cover.quality is None and isinstance(cover.certificate, inscribe.CoverCertificate)
        # The cover's SphereSet carries its certificate, which names its spheres and mesh:
        # CertifiedObject takes delta and the cores from it, as from an in-process cover.
        assert cover.spheres.certificate.delta == cover.certificate.delta
        inscribe.CertifiedObject(internal.spheres, cover.spheres)
        certificate = client.certify_cover(cover.mesh_sha256, cover.sphere_set_key)
        assert isinstance(certificate, inscribe.CoverCertificate) and certificate.certified


class Lost(grpc.RpcError):
    """NOT_FOUND as the server answers for a mesh it no longer holds."""

    def code(self):
        return grpc.StatusCode.NOT_FOUND

    def details(self):
        return "unknown mesh"


def test_generate_uploads_a_mesh_the_server_lost_once_more(server, eight):
    with inscribe.Client(server.address) as client:
        replica = client._replicas[0]
        generate, put = replica.rpc["Generate"], replica.rpc["PutMesh"]
        calls = []

        def put_counted(request, **kwargs):
            calls.append("PutMesh")
            return put(request, **kwargs)

        def lost_once(request, **kwargs):
            calls.append("Generate")
            if calls.count("Generate") == 1:
                raise Lost()
            return generate(request, **kwargs)

        replica.rpc["PutMesh"], replica.rpc["Generate"] = put_counted, lost_once
        result = client.generate(eight, max_spheres=40)
        assert calls == ["PutMesh", "Generate", "PutMesh", "Generate"]
        assert len(result.spheres) > 0

        # Lost again after the second upload: that NOT_FOUND is the answer.
        def lost(request, **kwargs):
            calls.append("Generate")
            raise Lost()

        replica.rpc["Generate"] = lost
        calls.clear()
        with pytest.raises(inscribe.Error) as raised:
            client.generate(eight, max_spheres=40)
        assert raised.value.code == "NOT_FOUND"
        assert calls == ["PutMesh", "Generate", "PutMesh", "Generate"]
        # A stored mesh named by its key is not the client's to upload.
        calls.clear()
        with pytest.raises(inscribe.Error):
            client.generate(result.mesh_sha256, max_spheres=40)
        assert calls == ["Generate"]


def test_bad_settings_are_refused_before_anything_is_sent(eight):
    with inscribe.Client(free_dead_endpoint(), timeout=5.0,
                         retry=inscribe.RetryPolicy(max_attempts=1)) as client:
        with pytest.raises(ValueError, match="not both"):
            client.generate(eight, max_spheres=5, voxel_size=0.1)
        with pytest.raises(ValueError, match="unknown sphere selection 'greedy'"):
            client.generate(eight, max_spheres=60, selection="greedy")
        with pytest.raises(ValueError, match="kind must be"):
            client.generate(eight, kind="outer")
        with pytest.raises(ValueError, match="unit quaternion"):
            client.distance("a", "b", np.array([2.0, 0, 0, 0, 0, 0, 0]))
        with pytest.raises(ValueError, match="volume must be 'sphere' or 'rss'"):
            client.open_distance_session(volume="obb")
        with client.open_distance_session() as session:
            identity = np.array([1.0, 0, 0, 0, 0, 0, 0])
            with pytest.raises(ValueError, match=r"pairs\[0\] must be"):
                session.query([("a", "b", identity)])


def test_certified_intervals_over_the_service_are_the_in_process_ones(server, eight):
    with inscribe.Client(server.address) as client:
        internal = client.generate(eight, max_spheres=60, evaluate=False)
        cover = client.generate(eight, max_spheres=80, kind="cover", evaluate=False)
        assert cover.spheres.kind == "cover" and cover.certificate.certified
        local = inscribe.CertifiedObject(internal.spheres, cover.spheres,
                                         cover.certificate.delta,
                                         protrusions=cover.certificate.protrusions)
        rng = np.random.default_rng(5)
        q = rng.normal(size=(50, 4))
        poses = np.hstack([q / np.linalg.norm(q, axis=1, keepdims=True),
                           rng.uniform(-3, 3, size=(50, 3))])
        remote = client.distance(internal.sphere_set_key, internal.sphere_set_key, poses,
                                 cover_a=cover.sphere_set_key, cover_b=cover.sphere_set_key,
                                 closer_than=0.2)
        ours = inscribe.certified_distance(local, local, poses, closer_than=0.2)
        assert np.array_equal(remote.lower, ours.lower)
        assert np.array_equal(remote.upper, ours.upper)
        assert remote.answers == ours.closer
        # A cover made in-process, uploaded with its certificate, gives the same intervals.
        local_cover = inscribe.generate(eight, max_spheres=80, kind="cover", evaluate=False)
        uploaded = client.put_certified_cover(local_cover, local_cover.certificate)
        # Spheres edited after they were certified do not take the certificate.
        for scale in (1.03, 0.97):
            edited = local_cover.spheres * np.array([1.0, 1.0, 1.0, scale])
            with pytest.raises(ValueError, match="edited after they were certified"):
                client.put_certified_cover(edited, local_cover.certificate)
        again = client.distance(internal.sphere_set_key, internal.sphere_set_key, poses,
                                cover_a=uploaded, cover_b=uploaded, closer_than=0.2)
        assert np.array_equal(again.lower, ours.lower)
        # Without a threshold every answer is undecided, as in-process.
        unasked = client.distance(internal.sphere_set_key, internal.sphere_set_key, poses,
                                  cover_a=uploaded, cover_b=uploaded)
        assert unasked.answers == inscribe.certified_distance(local, local, poses).closer
        identity = np.array([1.0, 0, 0, 0, 0, 0, 0])
        with client.open_distance_session() as session:
            reply = session.query([(internal.sphere_set_key, internal.sphere_set_key, identity,
                                    poses[0], cover.sphere_set_key, cover.sphere_set_key)])
            assert reply.lower[0] == ours.lower[0] and reply.upper[0] == ours.upper[0]


def test_progress_and_deadlines(server):
    bunny = inscribe.load_mesh(mesh_path("bunny00.off"))
    with inscribe.Client(server.address) as client:
        with pytest.raises(inscribe.Error) as raised:
            client.generate(bunny, max_spheres=450, timeout=0.3)
        assert raised.value.code == "DEADLINE_EXCEEDED"
        seen = []
        client.generate(bunny, max_spheres=450, progress=seen.append, progress_interval=0.05)
        assert seen and seen == sorted(seen) and 0.0 <= seen[0] and seen[-1] <= 1.0


def test_server_errors_map_to_python_exceptions(server, eight):
    with inscribe.Client(server.address) as client:
        with pytest.raises(inscribe.Error) as raised:
            client.get_sphere_set("spheres/v1/" + "0" * 64)
        assert raised.value.code == "NOT_FOUND"
        with pytest.raises(ValueError):
            client.generate(eight, max_spheres=5, voxel_size=0.1)
        with pytest.raises(inscribe.Error) as raised:
            client.put_mesh(inscribe.load_mesh(mesh_path("ChineseDragon-10kv.off")))
        assert raised.value.code == "FAILED_PRECONDITION" and "not closed" in str(raised.value)
        with pytest.raises(TypeError, match="float32"):
            client.distance("a", "b", np.zeros((2, 7), dtype=np.float32))
        with pytest.raises(ValueError, match=r"\(7,\) or \(N, 7\)"):
            client.distance("a", "b", np.zeros((2, 4)))


def test_an_unreachable_server_is_unavailable_after_the_retries(eight):
    client = inscribe.Client(free_dead_endpoint(), timeout=5.0,
                             retry=inscribe.RetryPolicy(max_attempts=3, initial_backoff=0.01))
    with pytest.raises(inscribe.Error) as raised:
        client.put_mesh(eight)
    assert raised.value.code == "UNAVAILABLE" and "gave up after 3 attempts" in str(raised.value)


def test_routing_picks_the_cpp_clients_replica_and_fails_over(tmp_path, eight):
    a, b = Server("--jobs", "1"), Server("--jobs", "1")
    held = []
    try:
        endpoints = [a.address, b.address]
        cli = json.loads(run_cli("generate", mesh_path("eight.off"), "--max-spheres", "40",
                                 "--server", ",".join(endpoints), "--json").stdout)
        # The CLI's call computed the set on one replica only: the one Python must route to.
        computed = {s.address: inscribe.Client(s.address).cache_stats()["computations"]
                    for s in (a, b)}
        owner = a if computed[a.address] > 0 else b
        assert computed[owner.address] > 0 and computed[(b if owner is a else a).address] == 0
        with inscribe.Client(endpoints) as client:
            result = client.generate(eight, max_spheres=40)
            assert result.cache == "memory"  # where the CLI's call computed it
            assert result.sphere_set_key == cli["sphere_set_key"]
            # Sets without a mesh: put where their content routes and, when the key the server
            # answers routes elsewhere, there too, so that they are found by key (8 sets: some
            # move with probability 1 - 2^-8).
            for i in range(8):
                spheres = np.array([[float(i), 0.0, 0.0, 1.0]])
                key = client.put_sphere_set(spheres)
                assert np.array_equal(client.get_sphere_set(key).spheres, spheres)
        # Failover: a dead replica that the mesh routes to first; the call moves on to the
        # live one at once (no backoff), as the C++ client's does.
        route = inscribe._inscribe._route_key(result.mesh_sha256)
        held, dead = dead_endpoint_routed_first(route, owner.address)
        retry = inscribe.RetryPolicy(max_attempts=2, initial_backoff=30.0)
        with inscribe.Client([dead, owner.address], retry=retry, timeout=20.0) as client:
            start = time.monotonic()
            assert client.generate(eight, max_spheres=40).cache == "memory"
            assert time.monotonic() - start < 10.0
        # A distance stream routed to the dead replica is reopened on the next one, its frame
        # resent (a fresh client: nothing is marked down yet).
        with inscribe.Client([dead, owner.address]) as client:
            identity = np.array([1.0, 0, 0, 0, 0, 0, 0])
            shifted = np.array([1.0, 0, 0, 0, 3.0, 0, 0])
            key = result.sphere_set_key
            with client.open_distance_session() as session:
                reply = session.query([(key, key, identity, shifted)])
                local = inscribe.generate(eight, max_spheres=40, evaluate=False)
                assert reply.distance[0] == inscribe.distance(local, local, shifted).distance
    finally:
        if held is not None:
            held.close()
        a.stop()
        b.stop()


def test_bearer_tokens(tmp_path, eight):
    tokens = tmp_path / "tokens"
    tokens.write_text("# test\n" + "s3cret-token-0123456789" + "\n")
    server = Server("--auth-tokens", str(tokens))
    try:
        with inscribe.Client(server.address, token="s3cret-token-0123456789") as client:
            assert client.cache_stats()["entries"] >= 0
        with inscribe.Client(server.address) as client:
            with pytest.raises(inscribe.Error) as raised:
                client.cache_stats()
            assert raised.value.code == "UNAUTHENTICATED"
        with inscribe.Client(server.address, token="wrong-token-0123456789") as client:
            with pytest.raises(inscribe.Error, match="invalid bearer token"):
                client.cache_stats()
    finally:
        server.stop()


def openssl(*args):
    subprocess.run(["openssl", *args], check=True, capture_output=True)


def test_mutual_tls(tmp_path, eight):
    d = tmp_path
    ec = ["-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1", "-nodes"]
    openssl("req", "-x509", *ec, "-days", "2", "-subj", "/CN=ca", "-keyout", d / "ca.key",
            "-out", d / "ca.pem")
    for name, ext in [("server", "subjectAltName=IP:127.0.0.1,DNS:localhost\n"
                                 "extendedKeyUsage=serverAuth\n"),
                      ("client", "extendedKeyUsage=clientAuth\n")]:
        (d / f"{name}.ext").write_text("basicConstraints=CA:FALSE\n" + ext)
        openssl("req", *ec, "-subj", f"/CN={name}", "-keyout", d / f"{name}.key",
                "-out", d / f"{name}.csr")
        openssl("x509", "-req", "-days", "2", "-in", d / f"{name}.csr", "-CA", d / "ca.pem",
                "-CAkey", d / "ca.key", "-set_serial", "2" if name == "server" else "3",
                "-extfile", d / f"{name}.ext", "-out", d / f"{name}.pem")
    server = Server("--tls-cert", str(d / "server.pem"), "--tls-key", str(d / "server.key"),
                    "--tls-client-ca", str(d / "ca.pem"))
    try:
        with inscribe.Client(server.address, ca_file=str(d / "ca.pem"),
                             cert_file=str(d / "client.pem"), key_file=str(d / "client.key")) as c:
            assert c.put_mesh(eight).startswith("sha256:")
        with inscribe.Client(server.address, ca_file=str(d / "ca.pem"), timeout=5.0,
                             retry=inscribe.RetryPolicy(max_attempts=1)) as c:
            with pytest.raises(inscribe.Error):
                c.put_mesh(eight)  # no client certificate
        with inscribe.Client(server.address, timeout=5.0,
                             retry=inscribe.RetryPolicy(max_attempts=1)) as c:
            with pytest.raises(inscribe.Error) as raised:
                c.cache_stats()  # plaintext to a TLS port
            assert raised.value.code == "UNAVAILABLE"
    finally:
        server.stop()


def test_an_endpoint_without_a_port_dials_the_default_one():
    # The one rule (wire::TargetWithDefaultPort), the CLI's and the C++ client's too.
    from inscribe import _inscribe
    assert _inscribe._target_with_default_port("localhost") == "localhost:50051"
    assert _inscribe._target_with_default_port("::1") == "[::1]:50051"
    assert _inscribe._target_with_default_port("localhost:7000") == "localhost:7000"
    assert _inscribe._target_with_default_port("dns:///h:1") == "dns:///h:1"
