"""The Kubernetes manifests of deploy/k8s/ keep their promises: every flag they pass exists (asked
of the built binaries' --help), the memory and disk limits cover the budgets they are derived
from, the probes ask the health service over TLS, pods run unprivileged as the image's user,
the PDB and the headless Service select the replicas, Redis is LRU-bounded below its limit, and
the TLS files and tokens come from Secrets. Each rule is also shown to fail on a manifest broken
on purpose. scripts/kube-for-podman's output is checked too (no podman needed).

  /usr/bin/python3 k8s_manifests_test.py --inscribed PATH --inscribe PATH [unittest args]
"""
import argparse
import base64
import copy
import pathlib
import re
import subprocess
import sys
import tempfile
import unittest

import yaml

SOURCE = pathlib.Path(__file__).resolve().parents[2]
MANIFESTS = SOURCE / "deploy" / "k8s"
BINARIES = {}
MiB = 1 << 20

# Linux's memory accounting (kernel, page tables) and inscribed's ~25 MB baseline.
BASELINE = 64 * MiB


def load_manifests():
    documents = []
    for path in sorted(MANIFESTS.glob("*.yaml")):
        with open(path, encoding="utf-8") as stream:
            documents.extend(d for d in yaml.safe_load_all(stream) if d)
    return documents


def quantity(text):
    """Bytes (or cores) of a Kubernetes quantity: 4Gi, 1536Mi, 250m, 2, 1e3, 1G."""
    text = str(text)
    suffixes = {"Ki": 1 << 10, "Mi": 1 << 20, "Gi": 1 << 30, "Ti": 1 << 40,
                "k": 10**3, "M": 10**6, "G": 10**9, "T": 10**12, "m": 0.001}
    for suffix, factor in suffixes.items():
        if text.endswith(suffix):
            return float(text[: -len(suffix)]) * factor
    return float(text)


def redis_bytes(text):
    """Redis's memory units: 1gb = 1024^3, 1g = 10^9, plain bytes."""
    match = re.fullmatch(r"(\d+)(b|k|kb|m|mb|g|gb)?", str(text).lower())
    assert match, f"not a Redis memory size: {text}"
    units = {None: 1, "b": 1, "k": 10**3, "kb": 1 << 10, "m": 10**6, "mb": 1 << 20,
             "g": 10**9, "gb": 1 << 30}
    return int(match.group(1)) * units[match.group(2)]


def find(documents, kind, name=None):
    found = [d for d in documents if d["kind"] == kind
             and (name is None or d["metadata"]["name"] == name)]
    assert len(found) == 1, f"expected one {kind} {name or ''}, found {len(found)}"
    return found[0]


def flags_of(args):
    """{--flag: value} of an argument list where every flag takes one value."""
    assert len(args) % 2 == 0, f"odd argument list {args}"
    flags = {}
    for name, value in zip(args[::2], args[1::2]):
        assert name.startswith("--"), f"{name!r} is not a flag (arguments go flag, value)"
        assert name not in flags, f"{name} given twice"
        flags[name] = str(value)
    return flags


def help_flags(*command):
    """The long flags a CLI11 --help lists."""
    text = subprocess.run([*command, "--help"], check=True, capture_output=True, text=True).stdout
    return set(re.findall(r"^\s+(?:-\w,)?(--[a-z][a-z0-9-]*)", text, re.MULTILINE))


def image_uid():
    dockerfile = (SOURCE / "docker" / "Dockerfile").read_text(encoding="utf-8")
    return int(re.search(r"useradd [^\n]*--uid (\d+)[^\n]* inscribe\b", dockerfile).group(1))


def container(workload, name):
    spec = workload["spec"]["template"]["spec"]
    return next(c for c in spec["containers"] if c["name"] == name)


def mounts_by_path(workload, container_spec):
    volumes = {v["name"]: v for v in workload["spec"]["template"]["spec"]["volumes"]}
    return {m["mountPath"]: (m, volumes[m["name"]]) for m in container_spec["volumeMounts"]}


def volume_holding(workload, container_spec, path):
    """The (mount, volume) whose mountPath holds the file or directory path."""
    best = None
    for mount_path, pair in mounts_by_path(workload, container_spec).items():
        if path == mount_path or path.startswith(mount_path.rstrip("/") + "/"):
            if best is None or len(mount_path) > len(best[0]):
                best = (mount_path, pair)
    assert best, f"{path} is on no volume (the root filesystem is read-only)"
    return best[1]


