#!/usr/bin/env python3
"""Deploy.Files: the deployment files agree with the programs and with each other.

usage: check_deploy_files.py --source DIR --server BIN --worker BIN [--pending FILE]

  --source   the repository (deploy/, tests/deploy/pending_flags.txt)
  --server   the built skyfarm-server: its --help lists the flags it takes, and
             a short run on loopback answers /healthz and lists /metrics
  --worker   the built skyfarm-worker: its --help lists the farm flags
  --pending  agreed flags and variables that other changes add (default:
             tests/deploy/pending_flags.txt): accepted while missing from --help;
             an entry that --help lists is an error, so the list empties itself

What is checked (every failure is printed; exit 1 if any):
  every flag in a container's args, a compose command, a unit's ExecStart= is
  one the program's --help lists, with a value; every SKYFARM_ variable set
  anywhere is one the program reads; Kubernetes: kustomization.yaml lists the
  files (one autoscaler), Services and the PodDisruptionBudget select pods
  that exist, by ports they have; probes ask /healthz on the --listen port;
  the volume claim is mounted at --data-dir; every secret (and key) used exists
  in secrets.example.yaml and secret-file flags point into a mounted secret;
  workers connect to the broker Service and port; their grace period exceeds
  the server's --unit-timeout; the autoscalers name metrics the server
  exports; the pods' uid is the image's.  Compose: the same for services,
  secrets, volumes, the health check's port.  Dockerfile: Debian bookworm
  stages, non-root USER, HEALTHCHECK, VOLUME at the data dir, EXPOSE the ports,
  COPY sources that exist.  systemd: credentials the units use are loaded.
  yaml comes from python3-yaml; `kubectl kustomize` renders the kustomization
  where kubectl is installed.
"""
import argparse
import glob
import json
import os
import re
import shlex
import shutil
import subprocess
import sys
import urllib.request

import yaml

from idle_server import idle_server

DEFAULT_UNIT_TIMEOUT_S = 120.0
DATA_DIR = "/var/lib/skyfarm"
NOT_IN_KUSTOMIZATION = {"secrets.example.yaml", "hpa-external.yaml", "servicemonitor.yaml"}
AUTOSCALERS = {"keda-scaledobject.yaml", "hpa-external.yaml"}
# Variables the image's entry point reads (deploy/docker/entrypoint.sh), not the programs.
ENTRYPOINT_VARS = {"SKYFARM_TOKEN_FILE"}
# Variables of the image's health check (deploy/docker/healthcheck.sh).
HEALTHCHECK_VARS = {"SKYFARM_HEALTH_PORT"}
# Farm flags that take no value.
NO_VALUE_FLAGS = {"--help", "--version"}

errors = []
notes = []


def error(where, text):
    errors.append(f"{where}: {text}")


# --- The programs ----------------------------------------------------------

FLAG_RE = re.compile(r"(?<![\w-])--[a-z][a-z0-9-]*")


def help_text(binary):
    env = {k: v for k, v in os.environ.items() if not k.startswith("SKYFARM_")}
    out = subprocess.run([binary, "--help"], capture_output=True, text=True, timeout=30, env=env)
    if out.returncode != 0:
        sys.exit(f"{binary} --help exited {out.returncode}: {out.stderr}")
    return out.stdout + out.stderr


class Program:
    """What a program accepts: flags from its --help, variables it names."""

    def __init__(self, name, text, pending):
        self.name = name
        self.text = text
        if name == "skyfarm-worker":
            # The farm mode's flags only, not those of render/probe/...
            m = re.search(r"farm worker.*?\n(.*?)\ncommands:", text, re.S)
            if m:
                text = m.group(1)
        self.flags = set(FLAG_RE.findall(text)) | NO_VALUE_FLAGS
        self.vars = set(re.findall(r"SKYFARM_[A-Z0-9_]+", self.text))
        self.pending = pending.get(name, set())
        for p in sorted(self.pending):
            if p in self.flags or p in self.vars:
                error("pending_flags.txt", f"{name} {p} is in {name} --help now: delete its line")
        self.used_pending = set()

    def accepts_flag(self, flag):
        if flag in self.flags:
            return True
        if flag in self.pending:
            self.used_pending.add(flag)
            return True
        return False

    def accepts_var(self, var):
        if var in self.vars:
            return True
        flag = "--" + var[len("SKYFARM_"):].lower().replace("_", "-")
        if flag in self.flags:
            return True
        if var in self.pending or flag in self.pending:
            self.used_pending.add(var if var in self.pending else flag)
            return True
        return False