# ---- the rules ---------------------------------------------------------------------------

def check_inscribed_flags(documents):
    sts = find(documents, "StatefulSet", "inscribed")
    server = container(sts, "inscribed")
    assert server["command"] == ["/usr/local/bin/inscribed"], server["command"]
    known = help_flags(BINARIES["inscribed"])
    flags = flags_of(server["args"])
    unknown = sorted(set(flags) - known)
    assert not unknown, f"inscribed --help does not list {unknown}"
    for probe in ("readinessProbe", "livenessProbe"):
        command = server[probe]["exec"]["command"]
        assert command[:2] == ["/usr/local/bin/inscribe", "health"], command
        probe_known = help_flags(BINARIES["inscribe"], "health")
        unknown = sorted(set(flags_of(command[2:])) - probe_known)
        assert not unknown, f"inscribe health --help does not list {unknown} ({probe})"
    return flags


def check_inscribed_resources(documents):
    sts = find(documents, "StatefulSet", "inscribed")
    server = container(sts, "inscribed")
    flags = flags_of(server["args"])
    limits, requests = server["resources"]["limits"], server["resources"]["requests"]
    message = int(flags["--max-message-bytes"])
    jobs = int(flags["--jobs"])
    memory_volumes = sum(quantity(v["emptyDir"]["sizeLimit"])
                         for v in sts["spec"]["template"]["spec"]["volumes"]
                         if v.get("emptyDir", {}).get("medium") == "Memory")
    need = (int(flags["--memory-budget"]) + int(flags["--cache-memory-bytes"]) + 2 * message
            + BASELINE + memory_volumes)
    assert int(flags["--memory-budget"]) > 0, "an unlimited --memory-budget bounds nothing"
    assert quantity(limits["memory"]) >= need, (
        f"memory limit {limits['memory']} < {need / MiB:.0f} MiB (budget + cache + messages "
        "+ baseline + memory-backed volumes)")
    assert quantity(requests["memory"]) <= quantity(limits["memory"]), "request above limit"
    assert 0 < jobs <= quantity(limits["cpu"]), f"--jobs {jobs} exceeds the CPU limit"

    disk = int(flags["--cache-disk-bytes"])
    assert disk > 0, "an unbounded disk cache would outgrow any emptyDir"
    mount, volume = volume_holding(sts, server, flags["--cache-dir"])
    assert mount["mountPath"] == flags["--cache-dir"], "the cache directory is not a volume"
    size = quantity(volume["emptyDir"]["sizeLimit"])
    assert size >= disk + (jobs + 1) * message, (
        f"cache emptyDir sizeLimit {volume['emptyDir']['sizeLimit']} < --cache-disk-bytes + "
        "(--jobs + 1) x --max-message-bytes")
    if "ephemeral-storage" in limits:
        assert quantity(limits["ephemeral-storage"]) >= size, "ephemeral-storage < sizeLimit"

    grace = sts["spec"]["template"]["spec"]["terminationGracePeriodSeconds"]
    assert grace >= float(flags["--shutdown-grace"]) + 5, (
        f"terminationGracePeriodSeconds {grace} < --shutdown-grace + 5")


def check_inscribed_probes(documents):
    sts = find(documents, "StatefulSet", "inscribed")
    server = container(sts, "inscribed")
    flags = flags_of(server["args"])
    port = int(flags["--listen"].rsplit(":", 1)[1])
    ports = {p["name"]: p["containerPort"] for p in server["ports"]}
    assert ports["grpc"] == port, f"--listen port {port} != containerPort grpc {ports['grpc']}"
    assert ports["metrics"] == int(flags["--metrics-listen"].rsplit(":", 1)[1])
    for name in ("readinessProbe", "livenessProbe"):
        probe = server[name]
        probe_flags = flags_of(probe["exec"]["command"][2:])
        assert probe_flags["--server"] == f"127.0.0.1:{port}", f"{name} asks another port"
        if "--tls-cert" in flags:
            ca = probe_flags.get("--tls-ca")
            assert ca, f"{name} would speak plaintext to a TLS port"
            _, volume = volume_holding(sts, server, ca)
            assert "secret" in volume, f"{name}'s CA {ca} is not from a Secret"
        assert float(probe_flags["--timeout"]) < probe.get("timeoutSeconds", 1), (
            f"{name}: the CLI's --timeout must end before the kubelet's timeoutSeconds")