def read_pending(path):
    pending = {}
    if not os.path.exists(path):
        return pending
    for line in open(path, encoding="utf-8"):
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        program, name = line.split()
        pending.setdefault(program, set()).add(name)
    return pending


def parse_args(program, args, where):
    """{flag: value} of a farm command line; reports unknown flags and stray words."""
    values = {}
    i = 0
    while i < len(args):
        a = str(args[i])
        if not a.startswith("--"):
            error(where, f"unexpected argument '{a}' (not a flag value)")
            i += 1
            continue
        flag, eq, value = a.partition("=")
        if not program.accepts_flag(flag):
            error(where, f"{flag} is not a flag of {program.name} (its --help lists {sorted(program.flags)})")
        if flag in NO_VALUE_FLAGS:
            values[flag] = ""
            i += 1
            continue
        if not eq:
            if i + 1 >= len(args) or str(args[i + 1]).startswith("--"):
                error(where, f"{flag} needs a value")
                value = ""
            else:
                value = str(args[i + 1])
                i += 1
        values[flag] = value
        i += 1
    return values


def port_of(address):
    """8080 of HOST:8080 or tcp://HOST:8080; None if there is none."""
    m = re.search(r":(\d+)$", address or "")
    return int(m.group(1)) if m else None


def seconds(value):
    """Seconds of 300, "300", "300s", "5m", "1m30s"."""
    if isinstance(value, (int, float)):
        return float(value)
    total, rest = 0.0, str(value).strip()
    for number, unit in re.findall(r"(\d+(?:\.\d+)?)(h|ms|m|s|us)?", rest):
        total += float(number) * {"h": 3600, "m": 60, "s": 1, "ms": 1e-3, "us": 1e-6, "": 1}[unit or ""]
    return total


# --- A running server: /healthz and the metric names of /metrics ----------

def served_metrics(server_binary):
    with idle_server(server_binary) as url:
        with urllib.request.urlopen(url + "/healthz", timeout=2) as r:
            if r.status != 200 or json.load(r).get("status") != "ok":
                error("skyfarm-server", f"/healthz answered {r.status}")
        try:
            with urllib.request.urlopen(url + "/metrics", timeout=5) as r:
                text = r.read().decode()
        except (OSError, ValueError) as e:
            sys.exit(f"skyfarm-server gave no /metrics ({e})")
    names = set()
    for line in text.splitlines():
        m = re.match(r"# TYPE (\S+)", line) or re.match(r"([a-zA-Z_:][a-zA-Z0-9_:]*)", line)
        if m:
            names.add(m.group(1))
    return names


def check_query(query, metrics, where):
    used = set(re.findall(r"skyfarm_[a-z0-9_]+", query))
    if "skyfarm_queue_units" not in used:
        error(where, f"the query does not use skyfarm_queue_units: {query}")
    for name in sorted(used - metrics):
        error(where, f"{name} is not a metric skyfarm-server exports on /metrics")


# --- Kubernetes --------------------------------------------------------------

def load_k8s(k8s_dir):
    objects = []  # (file, object)
    for path in sorted(glob.glob(os.path.join(k8s_dir, "*.yaml"))):
        name = os.path.basename(path)
        if name == "kustomization.yaml":
            continue
        for doc in yaml.safe_load_all(open(path, encoding="utf-8")):
            if doc:
                objects.append((name, doc))
    return objects


def selects(selector, labels):
    return bool(selector) and all(labels.get(k) == v for k, v in selector.items())


def container_ports(container):
    return {p.get("name"): p["containerPort"] for p in container.get("ports", [])}


def resolve_port(port, ports, where):
    if isinstance(port, int):
        return port
    if port not in ports:
        error(where, f"port '{port}' is not a port of the container ({sorted(ports)})")
        return None
    return ports[port]


def check_k8s(source, programs, metrics):
    k8s_dir = os.path.join(source, "deploy", "k8s")
    objects = load_k8s(k8s_dir)
    kust = yaml.safe_load(open(os.path.join(k8s_dir, "kustomization.yaml"), encoding="utf-8"))
    # kubectl is no Debian package: kustomize's own rendering only where it is installed.
    kubectl = shutil.which("kubectl")
    if kubectl:
        out = subprocess.run([kubectl, "kustomize", k8s_dir], capture_output=True, text=True, timeout=60)
        if out.returncode != 0:
            error("kustomization.yaml", f"kubectl kustomize failed: {out.stderr.strip()}")
    else:
        notes.append("kubectl is not installed: kustomization.yaml not rendered by kustomize")

    # kustomization.yaml: the files, one autoscaler, the namespace.
    listed = set(kust.get("resources", []))
    files = {os.path.basename(p) for p in glob.glob(os.path.join(k8s_dir, "*.yaml"))} - {"kustomization.yaml"}
    for r in sorted(listed - files):
        error("kustomization.yaml", f"resource {r} does not exist")
    for f in sorted(files - listed - NOT_IN_KUSTOMIZATION):
        error("kustomization.yaml", f"{f} is not listed")
    for f in sorted(listed & (NOT_IN_KUSTOMIZATION - AUTOSCALERS)):
        error("kustomization.yaml", f"{f} must not be listed (see its header)")
    if len(listed & AUTOSCALERS) != 1:
        error("kustomization.yaml", f"list exactly one of {sorted(AUTOSCALERS)}")
    namespaces = [o["metadata"]["name"] for _, o in objects if o.get("kind") == "Namespace"]
    if namespaces != [kust.get("namespace")]:
        error("kustomization.yaml", f"namespace {kust.get('namespace')} is not the Namespace object's {namespaces}")
    for f, o in objects:
        ns = o.get("metadata", {}).get("namespace")
        if ns is not None and ns != kust.get("namespace"):
            error(f, f"{o['kind']} {o['metadata']['name']} in namespace {ns}")

    by_kind = {}
    for f, o in objects:
        by_kind.setdefault(o["kind"], []).append((f, o))

    secrets = {}
    for f, o in by_kind.get("Secret", []):
        secrets[o["metadata"]["name"]] = set(o.get("stringData", {})) | set(o.get("data", {}))

    workloads = by_kind.get("StatefulSet", []) + by_kind.get("Deployment", [])
    pods = []  # (where, workload, labels, container, program, flags)
    for f, w in workloads:
        name = w["metadata"]["name"]
        where = f"{f} {w['kind']} {name}"
        spec = w["spec"]
        template = spec["template"]
        labels = template["metadata"].get("labels", {})
        if not selects(spec["selector"].get("matchLabels", {}), labels):
            error(where, "selector.matchLabels do not select the pod template's labels")
        pod = template["spec"]
        volumes = {v["name"]: v for v in pod.get("volumes", [])}
        for c in pod["containers"]:
            cwhere = f"{where} container {c['name']}"
            command = c.get("command") or []
            program = programs.get(os.path.basename(str(command[0]))) if command else None
            if program is None:
                error(cwhere, "command must be [skyfarm-server] or [skyfarm-worker]")
                continue
            flags = parse_args(program, list(command[1:]) + list(c.get("args", [])), cwhere)
            for e in c.get("env", []):
                var = e["name"]
                if var in ENTRYPOINT_VARS:
                    error(cwhere, f"{var} is read by the image's entry point, which command: replaces")
                elif var.startswith("SKYFARM_") and not program.accepts_var(var):
                    error(cwhere, f"{var} is not a variable of {program.name}")
                ref = e.get("valueFrom", {}).get("secretKeyRef")
                if ref and ref.get("key") not in secrets.get(ref.get("name"), set()):
                    error(cwhere, f"secret {ref.get('name')} key {ref.get('key')} is not in secrets.example.yaml")
            requests = c.get("resources", {}).get("requests", {})
            if "cpu" not in requests or "memory" not in requests:
                error(cwhere, "resources.requests needs cpu and memory")
            if not pod.get("securityContext", {}).get("runAsNonRoot"):
                error(cwhere, "the pod must set securityContext.runAsNonRoot")
            mounts = c.get("volumeMounts", [])
            for m in mounts:
                if m["name"] not in volumes and m["name"] not in {
                        t["metadata"]["name"] for t in spec.get("volumeClaimTemplates", [])}:
                    error(cwhere, f"volumeMount {m['name']} has no volume")
            # Files a flag names must come from a mounted secret holding that key.
            for flag in ("--worker-secret-file", "--secret-file", "--server-key-file", "--key-file"):
                if flag in flags:
                    check_secret_file(flags[flag], flag, mounts, volumes, secrets, cwhere)
            pods.append((where, w, labels, c, program, flags, mounts))

    servers = [p for p in pods if p[4].name == "skyfarm-server"]
    workers = [p for p in pods if p[4].name == "skyfarm-worker"]
    if len(servers) != 1 or servers[0][1]["kind"] != "StatefulSet" or servers[0][1]["spec"].get("replicas") != 1:
        error("k8s", "skyfarm-server must run in one StatefulSet of 1 replica")
    if not workers or workers[0][1]["kind"] != "Deployment":
        error("k8s", "skyfarm-worker must run in a Deployment")
    services = {o["metadata"]["name"]: (f, o) for f, o in by_kind.get("Service", [])}

    unit_timeout = DEFAULT_UNIT_TIMEOUT_S
    for where, w, labels, c, program, flags, mounts in servers:
        unit_timeout = float(flags.get("--unit-timeout", DEFAULT_UNIT_TIMEOUT_S))
        ports = container_ports(c)
        listen = port_of(flags.get("--listen"))
        broker = port_of(flags.get("--broker"))
        if not flags.get("--listen", "").startswith("0.0.0.0:"):
            error(where, "--listen must bind 0.0.0.0 so that Services reach it")
        if flags.get("--local-workers") != "0":
            error(where, "--local-workers must be 0 (the worker Deployment renders)")
        if ports.get("http") != listen:
            error(where, f"container port 'http' {ports.get('http')} is not --listen's {listen}")
        if ports.get("broker") != broker:
            error(where, f"container port 'broker' {ports.get('broker')} is not --broker's {broker}")
        for probe in ("readinessProbe", "livenessProbe", "startupProbe"):
            p = c.get(probe)
            if p is None:
                if probe != "startupProbe":
                    error(where, f"{probe} is missing")
                continue
            get = p.get("httpGet", {})
            if get.get("path") != "/healthz":
                error(where, f"{probe} must GET /healthz, not {get.get('path')}")
            if resolve_port(get.get("port"), ports, f"{where} {probe}") != listen:
                error(where, f"{probe} port {get.get('port')} is not the --listen port {listen}")
        claims = {t["metadata"]["name"] for t in w["spec"].get("volumeClaimTemplates", [])}
        data_mounts = [m["mountPath"] for m in mounts if m["name"] in claims]
        if not claims or data_mounts != [flags.get("--data-dir")]:
            error(where, f"the volume claim template must be mounted at --data-dir {flags.get('--data-dir')}"
                  f" (mounted at {data_mounts})")
        if not any(e["name"] == "SKYFARM_TOKEN" for e in c.get("env", [])) and "--token" not in flags:
            error(where, "a server listening beyond loopback needs the HTTP token (SKYFARM_TOKEN)")

    # Services: select a workload's pods, target ports they have.
    for name, (f, s) in services.items():
        selected = [p for p in pods if selects(s["spec"].get("selector", {}), p[2])]
        if not selected:
            error(f"{f} Service {name}", "selects no pod")
            continue
        for sp in s["spec"]["ports"]:
            resolve_port(sp.get("targetPort", sp["port"]), container_ports(selected[0][3]), f"{f} Service {name}")

    for where, w, labels, c, program, flags, mounts in workers:
        url = flags.get("--connect", "")
        m = re.match(r"tcp://([^:/]+):(\d+)$", url)
        if not m:
            error(where, f"--connect must be tcp://SERVICE:PORT, not '{url}'")
        elif m.group(1) not in services:
            error(where, f"--connect names {m.group(1)}, which is not a Service")
        else:
            f, s = services[m.group(1)]
            port = [p for p in s["spec"]["ports"] if p["port"] == int(m.group(2))]
            target = None
            if port and servers:
                target = resolve_port(port[0].get("targetPort", port[0]["port"]), container_ports(servers[0][3]),
                                      f"{f} Service {m.group(1)}")
            if not servers or target != port_of(servers[0][5].get("--broker")):
                error(where, f"--connect {url} does not reach the server's --broker")
        if "--secret-file" not in flags and "--key-file" not in flags:
            error(where, "a worker needs --secret-file (or --key-file) to join a broker beyond loopback")
        grace = w["spec"]["template"]["spec"].get("terminationGracePeriodSeconds", 30)
        if grace <= unit_timeout:
            error(where, f"terminationGracePeriodSeconds {grace} must exceed the server's --unit-timeout "
                  f"{unit_timeout:g} so that a draining worker finishes its units")

    worker_deployments = {w["metadata"]["name"]: labels for _, w, labels, *_ in workers}
    for f, pdb in by_kind.get("PodDisruptionBudget", []):
        if not any(selects(pdb["spec"]["selector"].get("matchLabels", {}), l) for l in worker_deployments.values()):
            error(f"{f} PodDisruptionBudget", "selects no worker pod")
    if not by_kind.get("PodDisruptionBudget"):
        error("k8s", "the workers need a PodDisruptionBudget")
    for f, so in by_kind.get("ScaledObject", []):
        if so["spec"]["scaleTargetRef"]["name"] not in worker_deployments:
            error(f, "scaleTargetRef is not the worker Deployment")
        for t in so["spec"]["triggers"]:
            if t["type"] == "prometheus":
                check_query(t["metadata"]["query"], metrics, f)
    for f, hpa in by_kind.get("HorizontalPodAutoscaler", []):
        if hpa["spec"]["scaleTargetRef"]["name"] not in worker_deployments:
            error(f, "scaleTargetRef is not the worker Deployment")
        for m in hpa["spec"]["metrics"]:
            check_query(m["external"]["metric"]["name"], metrics, f)
    for f, sm in by_kind.get("ServiceMonitor", []):
        for ep in sm["spec"]["endpoints"]:
            if ep.get("path") != "/metrics":
                error(f, "the endpoint must scrape /metrics")
            ref = ep.get("authorization", {}).get("credentials", {})
            if ref.get("key") not in secrets.get(ref.get("name"), set()):
                error(f, "the bearer token must come from a secret of secrets.example.yaml")
            if not any(selects(sm["spec"]["selector"].get("matchLabels", {}), s["metadata"].get("labels", {}))
                       and ep.get("port") in {p.get("name") for p in s["spec"]["ports"]}
                       for _, s in services.values()):
                error(f, f"no Service with those labels has a port named {ep.get('port')}")
    return [p[1]["spec"]["template"]["spec"].get("securityContext", {}).get("runAsUser") for p in pods]