def check_security(documents):
    uid = image_uid()
    for kind, name in (("StatefulSet", "inscribed"), ("Deployment", "inscribe-redis")):
        workload = find(documents, kind, name)
        spec = workload["spec"]["template"]["spec"]
        pod = spec["securityContext"]
        assert pod["runAsNonRoot"] is True, f"{name}: runAsNonRoot"
        assert pod["runAsUser"] > 0, f"{name}: runs as root"
        assert spec.get("automountServiceAccountToken") is False, f"{name}: API token mounted"
        for c in spec["containers"]:
            context = c["securityContext"]
            assert context["allowPrivilegeEscalation"] is False, f"{name}: privilege escalation"
            assert context["readOnlyRootFilesystem"] is True, f"{name}: writable root"
            assert context["capabilities"]["drop"] == ["ALL"], f"{name}: capabilities kept"
            assert "privileged" not in context or context["privileged"] is False
            image = c["image"]
            assert "." not in image.split("/")[0] and not re.match(r"^[^/]+:\d+/", image), (
                f"{name}: {image} names a registry host")
    pod = find(documents, "StatefulSet", "inscribed")["spec"]["template"]["spec"]
    assert pod["securityContext"]["runAsUser"] == uid, (
        f"inscribed runs as {pod['securityContext']['runAsUser']}, the image's user is {uid}")


def check_secrets(documents):
    sts = find(documents, "StatefulSet", "inscribed")
    server = container(sts, "inscribed")
    flags = flags_of(server["args"])
    expected = {"--tls-cert": ("inscribed-tls", "tls.crt"), "--tls-key": ("inscribed-tls", "tls.key"),
                "--auth-tokens": ("inscribed-tokens", "tokens")}
    for flag, (secret, key) in expected.items():
        assert flag in flags, f"inscribed runs without {flag}"
        mount, volume = volume_holding(sts, server, flags[flag])
        assert volume.get("secret", {}).get("secretName") == secret, f"{flag} is not from {secret}"
        assert flags[flag] == f"{mount['mountPath']}/{key}", f"{flag} is not key {key}"
        assert mount.get("readOnly") is True, f"{secret} is mounted writable"
        assert "subPath" not in mount, f"{secret}: a subPath mount never sees an updated Secret"
    for mount_path, (mount, volume) in mounts_by_path(sts, server).items():
        if "secret" in volume:
            assert volume["secret"].get("optional") is False, (
                f"{mount_path}: say optional: false (podman 4.3 crashes without it)")
    env = {e["name"]: e["value"] for e in server.get("env", [])}
    _, tmp = volume_holding(sts, server, env["TMPDIR"] + "/inscribed-tls-x")
    assert "emptyDir" in tmp, "TMPDIR (the TLS files' private copy) is not a writable emptyDir"


def check_service_and_pdb(documents):
    sts = find(documents, "StatefulSet", "inscribed")
    labels = sts["spec"]["template"]["metadata"]["labels"]
    service = find(documents, "Service", sts["spec"]["serviceName"])
    assert service["spec"].get("clusterIP") == "None", "the Service is not headless"
    assert service["spec"]["selector"].items() <= labels.items(), "Service selects no replica"
    ports = {p["name"] for p in container(sts, "inscribed")["ports"]}
    for port in service["spec"]["ports"]:
        assert port["targetPort"] in ports, f"Service port {port['name']} targets nothing"
    assert sts["spec"]["selector"]["matchLabels"].items() <= labels.items()
    pdb = find(documents, "PodDisruptionBudget", "inscribed")
    assert pdb["spec"]["selector"]["matchLabels"].items() <= labels.items(), (
        "the PodDisruptionBudget selects no replica")
    assert pdb["spec"]["selector"] == sts["spec"]["selector"], "PDB and StatefulSet differ"
    allowed = pdb["spec"].get("maxUnavailable", 0)
    assert 0 < allowed < sts["spec"]["replicas"], "the PDB must leave a replica serving"