def check_secret_file(path, flag, mounts, volumes, secrets, where):
    for m in mounts:
        v = volumes.get(m["name"], {})
        prefix = m["mountPath"].rstrip("/") + "/"
        if "secret" in v and path.startswith(prefix):
            name = v["secret"]["secretName"]
            keys = {i["path"]: i["key"] for i in v["secret"].get("items", [])} or {k: k for k in secrets.get(name, ())}
            if name not in secrets:
                error(where, f"{flag}: secret {name} is not in secrets.example.yaml")
            elif path[len(prefix):] not in keys:
                error(where, f"{flag} {path}: secret {name} has no key {path[len(prefix):]}")
            return
    error(where, f"{flag} {path} is not in a mounted secret")


# --- Compose -----------------------------------------------------------------

def check_compose(source, programs):
    path = os.path.join(source, "deploy", "compose.yaml")
    where = "compose.yaml"
    doc = yaml.safe_load(open(path, encoding="utf-8"))
    top_secrets = doc.get("secrets", {})
    top_volumes = doc.get("volumes", {})
    for name, s in top_secrets.items():
        if "file" not in s and "environment" not in s and not s.get("external"):
            error(where, f"secret {name} has no file")
    services = {}
    for name, s in doc["services"].items():
        swhere = f"{where} service {name}"
        build = s.get("build")
        if build:
            dockerfile = os.path.normpath(os.path.join(source, "deploy", build.get("context", "."),
                                                       build.get("dockerfile", "Dockerfile")))
            if not os.path.exists(dockerfile):
                error(swhere, f"build.dockerfile {dockerfile} does not exist")
        command = s.get("command")
        if isinstance(command, str):
            command = shlex.split(command)
        program = programs.get(os.path.basename(str(command[0]))) if command else None
        if program is None:
            error(swhere, "command must start with skyfarm-server or skyfarm-worker")
            continue
        flags = parse_args(program, command[1:], swhere)
        env = s.get("environment", {})
        if isinstance(env, list):
            env = dict(e.split("=", 1) for e in env)
        for var in env:
            if var.startswith("SKYFARM_") and var not in ENTRYPOINT_VARS | HEALTHCHECK_VARS \
                    and not program.accepts_var(var):
                error(swhere, f"{var} is not a variable of {program.name}")
        used = [x if isinstance(x, str) else x["source"] for x in s.get("secrets", [])]
        for x in used:
            if x not in top_secrets:
                error(swhere, f"secret {x} is not defined at the top level")
        files = {f"/run/secrets/{x}" for x in used}
        for flag in ("--worker-secret-file", "--secret-file", "--server-key-file", "--key-file"):
            if flag in flags and flags[flag] not in files:
                error(swhere, f"{flag} {flags[flag]} is not one of the service's secrets {sorted(files)}")
        if "SKYFARM_TOKEN_FILE" in env and env["SKYFARM_TOKEN_FILE"] not in files:
            error(swhere, f"SKYFARM_TOKEN_FILE {env['SKYFARM_TOKEN_FILE']} is not one of the service's secrets")
        mounts = {}
        for v in s.get("volumes", []):
            src, _, dst = (v if isinstance(v, str) else f"{v['source']}:{v['target']}").partition(":")
            dst = dst.split(":")[0]
            if not src.startswith((".", "/")) and src not in top_volumes:
                error(swhere, f"volume {src} is not defined at the top level")
            mounts[dst] = src
        services[name] = (swhere, s, program, flags, env, mounts)

    servers = [x for x in services.items() if x[1][2].name == "skyfarm-server"]
    workers = [x for x in services.items() if x[1][2].name == "skyfarm-worker"]
    if len(servers) != 1 or not workers:
        error(where, "one skyfarm-server service and at least one skyfarm-worker service")
        return
    sname, (swhere, s, _, flags, env, mounts) = servers[0]
    listen, broker = port_of(flags.get("--listen")), port_of(flags.get("--broker"))
    if not flags.get("--listen", "").startswith("0.0.0.0:") or not flags.get("--broker", "").startswith("tcp://0.0.0.0:"):
        error(swhere, "--listen and --broker must bind 0.0.0.0 inside the network")
    if flags.get("--local-workers") != "0":
        error(swhere, "--local-workers must be 0")
    if "--worker-secret-file" not in flags and "--worker-keys" not in flags:
        error(swhere, "a broker beyond loopback needs --worker-secret-file or --worker-keys")
    if "SKYFARM_TOKEN_FILE" not in env and "SKYFARM_TOKEN" not in env:
        error(swhere, "a server listening beyond loopback needs the HTTP token")
    data_dir = flags.get("--data-dir", env.get("SKYFARM_DATA_DIR", DATA_DIR))
    if mounts.get(data_dir) not in top_volumes:
        error(swhere, f"--data-dir {data_dir} is not a named volume's mount ({mounts})")
    published = {int(str(p).split(":")[-1].split("/")[0]) for p in s.get("ports", [])}
    if listen not in published:
        error(swhere, f"the --listen port {listen} is not published ({sorted(published)})")
    test = " ".join(s.get("healthcheck", {}).get("test", []))
    health_port = int(env.get("SKYFARM_HEALTH_PORT", port_of(env.get("SKYFARM_LISTEN")) or 8080))
    if "skyfarm-healthcheck" in test:
        if health_port != listen:
            error(swhere, f"skyfarm-healthcheck asks port {health_port}, --listen is {listen}")
    elif "/healthz" not in test or f":{listen}" not in test:
        error(swhere, f"the healthcheck must ask /healthz on port {listen}")
    unit_timeout = float(flags.get("--unit-timeout", DEFAULT_UNIT_TIMEOUT_S))
    for wname, (wwhere, w, _, wflags, wenv, _) in workers:
        m = re.match(r"tcp://([^:/]+):(\d+)$", wflags.get("--connect", ""))
        if not m or m.group(1) != sname or int(m.group(2)) != broker:
            error(wwhere, f"--connect must be tcp://{sname}:{broker}")
        if "--secret-file" not in wflags and "--key-file" not in wflags:
            error(wwhere, "a worker needs --secret-file (or --key-file)")
        replicas = w.get("deploy", {}).get("replicas")
        if not isinstance(replicas, int) or replicas < 1:
            error(wwhere, "deploy.replicas must be a whole number >= 1")
        if seconds(w.get("stop_grace_period", 10)) <= unit_timeout:
            error(wwhere, f"stop_grace_period must exceed the server's --unit-timeout {unit_timeout:g} s")
        if w.get("depends_on") and sname not in w["depends_on"]:
            error(wwhere, f"depends_on does not name {sname}")


# --- Dockerfile ----------------------------------------------------------------

def check_dockerfile(source, uids):
    path = os.path.join(source, "deploy", "docker", "Dockerfile")
    where = "Dockerfile"
    lines = []
    for raw in re.sub(r"\\\n", " ", open(path, encoding="utf-8").read()).splitlines():
        raw = raw.strip()
        if raw and not raw.startswith("#"):
            instr, _, rest = raw.partition(" ")
            lines.append((instr.upper(), rest.strip()))
    args = {}
    stages = []
    for instr, rest in lines:
        if instr == "ARG" and not stages and "=" in rest:
            k, v = rest.split("=", 1)
            args[k] = v
        if instr == "FROM":
            image = re.sub(r"\$\{(\w+)\}", lambda m: args.get(m.group(1), ""), rest.split()[0])
            if not image.startswith("debian:bookworm"):
                error(where, f"stage FROM {image} is not Debian bookworm")
            stages.append([])
        elif stages:
            stages[-1].append((instr, rest))
    if len(stages) < 2:
        error(where, "a build stage and a runtime stage")
        return
    build, runtime = stages[0], stages[-1]
    if not any(i == "RUN" and "scripts/install-deps.sh" in r for i, r in build):
        error(where, "the build stage installs its packages with scripts/install-deps.sh")
    for instr, rest in build + runtime:
        if instr == "COPY" and "--from" not in rest:
            for src in shlex.split(rest)[:-1]:
                if not src.startswith("--") and not os.path.exists(os.path.join(source, src)):
                    error(where, f"COPY {src}: no such file in the repository")
    user = [r for i, r in runtime if i == "USER"]
    uid = user[-1].split(":")[0] if user else "root"
    if uid in ("root", "0"):
        error(where, "the runtime stage must run as a non-root USER")
    for u in set(uids):
        if str(u) != uid:
            error(where, f"USER {uid} is not the pods' runAsUser {u}")
    if not any(i == "HEALTHCHECK" and ("/healthz" in r or "skyfarm-healthcheck" in r) for i, r in runtime):
        error(where, "the runtime stage needs a HEALTHCHECK on /healthz")
    volumes = " ".join(r for i, r in runtime if i == "VOLUME")
    if DATA_DIR not in volumes:
        error(where, f"VOLUME {DATA_DIR} (the data dir) is missing")
    if not any(i == "ENV" and f"SKYFARM_DATA_DIR={DATA_DIR}" in r for i, r in runtime):
        error(where, f"ENV SKYFARM_DATA_DIR={DATA_DIR} is missing")
    exposed = set(" ".join(r for i, r in runtime if i == "EXPOSE").split())
    if not {"8080", "5555"} <= exposed:
        error(where, f"EXPOSE 8080 5555 (HTTP, broker), not {sorted(exposed)}")