def check_redis(documents):
    deployment = find(documents, "Deployment", "inscribe-redis")
    redis = container(deployment, "redis")
    flags = flags_of(redis["args"])
    assert flags["--maxmemory-policy"] == "allkeys-lru", "Redis must evict any key (LRU)"
    assert flags["--save"] == "" and flags["--appendonly"] == "no", "Redis persists"
    maxmemory = redis_bytes(flags["--maxmemory"])
    limit = quantity(redis["resources"]["limits"]["memory"])
    assert limit >= 1.25 * maxmemory + BASELINE, (
        f"Redis memory limit {redis['resources']['limits']['memory']} < 1.25 x maxmemory + 64 MiB")
    service = find(documents, "Service", "inscribe-redis")
    labels = deployment["spec"]["template"]["metadata"]["labels"]
    assert service["spec"]["selector"].items() <= labels.items(), "Redis Service selects nothing"
    url = flags_of(container(find(documents, "StatefulSet", "inscribed"), "inscribed")["args"])
    match = re.fullmatch(r"redis://([^:/]+):(\d+)", url["--redis"])
    assert match, f"--redis {url['--redis']}"
    assert match.group(1) == service["metadata"]["name"], "--redis names another Service"
    assert int(match.group(2)) == service["spec"]["ports"][0]["port"], "--redis port"
    assert int(flags["--port"]) == redis["ports"][0]["containerPort"]


RULES = [check_inscribed_flags, check_inscribed_resources, check_inscribed_probes,
         check_security, check_secrets, check_service_and_pdb, check_redis]


def args_set(documents, flag, value):
    args = container(find(documents, "StatefulSet", "inscribed"), "inscribed")["args"]
    args[args.index(flag) + 1] = value


class ManifestsTest(unittest.TestCase):
    def setUp(self):
        self.documents = load_manifests()

    def test_every_rule_holds(self):
        for rule in RULES:
            with self.subTest(rule=rule.__name__):
                rule(self.documents)

    def assert_breaks(self, rule, change, message):
        documents = copy.deepcopy(self.documents)
        change(documents)
        with self.assertRaisesRegex(AssertionError, message):
            rule(documents)

    def test_each_rule_can_fail(self):
        sts = lambda d: find(d, "StatefulSet", "inscribed")
        spec = lambda d: sts(d)["spec"]["template"]["spec"]
        server = lambda d: container(sts(d), "inscribed")
        redis = lambda d: container(find(d, "Deployment", "inscribe-redis"), "redis")
        cases = [
            (check_inscribed_flags, lambda d: server(d)["args"].extend(["--no-such-flag", "1"]),
             "does not list"),
            (check_inscribed_flags, lambda d: server(d)["readinessProbe"]["exec"]["command"]
             .extend(["--verbose", "1"]), "does not list"),
            (check_inscribed_resources, lambda d: args_set(d, "--memory-budget", "4294967296"),
             "memory limit"),
            (check_inscribed_resources, lambda d: args_set(d, "--cache-disk-bytes", "6000000000"),
             "sizeLimit"),
            (check_inscribed_resources, lambda d: args_set(d, "--jobs", "8"), "CPU limit"),
            (check_inscribed_resources, lambda d: args_set(d, "--shutdown-grace", "60"),
             "terminationGracePeriodSeconds"),
            (check_inscribed_probes, lambda d: args_set(d, "--listen", "0.0.0.0:6000"),
             "containerPort"),
            (check_inscribed_probes, lambda d: server(d)["livenessProbe"]["exec"]["command"]
             .__setitem__(slice(4, 6), []), "plaintext"),
            (check_security, lambda d: spec(d)["securityContext"].__setitem__("runAsUser", 1000),
             "image's user"),
            (check_security, lambda d: server(d)["securityContext"]["capabilities"]
             .__setitem__("drop", ["NET_RAW"]), "capabilities"),
            (check_security, lambda d: redis(d)["securityContext"]
             .__setitem__("readOnlyRootFilesystem", False), "writable root"),
            (check_security, lambda d: server(d).__setitem__("image", "registry.example:5000/x"),
             "registry host"),
            (check_secrets, lambda d: server(d)["volumeMounts"][2].__setitem__("readOnly", False),
             "writable"),
            (check_secrets, lambda d: spec(d)["volumes"][2]["secret"]
             .__setitem__("secretName", "other"), "not from inscribed-tls"),
            (check_service_and_pdb, lambda d: find(d, "Service", "inscribed")["spec"]
             .__setitem__("clusterIP", "10.0.0.9"), "headless"),
            (check_service_and_pdb, lambda d: find(d, "PodDisruptionBudget", "inscribed")["spec"]
             ["selector"]["matchLabels"].__setitem__("app.kubernetes.io/name", "x"), "PodDisruption"),
            (check_redis, lambda d: redis(d)["args"].__setitem__(-1, "noeviction"), "LRU"),
            (check_redis, lambda d: redis(d)["resources"]["limits"].__setitem__("memory", "1Gi"),
             "memory limit"),
            (check_redis, lambda d: args_set(d, "--redis", "redis://redis:6379"), "another Service"),
        ]
        for rule, change, message in cases:
            with self.subTest(rule=rule.__name__, message=message):
                self.assert_breaks(rule, change, message)