# --- systemd units and the environment example ------------------------------------

def check_systemd(source, programs):
    sd = os.path.join(source, "deploy", "systemd")
    for path in sorted(glob.glob(os.path.join(sd, "*.service"))):
        where = os.path.basename(path)
        text = open(path, encoding="utf-8").read()
        keys = re.findall(r"^(\w+)=(.*)$", text, re.M)
        exec_start = [v for k, v in keys if k == "ExecStart"]
        if len(exec_start) != 1:
            error(where, "one ExecStart=")
            continue
        argv = shlex.split(exec_start[0])
        m = re.match(r"/usr/bin/(skyfarm-\w+)$", argv[0])
        if not m or m.group(1) not in programs:
            error(where, f"ExecStart= must run /usr/bin/skyfarm-server or -worker (the install path), not {argv[0]}")
            continue
        program = programs[m.group(1)]
        parse_args(program, argv[1:], where)
        for k, v in keys:
            if k == "Environment":
                for assignment in shlex.split(v):
                    var = assignment.split("=", 1)[0]
                    if var.startswith("SKYFARM_") and not program.accepts_var(var):
                        error(where, f"{var} is not a variable of {program.name}")
        loaded = {v.split(":", 1)[0] for k, v in keys if k == "LoadCredential"}
        for cred in re.findall(r"%d/([\w.-]+)", text):
            if cred not in loaded:
                error(where, f"%d/{cred} is used but no LoadCredential= loads it")
        if "EnvironmentFile=-/etc/skyfarm/skyfarm.env" not in text:
            error(where, "EnvironmentFile=-/etc/skyfarm/skyfarm.env is missing")
    env_example = os.path.join(sd, "skyfarm.env.example")
    for n, line in enumerate(open(env_example, encoding="utf-8"), 1):
        m = re.match(r"#?(SKYFARM_[A-Z0-9_]+)=", line.strip())
        if m and not any(p.accepts_var(m.group(1)) for p in programs.values()):
            error(f"skyfarm.env.example:{n}", f"{m.group(1)} is not a variable of skyfarm-server or skyfarm-worker")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--source", required=True)
    ap.add_argument("--server", required=True)
    ap.add_argument("--worker", required=True)
    ap.add_argument("--pending")
    a = ap.parse_args()
    a.server, a.worker = os.path.abspath(a.server), os.path.abspath(a.worker)
    pending = read_pending(a.pending or os.path.join(a.source, "tests", "deploy", "pending_flags.txt"))
    programs = {
        "skyfarm-server": Program("skyfarm-server", help_text(a.server), pending),
        "skyfarm-worker": Program("skyfarm-worker", help_text(a.worker), pending),
    }
    metrics = served_metrics(a.server)
    uids = check_k8s(a.source, programs, metrics)
    check_compose(a.source, programs)
    check_dockerfile(a.source, [u for u in uids if u is not None])
    check_systemd(a.source, programs)
    for p in programs.values():
        for name in sorted(p.used_pending):
            notes.append(f"{p.name} {name}: used by the deployment files, not in --help yet (pending_flags.txt)")
    for n in notes:
        print("note:", n)
    for e in errors:
        print("error:", e)
    print(f"{len(errors)} error(s)")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