class PodmanTransformTest(unittest.TestCase):
    """scripts/kube-for-podman: the StatefulSet as the controller's Pods, Secrets as files."""

    def run_transform(self, *args):
        return subprocess.run(["/usr/bin/python3", str(SOURCE / "scripts" / "kube-for-podman"),
                               *args, "--manifests", str(MANIFESTS)],
                              check=True, capture_output=True, text=True).stdout

    def test_statefulset_becomes_pods_with_own_volumes_and_secret_files(self):
        with tempfile.TemporaryDirectory() as work:
            secrets = pathlib.Path(work) / "secrets.yaml"
            encoded = {k: base64.b64encode(k.encode()).decode()
                       for k in ("tls.crt", "tls.key", "ca.crt", "tokens")}
            secrets.write_text(yaml.safe_dump_all([
                {"kind": "Secret", "metadata": {"name": "inscribed-tls"},
                 "data": {k: encoded[k] for k in ("tls.crt", "tls.key", "ca.crt")}},
                {"kind": "Secret", "metadata": {"name": "inscribed-tokens"},
                 "data": {"tokens": encoded["tokens"]}}]))
            out = self.run_transform("pods", "--only", "StatefulSet/inscribed",
                                     "--secrets", str(secrets), "--secrets-dir", work,
                                     "--image", "inscribe:dev=inscribe:test",
                                     "--host-alias", "inscribe-redis=10.0.0.7")
            pods = list(yaml.safe_load_all(out))
            replicas = find(load_manifests(), "StatefulSet", "inscribed")["spec"]["replicas"]
            self.assertEqual([p["metadata"]["name"] for p in pods],
                             [f"inscribed-{i}" for i in range(replicas)])
            volume_names = set()
            for pod in pods:
                spec = pod["spec"]
                self.assertEqual(pod["kind"], "Pod")
                self.assertEqual(spec["hostname"], pod["metadata"]["name"])
                self.assertEqual(spec["subdomain"], "inscribed")
                self.assertEqual(spec["containers"][0]["image"], "inscribe:test")
                self.assertEqual(spec["hostAliases"],
                                 [{"ip": "10.0.0.7", "hostnames": ["inscribe-redis"]}])
                for volume in spec["volumes"]:
                    self.assertNotIn("secret", volume)
                    if "hostPath" in volume:
                        path = pathlib.Path(volume["hostPath"]["path"])
                        for file in path.iterdir():
                            self.assertEqual(file.read_text(), file.name)  # decoded
                    else:
                        self.assertNotIn(volume["name"], volume_names)  # one per pod
                        volume_names.add(volume["name"])
                mounted = {m["name"] for m in spec["containers"][0]["volumeMounts"]}
                self.assertEqual(mounted, {v["name"] for v in spec["volumes"]})

    def test_probe_and_names(self):
        probe = self.run_transform("probe", "--only", "StatefulSet/inscribed").split("\0")
        self.assertEqual(probe[:2], ["/usr/local/bin/inscribe", "health"])
        self.assertEqual(self.run_transform("pod-names", "--only", "Deployment/inscribe-redis")
                         .split(), ["inscribe-redis-pod-0"])


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--inscribed", required=True, help="the built inscribed")
    parser.add_argument("--inscribe", required=True, help="the built inscribe CLI")
    known, rest = parser.parse_known_args()
    BINARIES.update(inscribed=known.inscribed, inscribe=known.inscribe)
    unittest.main(argv=[sys.argv[0], *rest])
